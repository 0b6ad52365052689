// Landing set-up shared by the command-line tools and the ROS node.
#include "regolith_twin/observe/landing_scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "regolith_twin/observe/runner.hpp"
#include "regolith_twin/observe/series.hpp"
#include "regolith_twin/scene/checkpoint.hpp"

namespace rt {
namespace {

uint64_t fnv(const void* p, size_t n, uint64_t h) {
  const unsigned char* c = static_cast<const unsigned char*>(p);
  for (size_t i = 0; i < n; ++i) {
    h ^= c[i];
    h *= 1099511628211ULL;
  }
  return h;
}

// Key of a relaxed bed: grains, initial positions, materials, walls, bodies
// other than the lander (boulders), gravity, k_n, dt.
std::string bed_key(const Model& m, const State& s, int lander) {
  uint64_t h = 1469598103934665603ULL;
  h = fnv(m.grain_radius.data(), m.grain_radius.size() * sizeof(double), h);
  h = fnv(s.pos.data(), s.pos.size() * sizeof(Vec3), h);
  for (const auto& mat : m.materials) {
    const double v[] = {mat.density, mat.eps_n, mat.eps_t, mat.mu_s, mat.mu_r, mat.mu_t, mat.beta, mat.young};
    h = fnv(v, sizeof v, h);
  }
  for (const auto& w : m.walls) {
    const double v[] = {w.origin.x(), w.origin.y(), w.origin.z(), w.axis.x(), w.axis.y(), w.axis.z(), w.radius, w.length};
    h = fnv(v, sizeof v, h);
  }
  for (size_t k = 0; k < m.bodies.size(); ++k) {
    if (int(k) == lander) continue;
    const BodyModel& bm = m.bodies[k];
    const BodyState& bs = s.bodies[k];
    const double v[] = {bm.mass, bm.inertia.x(), bm.inertia.y(), bm.inertia.z(), double(bm.fixed), double(bm.material),
                        bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.q.w(), bs.q.x(), bs.q.y(), bs.q.z()};
    h = fnv(v, sizeof v, h);
    for (const Shape& sh : bm.shapes) {
      const double w[] = {double(sh.type), sh.size.x(), sh.size.y(), sh.size.z(), sh.pos.x(), sh.pos.y(), sh.pos.z()};
      h = fnv(w, sizeof w, h);
    }
  }
  const double v[] = {m.gravity.x(), m.gravity.y(), m.gravity.z(), m.kn, m.dt, m.skin, double(m.partitions)};
  h = fnv(v, sizeof v, h);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

const char* attitude_name(Attitude a) { return a == Attitude::Flat ? "Flat" : a == Attitude::BCF ? "BCF" : "FCF"; }

}  // namespace

std::string default_cache_dir() {
  const char* env = std::getenv("REGOLITH_CACHE");
  const char* home = std::getenv("HOME");
  return env ? env : std::string(home ? home : ".") + "/.cache/regolith_twin";
}

LandingScene prepare_landing(const std::string& file, const std::vector<std::string>& overrides,
                             const LandingSetupOptions& opt) {
  LandingScene ls;
  ls.file = file;
  YAML::Node root = load_document(file, overrides);
  ls.spec = parse_landing(root["landing"], file);
  root.remove("landing");
  ls.sc = parse_scenario(root, file);
  Scenario& sc = ls.sc;
  Model& m = sc.model;
  for (size_t k = 0; k < m.bodies.size(); ++k)
    if (m.bodies[k].name == ls.spec.lander) ls.lander = int(k);
  if (ls.lander < 0)
    throw InputError(file + ": key 'landing.lander': no body named '" + ls.spec.lander + "' under 'bodies'");
  const int b = ls.lander;
  m.gravity = landing_gravity(ls.spec);
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
  s.bodies[b].pos = Vec3(0, 0, ls.spec.rim + 100.0);
  set_body_velocity(m.bodies[b], s.bodies[b], Vec3::Zero(), Vec3::Zero());
  const std::string cache = opt.cache_dir.empty() ? default_cache_dir() : opt.cache_dir;
  make_dirs(cache + "/beds");
  ls.bed_cache = cache + "/beds/" + bed_key(m, s, b) + ".ckpt";
  if (std::ifstream(ls.bed_cache).good()) {
    s = load_checkpoint(ls.bed_cache, m);
    if (!opt.quiet) std::fprintf(stderr, "[landing] relaxed bed from the cache: %s\n", ls.bed_cache.c_str());
  } else {
    if (sc.stages.empty()) throw InputError(file + ": key 'stages': the bed relaxation stage is missing");
    if (!opt.quiet) std::fprintf(stderr, "[landing] relaxing the bed once (cached afterwards in %s)\n", ls.bed_cache.c_str());
    RunOptions ro;
    ro.out_dir = opt.relax_out;
    ro.progress_every = opt.quiet ? 0 : 5.0;
    const RunReport rr = run_scenario(sc, s, ro);
    if (rr.status != "ok") throw BlowUpError("bed relaxation: " + rr.message);
    if (!opt.quiet)
      std::fprintf(stderr, "[landing] bed relaxed in %.4g s simulated (%s)\n", rr.sim_time,
                   rr.stages.empty() ? "" : rr.stages.back().reason.c_str());
    save_checkpoint(ls.bed_cache, m, s);
  }
  // Bed figures: grains below the trim plane in the container.
  double vol = 0, mean_r = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    mean_r += r;
    if (s.pos[i].z() <= ls.spec.rim) vol += 4.0 / 3.0 * M_PI * r * r * r;
  }
  mean_r /= std::max(1, m.n_grains);
  const double box = M_PI * ls.spec.container_radius * ls.spec.container_radius * ls.spec.rim;
  ls.packing = vol / box;
  ls.bulk_density = m.n_grains ? ls.packing * m.materials[m.grain_material[0]].density : 0;

  // 2. Perturbed repeat and placement.
  ls.pert = perturbation(ls.spec, mean_r);
  ls.run_spec = ls.spec;
  if (ls.spec.repeat > 0) {
    rotate_bed(m, s, ls.pert.angle);
    ls.run_spec.aim += ls.pert.aim_offset;
  }
  s.time = 0;  // landing time counts from the start of the approach
  place_lander(m, s, b, ls.run_spec);
  ls.start = std::move(s);
  return ls;
}

void write_landing_summary(const std::string& path, const LandingScene& ls, const LandingOutcome& o, int threads) {
  const LandingSpec& spec = ls.spec;
  const Model& m = ls.sc.model;
  JsonObject j;
  j.str("scenario", ls.sc.name).str("file", ls.file).str("status", o.status);
  if (!o.message.empty()) j.str("message", o.message);
  JsonObject in;
  in.str("attitude", attitude_name(spec.attitude));
  in.num("angle_deg", spec.angle_deg).num("speed", spec.speed).num("gravity", spec.g).num("slope_deg", spec.slope_deg);
  in.num("pitch_deg", spec.pitch_deg).num("roll_deg", spec.roll_deg).num("heading_deg", spec.heading_deg);
  in.num("repeat", double(spec.repeat)).num("bed_rotation_deg", ls.pert.angle * 180 / M_PI);
  in.nums("aim", {ls.run_spec.aim.x(), ls.run_spec.aim.y()});
  j.obj("input", in);
  JsonObject bed;
  bed.num("grains", m.n_grains).num("trim_plane", spec.rim).num("packing_fraction", ls.packing);
  bed.num("bulk_density", ls.bulk_density).str("cache", ls.bed_cache);
  j.obj("bed", bed);
  JsonObject oc;
  oc.boolean("contact", o.contact).boolean("lifted_off", o.lifted_off).str("ended_by", o.ended_by);
  oc.num("cancelled_liftoffs", o.relandings);
  oc.num("t_contact", o.t_contact).num("t_liftoff", o.t_liftoff).num("t_end", o.t_end);
  oc.num("v_in", o.v_in).num("v_out", o.v_out).num("speed_ratio", o.speed_ratio);
  oc.num("E_lin_in", o.e_lin_in).num("E_rot_in", o.e_rot_in).num("E_lin_out", o.e_lin_out).num("E_rot_out", o.e_rot_out);
  oc.num("E_rot_out_over_E_lin_in", o.rot_out_over_lin_in).num("E_rot_out_over_E_lin_out", o.rot_out_over_lin_out);
  oc.num("energy_ratio", o.energy_ratio).num("angle_out_deg", o.angle_out_deg).num("spin_out", o.spin_out);
  oc.num("collision_duration", o.collision_duration).num("max_penetration", o.max_penetration);
  oc.num("h_liftoff", o.h_liftoff).num("travel_distance", o.travel_distance).num("travel_time", o.travel_time);
  oc.num("second_impact_speed", o.second_impact_speed).num("second_impact_angle_deg", o.second_impact_angle_deg);
  oc.num("ejected_volume", o.ejected_volume).num("ejected_grains", double(o.ejected_grains));
  oc.num("far_field_rms_speed", o.far_field_rms).num("max_overlap_ratio", o.max_overlap_ratio);
  oc.num("active_radius", spec.active_radius).num("active_grains", double(o.active_grains));
  oc.num("active_edge_rms_speed", o.active_edge_rms);
  j.obj("outcome", oc);
  JsonObject run;
  run.num("steps", double(o.steps)).num("wall_seconds", o.wall_seconds).num("dt", m.dt).num("kn", m.kn);
  if (threads > 0) run.num("threads", threads);
  j.obj("run", run);
  j.write(path);
}

}  // namespace rt
