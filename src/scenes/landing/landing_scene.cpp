// The landing scene kind (see landing_scene.hpp).
#include "regolith_twin/scenes/landing/landing_scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/observers/surface_map.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {
namespace {

const char* attitude_name(Attitude a) { return a == Attitude::Flat ? "Flat" : a == Attitude::BCF ? "BCF" : "FCF"; }

double mean_radius(const Model& m) {
  double r = 0;
  for (int i = 0; i < m.n_grains; ++i) r += m.grain_radius[i];
  return m.n_grains ? r / m.n_grains : 0;
}

class LandingKind : public SceneKind {
 public:
  std::string name() const override { return "landing"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override;
};

}  // namespace

// --- one run --------------------------------------------------------------------

LandingRun::LandingRun(const LandingScene& scene, const Model& m)
    : scene_(scene),
      tracker_(scene.lander, scene.run_spec, scene.run_spec.rim + mean_radius(m)),
      ejecta_(scene.run_spec.rim + mean_radius(m), std::max(1, int(std::lround(1e-3 / m.dt)))),  // each millisecond
      zone_(scene.lander, scene.run_spec.active_radius, scene.run_spec.far_ring,
            std::max(1, int(std::lround(1e-3 / m.dt))), &ejecta_) {}

std::unique_ptr<SceneRun> LandingScene::begin(Run& run) const {
  return std::make_unique<LandingRun>(*this, run.model());
}

LandingOutcome LandingRun::outcome(const RunReport& rep, bool final) const {
  LandingOutcome o = tracker_.tracker().outcome();
  o.ejected_grains = ejecta_.count();
  o.ejected_volume = ejecta_.volume();
  o.max_overlap_ratio = tracker_.max_overlap_ratio();
  if (final) {
    o.far_field_rms = tracker_.far_field_rms();
    o.active_grains = zone_.active_grains();
    o.active_edge_rms = zone_.edge_rms();
  }
  o.status = rep.status;
  o.message = rep.message;
  o.steps = rep.steps;
  o.wall_seconds = rep.wall_seconds;
  return o;
}

void LandingRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                               int threads) const {
  write_landing_summary(path, scene_, outcome(rep, true), threads, &rep);
}

void LandingRun::write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {
  const LandingSpec& sp = scene_.run_spec;
  write_surface(dir + "/surface.csv", m, s, sp.container_radius, sp.rim, 0.01);
}

std::vector<std::pair<std::string, std::string>> LandingRun::files() const {
  return {{"summary", "summary.json"}, {"time series", "series.csv"}, {"surface", "surface.csv"}};
}

std::string LandingRun::result_line(const Model& m, const State& s, const RunReport& rep) const {
  const LandingOutcome o = outcome(rep, true);
  char b[320];
  std::snprintf(b, sizeof b,
                "landing %s: %s, speed ratio %.3f, collision %.3g s, penetration %.3g m, travel %.3g m (%.0f s wall)",
                scene_.sc.name.c_str(), o.lifted_off ? "lifted off" : "no lift-off", o.speed_ratio,
                o.collision_duration, o.max_penetration, o.travel_distance, o.wall_seconds);
  return b;
}

// --- preparation ----------------------------------------------------------------

std::unique_ptr<Scene> LandingKind::prepare(const YAML::Node& doc, const std::string& file,
                                            const SceneOptions& opt) const {
  auto ls = std::make_unique<LandingScene>();
  ls->file = file;
  YAML::Node root = YAML::Clone(doc);
  ls->spec = parse_landing(root["landing"], file);
  root.remove("landing");
  ls->sc = parse_scenario(root, file);
  Scenario& sc = ls->sc;
  Model& m = sc.model;
  for (size_t k = 0; k < m.bodies.size(); ++k)
    if (m.bodies[k].name == ls->spec.lander) ls->lander = int(k);
  if (ls->lander < 0)
    throw InputError(file + ": key 'landing.lander': no body named '" + ls->spec.lander + "' (" + body_names_text(m) + ")");
  const int b = ls->lander;
  check_container(m, file, "landing", ls->spec.rim, ls->spec.container_radius, b);
  m.gravity = landing_gravity(ls->spec);
  for (const auto& w : sc.warnings) std::fprintf(stderr, "[landing] warning: %s\n", w.c_str());
  if (!opt.quiet) {
    if (sc.carved_grains > 0)
      std::fprintf(stderr, "[landing] %d grains removed to make room for buried bodies\n", sc.carved_grains);
    std::fprintf(stderr, "[landing] %d grains, dt = %.4g s, k_n = %.4g N/m, g = %.4g m/s^2\n", m.n_grains, m.dt, m.kn,
                 m.gravity.norm());
    for (const auto& r : sc.resolution)
      std::fprintf(stderr, "[landing]   %s: %.1f steps per contact\n", r.label.c_str(), r.steps);
  }

  // 1. The relaxed bed: from the cache, or relaxed now (lander parked far above).
  State s = sc.initial;
  s.bodies[b].pos = Vec3(0, 0, ls->spec.rim + 100.0);
  set_body_velocity(m.bodies[b], s.bodies[b], Vec3::Zero(), Vec3::Zero());
  RelaxedBed bed = relax_bed(sc, s, {b}, opt, "landing");
  s = std::move(bed.state);
  ls->bed_cache = bed.cache;
  // Bed figures: grains below the trim plane in the container.
  double vol = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    if (s.pos[i].z() <= ls->spec.rim) vol += 4.0 / 3.0 * kPi * r * r * r;
  }
  const double mean_r = mean_radius(m);
  const double box = kPi * ls->spec.container_radius * ls->spec.container_radius * ls->spec.rim;
  ls->packing = vol / box;
  ls->bulk_density = m.n_grains ? ls->packing * m.materials[m.grain_material[0]].density : 0;

  // 2. Perturbed repeat and placement.
  ls->pert = perturbation(ls->spec, mean_r);
  ls->run_spec = ls->spec;
  if (ls->spec.repeat > 0) {
    rotate_grains_about_z(m, s, ls->pert.angle);
    ls->run_spec.aim += ls->pert.aim_offset;
  }
  s.time = 0;  // landing time counts from the start of the approach
  place_lander(m, s, b, ls->run_spec);
  ls->start = std::move(s);
  ls->bed_top_ = ls->run_spec.rim + mean_r;
  // The run: one open-ended stage that the tracker ends.
  ls->plan = RunPlan::open_ended(sc.name, "landing");
  ls->sample_every = ls->run_spec.sample_every;
  return ls;
}

std::shared_ptr<const SceneKind> landing_kind() { return std::make_shared<LandingKind>(); }

void write_landing_summary(const std::string& path, const LandingScene& ls, const LandingOutcome& o, int threads,
                           const RunReport* rep) {
  const LandingSpec& spec = ls.spec;
  const Model& m = ls.sc.model;
  JsonObject j;
  j.str("scenario", ls.sc.name).str("file", ls.file).str("status", o.status);
  if (!o.message.empty()) j.str("message", o.message);
  JsonObject in;
  in.str("attitude", attitude_name(spec.attitude));
  in.num("angle_deg", spec.angle_deg).num("speed", spec.speed).num("gravity", spec.g).num("slope_deg", spec.slope_deg);
  in.num("pitch_deg", spec.pitch_deg).num("roll_deg", spec.roll_deg).num("heading_deg", spec.heading_deg);
  in.num("repeat", double(spec.repeat)).num("bed_rotation_deg", ls.pert.angle * 180 / kPi);
  in.nums("aim", {ls.run_spec.aim.x(), ls.run_spec.aim.y()});
  j.obj("input", in);
  JsonObject bed;
  bed.num("grains", m.n_grains).num("trim_plane", spec.rim).num("packing_fraction", ls.packing);
  bed.num("bulk_density", ls.bulk_density).str("cache", ls.bed_cache);
  j.obj("bed", bed);
  JsonObject oc;
  landing_outcome_json(o, oc);
  oc.num("ejected_volume", o.ejected_volume).num("ejected_grains", double(o.ejected_grains));
  oc.num("far_field_rms_speed", o.far_field_rms).num("max_overlap_ratio", o.max_overlap_ratio);
  oc.num("active_radius", spec.active_radius).num("active_grains", double(o.active_grains));
  oc.num("active_edge_rms_speed", o.active_edge_rms);
  j.obj("outcome", oc);
  JsonObject run;
  run.num("steps", double(o.steps)).num("wall_seconds", o.wall_seconds).num("dt", m.dt).num("kn", m.kn);
  if (threads > 0) run.num("threads", threads);
  if (rep) run.num("rebuilds", double(rep->rebuilds)).num("body_rebuilds", double(rep->body_rebuilds));
  if (rep) add_sleep_summary(run, *rep);
  if (rep) add_free_flight_summary(run, *rep);
  if (rep) add_schedule_summary(run, *rep);
  j.obj("run", run);
  j.write(path);
}

}  // namespace rt
