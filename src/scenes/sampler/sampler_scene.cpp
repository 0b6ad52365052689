// The sampler scene kind (see sampler_scene.hpp; docs/scenes.md B).
#include "regolith_twin/scenes/sampler/sampler_scene.hpp"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/types.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <cstdio>
#include <random>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/observers/escape.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/io/yaml_reader.hpp"
#include "regolith_twin/scenes/sampler/crater.hpp"
#include "regolith_twin/scenes/sampler/horn_segments.hpp"
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "regolith_twin/scenes/sampler/packing_below_filter.hpp"

namespace rt {
namespace {


int every_steps(double seconds, double dt) { return std::max(1, int(std::lround(seconds / dt))); }

class SamplerKind : public SceneKind {
 public:
  std::string name() const override { return "sampler"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override;
};

WaveOptions wave_options(const SamplerScene& sc) {
  WaveOptions o;
  o.impact = sc.impact;
  o.times = sc.spec.wave_times;
  o.rest_rms = sc.rest_rms;
  return o;
}

ZFitOptions z_options(const SamplerScene& sc) {
  ZFitOptions o;
  o.impact = sc.impact;
  return o;
}

}  // namespace

SamplerRun::SamplerRun(const SamplerScene& sc, const Model& m)
    : SceneRun("sampler"),
      scene_(sc),
      clock_(sc.projectile),
      segments_(sc.geometry, sc.projectile, every_steps(1e-5, m.dt), sc.spec.requirement),
      escape_(Vec3(sc.impact.x() - sc.spec.escape_half_width, sc.impact.y() - sc.spec.escape_half_width, -1.0),
              Vec3(sc.impact.x() + sc.spec.escape_half_width, sc.impact.y() + sc.spec.escape_half_width,
                   sc.spec.escape_height),
              every_steps(1e-5, m.dt)),
      ejecta_(&clock_, sc.surface_, sc.impact, sc.spec.container_radius, m.gravity.norm(), every_steps(1e-5, m.dt)),
      energy_(&clock_, every_steps(sc.spec.energy_window / 100, m.dt), sc.spec.energy_window),
      wave_(&clock_, wave_options(sc)),
      zfit_(&clock_, z_options(sc), sc.rest_rms, sc.spec.z_times),
      crater_(sc.impact, sc.projectile, every_steps(1e-4, m.dt)),
      packing_(sc.geometry),
      second_(sc) {}

SecondShot::SecondShot(const SamplerScene& sc)
    : enabled_(sc.spec.second_shot),
      t_(sc.spec.second_delay),
      radius_(sc.spec.radius),
      material_(sc.projectile_material),
      p0_(sc.geometry.origin + sc.geometry.axis * sc.geometry.segment_z[3]),
      v0_(sc.direction * sc.spec.speed) {}

void SecondShot::add_grains(Model& m, State& s) {
  if (!enabled_ || t_fired_ >= 0 || s.time < t_ - 0.5 * m.dt) return;
  grain_ = add_grain(m, s, radius_, material_, p0_, v0_, Vec3::Zero());
  t_fired_ = s.time;
}

void SecondShot::grains_removed(const std::vector<int>& old_to_new) {
  if (grain_ >= 0) grain_ = grain_ < int(old_to_new.size()) ? old_to_new[grain_] : -1;
}

void SecondShot::summary(JsonObject& out) const {
  if (!enabled_) return;
  JsonObject o;
  o.num("delay", t_).boolean("fired", t_fired_ >= 0).num("t_fired", t_fired_);
  o.nums("position", {p0_.x(), p0_.y(), p0_.z()}).nums("velocity", {v0_.x(), v0_.y(), v0_.z()});
  out.obj("second_projectile", o);
}

void SamplerRun::write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {
  segments_.write_csv(dir + "/collected.csv");
  ejecta_.write_csv(dir + "/ejecta.csv");
  energy_.write_csv(dir + "/energy_partition.csv");
  wave_.write_csv(dir + "/wave.csv");
  zfit_.write_csv(dir + "/zmodel.csv");
}

std::vector<std::pair<std::string, std::string>> SamplerRun::files() const {
  return {{"summary", "summary.json"},
          {"time series", "series.csv"},
          {"collected through the top", "collected.csv"},
          {"ejecta", "ejecta.csv"},
          {"energy partition", "energy_partition.csv"},
          {"impact wave", "wave.csv"},
          {"Z-model fits", "zmodel.csv"}};
}

std::string SamplerRun::result_line(const Model& m, const State& s, const RunReport& rep) const {
  char b[400];
  std::snprintf(b, sizeof b,
                "sampler %s: %.0f m/s, collected %.4g mg after %.4g s (requirement %.0f mg %s), crater depth "
                "%.3g m, radius %.3g m, %ld ejecta (%.0f s wall)",
                scene_.sc.name.c_str(), scene_.spec.speed, segments_.collected_mass() * 1e6, s.time,
                scene_.spec.requirement * 1e6,
                segments_.collected_mass() >= scene_.spec.requirement ? "met" : "not met", crater_.depth(),
                crater_.radius(), ejecta_.count(), rep.wall_seconds);
  return b;
}

void SamplerRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                               int threads) const {
  const SamplerScene& sc = scene_;
  const SamplerSpec& sp = sc.spec;
  JsonObject j = summary_head(sc.sc.name, sc.file, rep);
  JsonObject in;
  in.num("speed", sp.speed).num("tilt_deg", sp.tilt_deg).num("offset", sp.offset).num("duration", sp.duration);
  in.num("projectile_mass", sp.mass).num("projectile_radius", sp.radius).num("repeat", double(sp.repeat));
  in.num("bed_rotation_deg", sc.bed_rotation * 180 / kPi).nums("impact_shift", {sc.impact_shift.x(), sc.impact_shift.y()});
  in.nums("impact_point", {sc.impact.x(), sc.impact.y(), sc.impact.z()});
  in.num("horn_bottom", sc.geometry.origin.z()).num("gravity", m.gravity.norm());
  j.obj("input", in);
  JsonObject bed;
  bed.num("grains", sc.bed_grains).num("mass", sc.bed_mass).num("depth", sc.bed_depth);
  bed.num("packing_fraction", sc.packing).num("bulk_density", sc.bulk_density).num("rest_rms_speed", sc.rest_rms);
  bed.num("surface_height", sc.surface_).num("surface_top", sc.surface_top).str("cache", sc.bed_cache);
  j.obj("bed", bed);
  JsonObject res;
  for (const auto& r : sc.sc.resolution) res.num(r.label, r.steps);
  j.obj("steps_per_contact", res);
  JsonObject coll;
  coll.num("collected_mass", segments_.collected_mass()).num("requirement", sp.requirement);
  coll.boolean("requirement_met", segments_.collected_mass() >= sp.requirement);
  coll.num("after", s.time);
  j.obj("collection", coll);
  add_run_and_observers(j, m, rep, threads);
  j.write(path);
}

SamplerSpec parse_sampler(const YAML::Node& n, const std::string& src) {
  SamplerSpec sp;
  const YamlReader rd(src);
  const std::string p = "sampler";
  if (!n || !n.IsMap()) rd.fail(p, "missing or not a mapping");
  rd.only(n, p,
          {"horn", "projectile_material", "speed", "tilt_deg", "offset", "mass", "radius", "start_gap",
           "horn_clearance", "container_radius", "duration", "kn_ref", "dt_ref", "v_ref", "dt_factor",
           "sample_every", "escape_half_width", "escape_height", "repeat", "perturb_seed", "z_times", "wave_times",
           "energy_window", "requirement", "second_shot", "second_delay"});
  sp.horn = rd.text(n, p, "horn", sp.horn);
  sp.projectile_material = rd.text(n, p, "projectile_material", sp.projectile_material);
  sp.speed = rd.number(n, p, "speed", sp.speed, 1, 1e4, true);
  sp.tilt_deg = rd.number(n, p, "tilt_deg", sp.tilt_deg, -25, 25);
  sp.offset = rd.number(n, p, "offset", sp.offset, -2.5e-3, 2.5e-3);
  sp.mass = rd.number(n, p, "mass", sp.mass, 1e-6, 1e3);
  sp.radius = rd.number(n, p, "radius", sp.radius, 1e-5, 1);
  sp.start_gap = rd.number(n, p, "start_gap", sp.start_gap, 0, 1);
  sp.horn_clearance = rd.number(n, p, "horn_clearance", sp.horn_clearance, 0, 1);
  sp.container_radius = rd.number(n, p, "container_radius", sp.container_radius, 0, 1e3, true);
  sp.duration = rd.number(n, p, "duration", sp.duration, 0, 1e4, true);
  sp.kn_ref = rd.number(n, p, "kn_ref", sp.kn_ref, 1e-3, 1e15);
  sp.dt_ref = rd.number(n, p, "dt_ref", sp.dt_ref, 1e-12, 1);
  sp.v_ref = rd.number(n, p, "v_ref", sp.v_ref, 1e-3, 1e5);
  sp.dt_factor = rd.number(n, p, "dt_factor", sp.dt_factor, 1e-3, 1);
  sp.sample_every = rd.number(n, p, "sample_every", sp.sample_every, 1e-7, 1e3);
  sp.escape_half_width = rd.number(n, p, "escape_half_width", sp.escape_half_width, 0, 1e3, true);
  sp.escape_height = rd.number(n, p, "escape_height", sp.escape_height, 0, 1e3, true);
  sp.repeat = int(rd.integer(n, p, "repeat", 0, 0, 1000000));
  sp.perturb_seed = (unsigned long)rd.integer(n, p, "perturb_seed", 1, 0, 4000000000L);
  auto times = [&](const char* key, std::vector<double>& out) {
    if (const YAML::Node t = n[key]) {
      if (!t.IsSequence()) rd.fail(p + "." + key, "expected a list of times after impact, s");
      out.clear();
      for (size_t i = 0; i < t.size(); ++i)
        out.push_back(rd.number(t[i], p + "." + key + "[" + std::to_string(i) + "]", 0, 1e4));
    }
  };
  times("z_times", sp.z_times);
  times("wave_times", sp.wave_times);
  sp.energy_window = rd.number(n, p, "energy_window", sp.energy_window, 0, 1e3);
  sp.requirement = rd.number(n, p, "requirement", sp.requirement, 0, 1e3);
  sp.second_shot = rd.boolean(n, p, "second_shot", sp.second_shot);
  sp.second_delay = rd.number(n, p, "second_delay", sp.second_delay, 0, 1e3, true);
  return sp;
}

std::unique_ptr<SceneRun> SamplerScene::begin(Run& run) const {
  return std::make_unique<SamplerRun>(*this, run.model());
}

std::unique_ptr<Scene> SamplerKind::prepare(const YAML::Node& doc, const std::string& file,
                                            const SceneOptions& opt) const {
  auto ss = std::make_unique<SamplerScene>();
  ss->file = file;
  YAML::Node root = YAML::Clone(doc);
  ss->spec = parse_sampler(root["sampler"], file);
  const SamplerSpec& sp = ss->spec;
  root.remove("sampler");
  // Stiffness and step from the shot speed (docs/model.md §4), given to the
  // scenario reader so that its resolution report is the shot's; a stiffness
  // schedule's design speed is the shot's (docs/model.md §17).
  const double ratio = sp.speed / sp.v_ref;
  DerivedContact derived;
  derived.kn = sp.kn_ref * ratio * ratio;
  derived.dt = sp.dt_ref / ratio * sp.dt_factor;
  derived.design_speed = sp.speed;
  derived.by = "sampler.speed (k_n = sampler.kn_ref (v / v_ref)^2, dt = sampler.dt_ref (v_ref / v) dt_factor)";
  ss->sc = parse_scenario(root, file, derived);
  Scenario& sc = ss->sc;
  Model& m = sc.model;
  for (size_t k = 0; k < m.bodies.size(); ++k)
    if (m.bodies[k].name == sp.horn) ss->horn = int(k);
  if (ss->horn < 0) throw InputError(file + ": key 'sampler.horn': no body named '" + sp.horn + "' (" + body_names_text(ss->sc.model) + ")");
  check_container(m, file, "sampler", std::numeric_limits<double>::quiet_NaN(), sp.container_radius, -1);
  if (!(m.gravity.norm() >= 1e-6))
    throw InputError(file + ": key 'gravity': the ejecta's flight figures need gravity of at least 1e-6 m/s^2");
  if (!m.bodies[ss->horn].fixed)
    throw InputError(file + ": key 'sampler.horn': the horn body '" + sp.horn + "' must be fixed (fixed: true)");
  int proj_mat = -1;
  for (size_t k = 0; k < m.materials.size(); ++k)
    if (m.materials[k].name == sp.projectile_material) proj_mat = int(k);
  if (proj_mat < 0)
    throw InputError(file + ": key 'sampler.projectile_material': no material named '" + sp.projectile_material +
                     "' under 'materials'");
  const int b = ss->horn;
  for (const auto& w : sc.warnings) std::fprintf(stderr, "[sampler] warning: %s\n", w.c_str());
  if (!opt.quiet) {
    std::fprintf(stderr, "[sampler] %d grains, %.0f m/s: dt = %.4g s, k_n = %.4g N/m, g = %.4g m/s^2\n", m.n_grains,
                 sp.speed, m.dt, m.kn, m.gravity.norm());
    for (const auto& r : sc.resolution)
      std::fprintf(stderr, "[sampler]   %s: %.1f steps per contact\n", r.label.c_str(), r.steps);
  }

  // 1. The relaxed bed at the shot's stiffness (horn parked far above).
  State s = sc.initial;
  s.bodies[b].pos = Vec3(0, 0, 100.0);
  RelaxedBed bed = relax_bed(sc, s, {b}, opt, "sampler");
  s = std::move(bed.state);
  ss->bed_cache = bed.cache;
  ss->rest_rms = rms_speed(m, s, -1);

  // 2. Perturbed repeat: the bed turned about the axis, the aim shifted
  // within one mean radius.
  double mean_r = 0, vol = 0, mass = 0, top = -1e300;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    mean_r += r;
    vol += 4.0 / 3.0 * kPi * r * r * r;
    mass += m.grain_inv_mass[i] > 0 ? 1 / m.grain_inv_mass[i] : 0;
    top = std::max(top, s.pos[i].z() + r);
  }
  if (m.n_grains == 0) throw InputError(file + ": key 'grains': the sampler needs a bed");
  mean_r /= m.n_grains;
  if (sp.repeat > 0) {
    std::mt19937_64 rng(sp.perturb_seed * 1000003ULL + static_cast<unsigned long>(sp.repeat));
    std::uniform_real_distribution<double> u(0, 1);
    ss->bed_rotation = 2 * kPi * u(rng);
    const double rad = mean_r * std::sqrt(u(rng)), phi = 2 * kPi * u(rng);
    ss->impact_shift = Vec3(rad * std::cos(phi), rad * std::sin(phi), 0);
    rotate_grains_about_z(m, s, ss->bed_rotation);
  }
  ss->bed_grains = m.n_grains;
  ss->bed_mass = mass;
  ss->bed_depth = top;
  const double box = kPi * sp.container_radius * sp.container_radius * top;
  ss->packing = vol / box;
  ss->bulk_density = mass / box;

  // 3. Surface heights: the highest grain centre (the ejecta line) and the
  // highest grain top under the projectile's path.
  const Vec3 aim(sp.offset + ss->impact_shift.x(), ss->impact_shift.y(), 0);
  double surf = -1e300, surf_top = -1e300, axis_top = -1e300;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    surf = std::max(surf, s.pos[i].z());
    surf_top = std::max(surf_top, s.pos[i].z() + r);
    const double d = std::hypot(s.pos[i].x() - aim.x(), s.pos[i].y() - aim.y());
    if (d < r + sp.radius) axis_top = std::max(axis_top, s.pos[i].z() + r);
  }
  ss->surface_ = surf;
  ss->surface_top = surf_top;
  ss->impact = Vec3(aim.x(), aim.y(), axis_top);

  // 4. The horn: axis vertical through the container's centre, bottom edge
  // horn_clearance above the highest grain top.
  BodyState& hb = s.bodies[b];
  const BodyModel& hm = m.bodies[b];
  const Vec3 origin(0, 0, surf_top + sp.horn_clearance);
  hb.q = hm.ref_rot.normalized();
  hb.pos = origin + hm.ref_pos;
  set_body_velocity(hm, hb, Vec3::Zero(), Vec3::Zero());
  ss->geometry = HornGeometry::shipped();
  ss->geometry.origin = origin;
  ss->geometry.axis = Vec3::UnitZ();
  s.rebuild_requested = true;

  // 5. The projectile: a grain of its own material (density from mass and
  // radius), its lowest point start_gap above the highest grain top on its
  // path, flying along the axis tilted by tilt_deg in the x-z plane.
  const double pvol = 4.0 / 3.0 * kPi * sp.radius * sp.radius * sp.radius;
  m.materials[proj_mat].density = sp.mass / pvol;
  ss->projectile_material = proj_mat;
  const double tilt = sp.tilt_deg * kPi / 180;
  ss->direction = Vec3(std::sin(tilt), 0, -std::cos(tilt));
  const double lift = sp.start_gap + sp.radius;
  const Vec3 p0 = ss->impact - ss->direction * (lift / std::cos(tilt));
  ss->projectile = add_grain(m, s, sp.radius, proj_mat, p0, ss->direction * sp.speed, Vec3::Zero());
  finalize_model(m);
  restart_at_zero(s);  // shot time counts from firing
  if (!opt.quiet)
    std::fprintf(stderr,
                 "[sampler] bed: %d grains, packing %.3f, bulk %.0f kg/m^3, rest RMS %.3g m/s; horn bottom at "
                 "z = %.4f m; projectile from (%.4f, %.4f, %.4f) m at %.0f m/s\n",
                 ss->bed_grains, ss->packing, ss->bulk_density, ss->rest_rms, origin.z(), p0.x(), p0.y(), p0.z(),
                 sp.speed);
  ss->start = std::move(s);
  ss->plan = RunPlan::open_ended(sc.name, "shot");
  ss->plan.stages[0].duration = sp.duration;
  ss->sample_every = sp.sample_every;
  return ss;
}

std::shared_ptr<const SceneKind> sampler_kind() { return std::make_shared<SamplerKind>(); }

}  // namespace rt
