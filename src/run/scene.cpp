// Scene registry, loading and the run of a prepared scene (see scene.hpp).
#include "regolith_twin/run/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>

#include "regolith_twin/run/scenario_kind.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {
namespace {

struct Registry {
  std::mutex mu;
  std::vector<std::shared_ptr<const SceneKind>> kinds;
  bool builtins = false;
};

Registry& registry() {
  static Registry r;
  std::lock_guard<std::mutex> lk(r.mu);
  if (!r.builtins) {
    r.builtins = true;
    for (auto& k : builtin_scene_kinds()) r.kinds.push_back(k);
  }
  return r;
}

}  // namespace

void SceneRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                             int threads) const {
  JsonObject j;
  j.str("kind", kind_).str("status", rep.status);
  if (!rep.message.empty()) j.str("message", rep.message);
  add_run_and_observers(j, m, rep, threads);
  j.write(path);
}

JsonObject SceneRun::summary_head(const std::string& scenario, const std::string& file, const RunReport& rep) const {
  JsonObject j;
  j.str("kind", kind_).str("scenario", scenario).str("file", file).str("status", rep.status);
  if (!rep.message.empty()) j.str("message", rep.message);
  return j;
}

void SceneRun::attach(Run& run) {
  for (Observer* o : observers()) run.add_observer(o);
  for (Fix* f : fixes()) run.add_fix(f);
}

void SceneRun::add_run_and_observers(JsonObject& j, const Model& m, const RunReport& rep, int threads) const {
  JsonObject run;
  run.num("grains", m.n_grains).num("steps", double(rep.steps)).num("sim_time", rep.sim_time);
  run.num("wall_seconds", rep.wall_seconds).num("dt", m.dt).num("kn", m.kn);
  run.num("rebuilds", double(rep.rebuilds)).num("body_rebuilds", double(rep.body_rebuilds));
  if (threads > 0) run.num("threads", threads);
  add_sleep_summary(run, rep);
  add_free_flight_summary(run, rep);
  add_schedule_summary(run, rep);
  j.obj("run", run);
  JsonObject obs;
  for (Observer* o : const_cast<SceneRun*>(this)->observers()) o->summary(obs);
  for (Fix* f : const_cast<SceneRun*>(this)->fixes()) f->summary(obs);
  j.obj("observers", obs);
}

void add_free_flight_summary(JsonObject& j, const RunReport& rep) {
  if (!rep.free_flight) return;
  JsonObject o;
  o.num("free_grains_max", double(rep.free_grains_max));
  j.obj("free_flight", o);
}

void restart_at_zero(State& s) {
  s.rebuild_requested = true;
  s.forces_valid = false;
  s.time = 0;
  s.step = 0;
  s.ticks = 0;
}

void add_sleep_summary(JsonObject& j, const RunReport& rep) {
  if (!rep.sleep) return;
  JsonObject sl;
  sl.num("sleeping_at_end", double(rep.sleeping_at_end)).num("mean_awake", rep.mean_awake);
  sl.num("fell_asleep", double(rep.fell_asleep)).num("woke", double(rep.woke));
  sl.num("discarded_kinetic_energy", rep.discarded_energy).num("discarded_max_speed", rep.discarded_max_speed);
  j.obj("sleep", sl);
}

void add_schedule_summary(JsonObject& j, const RunReport& rep) {
  if (!rep.schedule) return;
  const ScheduleState& q = rep.sched;
  JsonObject o;
  o.num("dt_scene", rep.dt_scene).num("dt_min", q.dt_min).num("dt_max", q.dt_max);
  o.num("kn_factor_at_end", q.scale).num("kn_factor_min", q.min_scale);
  o.num("lowered", double(q.lowered)).num("raised", double(q.raised));
  o.num("injected_energy", q.injected).num("released_energy", q.released).num("max_injected_fraction_of_kinetic", q.max_injected_fraction);
  o.num("kinetic_energy_ref", q.kinetic_ref);
  JsonObject by;
  by.num("grains", double(q.raised_grains)).num("body", double(q.raised_body));
  o.obj("raised_by", by);
  j.obj("schedule", o);
}

double Scene::bed_top() const { return std::numeric_limits<double>::infinity(); }

void register_scene_kind(std::shared_ptr<const SceneKind> kind) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lk(r.mu);
  for (auto& k : r.kinds)
    if (k->name() == kind->name()) {
      k = std::move(kind);  // a later registration replaces the kind of that name
      return;
    }
  r.kinds.push_back(std::move(kind));
}

std::vector<std::string> scene_kind_names() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lk(r.mu);
  std::vector<std::string> out;
  for (const auto& k : r.kinds) out.push_back(k->name());
  return out;
}

const SceneKind& scene_kind_of(const YAML::Node& root, const std::string& file) {
  static const std::shared_ptr<const SceneKind> plain = scenario_kind();
  Registry& r = registry();
  std::lock_guard<std::mutex> lk(r.mu);
  const SceneKind* found = nullptr;
  if (root && root.IsMap())
    for (const auto& k : r.kinds)
      if (root[k->name()]) {
        if (found)
          throw InputError(file + ": keys '" + found->name() + "' and '" + k->name() +
                           "': a scene file names at most one scene kind");
        found = k.get();
      }
  return found ? *found : *plain;
}

std::unique_ptr<Scene> load_scene(const std::string& file, const std::vector<std::string>& overrides,
                                  const SceneOptions& opt) {
  const YAML::Node root = load_document(file, overrides);
  try {
    return scene_kind_of(root, file).prepare(root, file, opt);
  } catch (const YAML::Exception& e) {  // a conversion a scene kind's reader did not check
    throw InputError(file + ": " + e.what());
  }
}

RunReport run_scene(const Scene& scene, Model& m, State& s, const SceneRunOptions& opt,
                    std::unique_ptr<SceneRun>* out_run) {
  RunOptions ro;
  ro.out_dir = opt.out_dir;
  ro.sample_every = scene.sample_every;
  ro.progress_every = opt.progress_every;
  ro.stage_snapshots = opt.stage_snapshots;
  ro.max_steps = opt.max_steps;
  Run run(m, s, scene.plan, ro);
  std::unique_ptr<SceneRun> sr = scene.begin(run);
  sr->attach(run);
  if (!opt.out_dir.empty()) sr->remove_earlier_outputs(opt.out_dir);
  const RunReport rep = run.run();
  if (!opt.out_dir.empty()) {
    sr->write_files(opt.out_dir, m, s, rep);
    sr->write_summary(opt.out_dir + "/summary.json", m, s, rep, opt.threads);
  }
  if (out_run) *out_run = std::move(sr);
  return rep;
}

void SceneRun::remove_earlier_outputs(const std::string& dir) const {
  make_dirs(dir);
  for (const auto& [label, name] : files()) {
    const std::string path = dir + "/" + name;
    if (std::remove(path.c_str()) != 0 && errno != ENOENT)
      throw InputError(path + ": cannot remove the " + label + " of an earlier run (" + std::strerror(errno) +
                       "): remove it, or give another output folder");
  }
}

void check_container(const Model& m, const std::string& file, const std::string& block, double rim,
                     double container_radius, int body) {
  double rmax = 0;
  for (int i = 0; i < m.n_grains; ++i) rmax = std::max(rmax, m.grain_radius[i]);
  char b[320];
  const auto fail = [&](const std::string& key, const char* what) {
    throw InputError(file + ": key '" + block + "." + key + "': " + what);
  };
  if (std::isfinite(rim)) {
    double floor = -std::numeric_limits<double>::infinity();
    int floor_wall = -1;
    for (size_t w = 0; w < m.walls.size(); ++w)
      if (m.walls[w].type == WallType::Plane && m.walls[w].axis.z() > 0.99 && m.walls[w].origin.z() > floor) {
        floor = m.walls[w].origin.z();
        floor_wall = int(w);
      }
    if (floor_wall >= 0 && !(rim >= floor + 2 * rmax)) {
      std::snprintf(b, sizeof b, "%.6g m is not a grain diameter (%.3g m) above the floor, walls[%d].point at z = %.6g m",
                    rim, 2 * rmax, floor_wall, floor);
      fail("rim", b);
    }
  }
  if (!(container_radius > 2 * rmax)) {
    std::snprintf(b, sizeof b, "%.6g m is not wider than a grain diameter (%.3g m)", container_radius, 2 * rmax);
    fail("container_radius", b);
  }
  for (size_t w = 0; w < m.walls.size(); ++w) {
    const Wall& c = m.walls[w];
    if (c.type == WallType::Cylinder && c.inner && std::abs(c.axis.z()) > 0.99 &&
        container_radius > c.radius * (1 + 1e-9)) {
      std::snprintf(b, sizeof b, "%.6g m is wider than the container's wall, walls[%zu].radius = %.6g m",
                    container_radius, w, c.radius);
      fail("container_radius", b);
    }
  }
  if (body >= 0 && !(m.bodies[body].bound_radius < container_radius)) {
    std::snprintf(b, sizeof b, "%.6g m: the body '%s' (bounding radius %.4g m) does not fit in the container",
                  container_radius, m.bodies[body].name.c_str(), m.bodies[body].bound_radius);
    fail("container_radius", b);
  }
}

std::string default_cache_dir() {
  const char* env = std::getenv("REGOLITH_CACHE");
  const char* home = std::getenv("HOME");
  return env ? env : std::string(home ? home : ".") + "/.cache/regolith_twin";
}

}  // namespace rt
