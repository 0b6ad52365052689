// The plain scenario kind (see scenario_kind.hpp).
#include "regolith_twin/run/scenario_kind.hpp"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <sstream>

#include "regolith_twin/observers/energy_series.hpp"

namespace rt {
namespace {

void write_final(const std::string& path, const Model& m, const State& s) {
  std::ostringstream f;  // written whole at the end (docs/files.md, outputs)
  f << "# id x y z radius vx vy vz  (SI units)\n";
  f.precision(10);
  for (int i = 0; i < m.n_grains; ++i)
    f << i << ' ' << s.pos[i].x() << ' ' << s.pos[i].y() << ' ' << s.pos[i].z() << ' ' << m.grain_radius[i] << ' '
      << s.vel[i].x() << ' ' << s.vel[i].y() << ' ' << s.vel[i].z() << '\n';
  write_file(path, f.str());
}

JsonObject energy_json(const Energy& e) {
  JsonObject o;
  o.num("translational", e.translational).num("rotational", e.rotational).num("potential", e.potential);
  o.num("elastic", e.elastic).num("total", e.total());
  return o;
}

class ScenarioRun : public SceneRun {
 public:
  ScenarioRun(const Scene& scene, const Run& run) : scene_(scene), series_(run) {}
  std::vector<Observer*> observers() override { return {&series_}; }

  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override {
    const Scenario& sc = scene_.sc;
    JsonObject j;
    j.str("scenario", sc.name).str("file", sc.file).str("status", rep.status);
    if (!rep.message.empty()) j.str("message", rep.message);
    j.num("grains", m.n_grains).num("walls", double(m.walls.size()));
    j.str("contact_model", m.contact_model == ContactModel::Linear ? "linear" : "hertz_mindlin");
    j.num("kn", m.kn).num("dt", m.dt).num("skin", m.skin).num("partitions", m.partitions).num("threads", threads);
    j.num("steps", double(s.step)).num("sim_time", rep.sim_time).num("wall_seconds", rep.wall_seconds);
    j.num("steps_per_second", s.step / std::max(rep.wall_seconds, 1e-9));
    j.num("grain_steps_per_second", double(s.step) * m.n_grains / std::max(rep.wall_seconds, 1e-9));
    j.num("list_rebuilds", double(s.rebuilds)).num("max_overlap_ratio", rep.max_overlap_ratio);
    add_sleep_summary(j, rep);
    add_free_flight_summary(j, rep);
    add_schedule_summary(j, rep);
    JsonObject res;
    for (const auto& r : sc.resolution) res.num(r.label, r.steps);
    j.obj("steps_per_contact", res);
    JsonObject warn;
    for (size_t i = 0; i < sc.warnings.size(); ++i) warn.str(std::to_string(i), sc.warnings[i]);
    j.obj("warnings", warn);
    j.obj("energy_initial", energy_json(series_.initial()));
    if (rep.status == "ok") j.obj("energy_final", energy_json(series_.final()));
    JsonObject stages;
    for (const auto& r : rep.stages) {
      JsonObject o;
      o.num("t_end", r.t_end).str("ended_by", r.reason);
      if (r.grains_removed) o.num("grains_removed", r.grains_removed);
      if (r.stiffness_injection != 0 || r.kinetic_at_switch != 0)
        o.num("stiffness_injection", r.stiffness_injection).num("kinetic_at_switch", r.kinetic_at_switch);
      stages.obj(r.name, o);
    }
    j.obj("stages", stages);
    JsonObject groups;
    for (const GrainGroup* g : series_.tracked()) {
      const Vec3 p = EnergySeries::group_mean(s.pos, *g), v = EnergySeries::group_mean(s.vel, *g);
      JsonObject o;
      o.nums("position", {p.x(), p.y(), p.z()}).nums("velocity", {v.x(), v.y(), v.z()});
      groups.obj(g->name, o);
    }
    j.obj("tracked_groups", groups);
    j.write(path);
  }

  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override {
    if (rep.status == "ok") write_final(dir + "/final_grains.txt", m, s);
  }

  std::vector<std::pair<std::string, std::string>> files() const override {
    return {{"summary", "summary.json"}, {"time series", "series.csv"}, {"final state", "final_grains.txt"}};
  }

  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override {
    char b[256];
    std::snprintf(b, sizeof b, "finished %s: %ld steps, %.4g s simulated in %.3g s wall (%.3g grain-steps/s)",
                  scene_.sc.name.c_str(), rep.steps, rep.sim_time, rep.wall_seconds,
                  double(rep.steps) * m.n_grains / std::max(rep.wall_seconds, 1e-9));
    return b;
  }

 private:
  const Scene& scene_;
  EnergySeries series_;
};

class ScenarioScene : public Scene {
 public:
  std::string kind() const override { return "scenario"; }
  std::unique_ptr<SceneRun> begin(Run& run) const override {
    return std::make_unique<ScenarioRun>(*this, run);
  }
};

class ScenarioKind : public SceneKind {
 public:
  std::string name() const override { return "scenario"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override {
    auto sc = std::make_unique<ScenarioScene>();
    sc->sc = parse_scenario(root, file);
    const Scenario& x = sc->sc;
    for (const auto& w : x.warnings) std::fprintf(stderr, "[%s] warning: %s\n", x.name.c_str(), w.c_str());
    if (!opt.quiet) {
      std::fprintf(stderr, "[%s] %d grains, %zu walls, %zu bodies, dt = %.4g s, k_n = %.4g N/m\n", x.name.c_str(),
                   x.model.n_grains, x.model.walls.size(), x.model.bodies.size(), x.model.dt, x.model.kn);
      for (const auto& r : x.resolution)
        std::fprintf(stderr, "[%s]   %s: %.1f steps per contact\n", x.name.c_str(), r.label.c_str(), r.steps);
    }
    sc->start = sc->sc.initial;
    sc->plan = RunPlan::of(sc->sc);
    sc->sample_every = sc->sc.output_every;
    return sc;
  }
};

}  // namespace

std::shared_ptr<const SceneKind> scenario_kind() { return std::make_shared<ScenarioKind>(); }

RunReport run_scenario(Scenario& sc, State& s, const RunOptions& opt_in, int threads) {
  RunOptions opt = opt_in;
  opt.sample_every = sc.output_every;
  ScenarioScene scene;
  scene.sc = sc;  // for the summary's settings
  Run run(sc.model, s, RunPlan::of(sc), opt);
  ScenarioRun sr(scene, run);
  sr.attach(run);
  if (!opt.out_dir.empty()) sr.remove_earlier_outputs(opt.out_dir);
  const RunReport rep = run.run();
  sc.groups = run.groups();
  if (!opt.out_dir.empty()) {
    sr.write_files(opt.out_dir, sc.model, s, rep);  // the summary last, as run_scene writes them
    sr.write_summary(opt.out_dir + "/summary.json", sc.model, s, rep, threads);
  }
  return rep;
}

}  // namespace rt
