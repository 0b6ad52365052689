// regolith_land: one lander touchdown on a prepared bed (SCENARIOS.md A).
//   regolith_land LANDING.yaml [--out DIR] [--threads N] [--set key=value ...] [--cache DIR] [--quiet]
// The file is a scenario (materials, walls, bodies, grains from a bed
// snapshot) plus a `landing:` block. The bed is first relaxed under the scene
// gravity with the lander parked away; the relaxed state is cached as an
// exact checkpoint, so later landings on the same bed start from it
// bit-identically. Exit codes: 0 done, 2 bad input, 3 numerical blow-up, 1 other.
#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/observe/landing.hpp"
#include "regolith_twin/observe/runner.hpp"
#include "regolith_twin/observe/series.hpp"
#include "regolith_twin/scene/checkpoint.hpp"
#include "regolith_twin/scene/scenario.hpp"

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: regolith_land LANDING.yaml [--out DIR] [--threads N] [--set key=value]... [--cache DIR] [--quiet]\n"
               "  --out DIR     summary.json, series.csv, surface.csv (default out/<name>)\n"
               "  --set k=v     override a key, e.g. --set landing.angle_deg=60 --set landing.attitude=Flat\n"
               "  --cache DIR   where relaxed beds are kept (default $REGOLITH_CACHE or ~/.cache/regolith_twin)\n"
               "  --threads N   OpenMP threads (default: all cores)\n");
}

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
std::string bed_key(const rt::Model& m, const rt::State& s, int lander) {
  uint64_t h = 1469598103934665603ULL;
  h = fnv(m.grain_radius.data(), m.grain_radius.size() * sizeof(double), h);
  h = fnv(s.pos.data(), s.pos.size() * sizeof(rt::Vec3), h);
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
    const rt::BodyModel& bm = m.bodies[k];
    const rt::BodyState& bs = s.bodies[k];
    const double v[] = {bm.mass, bm.inertia.x(), bm.inertia.y(), bm.inertia.z(), double(bm.fixed), double(bm.material),
                        bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.q.w(), bs.q.x(), bs.q.y(), bs.q.z()};
    h = fnv(v, sizeof v, h);
    for (const rt::Shape& sh : bm.shapes) {
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

void make_dirs(const std::string& path) {
  std::string cur;
  std::stringstream ss(path);
  if (!path.empty() && path[0] == '/') cur = "/";
  for (std::string part; std::getline(ss, part, '/');) {
    if (part.empty()) continue;
    cur += part + "/";
    ::mkdir(cur.c_str(), 0755);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, out, cache;
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "regolith_land: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") out = value("--out");
    else if (a == "--cache") cache = value("--cache");
    else if (a == "--set") overrides.push_back(value("--set"));
    else if (a == "--quiet") quiet = true;
    else if (a == "--threads") {
      const std::string v = value("--threads");
      char* end = nullptr;
      threads = int(std::strtol(v.c_str(), &end, 10));
      if (*end || threads < 1 || threads > 256) {
        std::fprintf(stderr, "regolith_land: --threads '%s': expected an integer in [1, 256]\n", v.c_str());
        return 2;
      }
    } else if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "regolith_land: unknown option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    } else if (file.empty()) file = a;
    else {
      std::fprintf(stderr, "regolith_land: only one landing file may be given\n");
      return 2;
    }
  }
  if (file.empty()) {
    usage(stderr);
    return 2;
  }
#ifdef _OPENMP
  if (threads > 0) omp_set_num_threads(threads);
#endif
  if (cache.empty()) {
    const char* env = std::getenv("REGOLITH_CACHE");
    const char* home = std::getenv("HOME");
    cache = env ? env : std::string(home ? home : ".") + "/.cache/regolith_twin";
  }
  try {
    YAML::Node root = rt::load_document(file, overrides);
    const rt::LandingSpec spec = rt::parse_landing(root["landing"], file);
    root.remove("landing");
    rt::Scenario sc = rt::parse_scenario(root, file);
    rt::Model& m = sc.model;
    int b = -1;
    for (size_t k = 0; k < m.bodies.size(); ++k)
      if (m.bodies[k].name == spec.lander) b = int(k);
    if (b < 0) throw rt::InputError(file + ": key 'landing.lander': no body named '" + spec.lander + "' under 'bodies'");
    m.gravity = rt::landing_gravity(spec);
    if (out.empty()) out = "out/" + sc.name;
    make_dirs(out);
    for (const auto& w : sc.warnings) std::fprintf(stderr, "regolith_land: warning: %s\n", w.c_str());
    if (!quiet && sc.carved_grains > 0)
      std::fprintf(stderr, "[landing] %d grains removed to make room for buried bodies\n", sc.carved_grains);
    if (!quiet) {
      std::fprintf(stderr, "[landing] %d grains, dt = %.4g s, k_n = %.4g N/m, g = %.4g m/s^2\n", m.n_grains, m.dt, m.kn,
                   m.gravity.norm());
      for (const auto& r : sc.resolution)
        std::fprintf(stderr, "[landing]   %s: %.1f steps per contact\n", r.label.c_str(), r.steps);
    }

    // 1. The relaxed bed: from the cache, or relaxed now (lander parked far above).
    rt::State s = sc.initial;
    s.bodies[b].pos = rt::Vec3(0, 0, spec.rim + 100.0);
    rt::set_body_velocity(m.bodies[b], s.bodies[b], rt::Vec3::Zero(), rt::Vec3::Zero());
    make_dirs(cache + "/beds");
    const std::string ckpt = cache + "/beds/" + bed_key(m, s, b) + ".ckpt";
    if (std::ifstream(ckpt).good()) {
      s = rt::load_checkpoint(ckpt, m);
      if (!quiet) std::fprintf(stderr, "[landing] relaxed bed from the cache: %s\n", ckpt.c_str());
    } else {
      if (sc.stages.empty()) throw rt::InputError(file + ": key 'stages': the bed relaxation stage is missing");
      if (!quiet) std::fprintf(stderr, "[landing] relaxing the bed once (cached afterwards in %s)\n", ckpt.c_str());
      rt::RunOptions ro;
      ro.out_dir = out + "/bed_relax";
      ro.progress_every = quiet ? 0 : 5.0;
      const rt::RunReport rr = rt::run_scenario(sc, s, ro);
      if (rr.status != "ok") {
        std::fprintf(stderr, "regolith_land: bed relaxation: %s\n", rr.message.c_str());
        return 3;
      }
      if (!quiet)
        std::fprintf(stderr, "[landing] bed relaxed in %.4g s simulated (%s)\n", rr.sim_time,
                     rr.stages.empty() ? "" : rr.stages.back().reason.c_str());
      rt::save_checkpoint(ckpt, m, s);
    }
    // Bed figures: grains below the trim plane in the container.
    double vol = 0, mean_r = 0;
    for (int i = 0; i < m.n_grains; ++i) {
      const double r = m.grain_radius[i];
      mean_r += r;
      if (s.pos[i].z() <= spec.rim) vol += 4.0 / 3.0 * M_PI * r * r * r;
    }
    mean_r /= std::max(1, m.n_grains);
    const double box = M_PI * spec.container_radius * spec.container_radius * spec.rim;
    const double packing = vol / box;
    const double density = m.n_grains ? m.materials[m.grain_material[0]].density : 0;

    // 2. Perturbed repeat, placement, landing.
    const rt::Perturbation pert = rt::perturbation(spec, mean_r);
    rt::LandingSpec run_spec = spec;
    if (spec.repeat > 0) {
      rt::rotate_bed(m, s, pert.angle);
      run_spec.aim += pert.aim_offset;
    }
    s.time = 0;  // landing time counts from the start of the approach
    rt::place_lander(m, s, b, run_spec);
    rt::LandingOptions lo;
    lo.out_dir = out;
    lo.progress_every = quiet ? 0 : 2.0;
    const rt::LandingOutcome o = rt::run_landing(m, s, b, run_spec, lo);
    rt::write_surface(out + "/surface.csv", m, s, run_spec, 0.01);

    rt::JsonObject j;
    j.str("scenario", sc.name).str("file", file).str("status", o.status);
    if (!o.message.empty()) j.str("message", o.message);
    rt::JsonObject in;
    in.str("attitude", spec.attitude == rt::Attitude::Flat ? "Flat" : spec.attitude == rt::Attitude::BCF ? "BCF" : "FCF");
    in.num("angle_deg", spec.angle_deg).num("speed", spec.speed).num("gravity", spec.g).num("slope_deg", spec.slope_deg);
    in.num("pitch_deg", spec.pitch_deg).num("roll_deg", spec.roll_deg).num("heading_deg", spec.heading_deg);
    in.num("repeat", double(spec.repeat)).num("bed_rotation_deg", pert.angle * 180 / M_PI);
    in.nums("aim", {run_spec.aim.x(), run_spec.aim.y()});
    j.obj("input", in);
    rt::JsonObject bed;
    bed.num("grains", m.n_grains).num("trim_plane", spec.rim).num("packing_fraction", packing);
    bed.num("bulk_density", packing * density).str("cache", ckpt);
    j.obj("bed", bed);
    rt::JsonObject oc;
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
    rt::JsonObject run;
    run.num("steps", double(o.steps)).num("wall_seconds", o.wall_seconds).num("dt", m.dt).num("kn", m.kn);
#ifdef _OPENMP
    run.num("threads", omp_get_max_threads());
#endif
    j.obj("run", run);
    j.write(out + "/summary.json");
    if (o.status != "ok") {
      std::fprintf(stderr, "regolith_land: %s\nregolith_land: outputs written so far are in %s/\n", o.message.c_str(),
                   out.c_str());
      return 3;
    }
    std::printf("landing %s: %s, speed ratio %.3f, collision %.3g s, penetration %.3g m, travel %.3g m (%.0f s wall)\n",
                sc.name.c_str(), o.lifted_off ? "lifted off" : "no lift-off", o.speed_ratio, o.collision_duration,
                o.max_penetration, o.travel_distance, o.wall_seconds);
    std::printf("summary:     %s/summary.json\ntime series: %s/series.csv\nsurface:     %s/surface.csv\n", out.c_str(),
                out.c_str(), out.c_str());
    return 0;
  } catch (const rt::InputError& e) {
    std::fprintf(stderr, "regolith_land: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "regolith_land: error: %s\n", e.what());
    return 1;
  }
}
