// Stage runner with observers and progress output.
#include "regolith_twin/observe/runner.hpp"
#include "regolith_twin/scene/snapshot.hpp"


#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/observe/series.hpp"

namespace rt {
namespace {

using Clock = std::chrono::steady_clock;

// Groups small enough to follow individually in the series (impactors, probes).
constexpr int kTrackedGroupMax = 8;

struct Speeds {
  double rms = 0, max = 0;
};

Speeds grain_speeds(const Model& m, const State& s, const std::vector<uint8_t>& held) {
  double sum = 0, mx = 0;
  long n = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (m.grain_inv_mass[i] == 0 || held[i]) continue;
    const double v2 = s.vel[i].squaredNorm();
    sum += v2;
    mx = std::max(mx, v2);
    ++n;
  }
  return {n ? std::sqrt(sum / n) : 0.0, std::sqrt(mx)};
}

Vec3 group_mean(const std::vector<Vec3>& a, const GrainGroup& g) {
  Vec3 c = Vec3::Zero();
  for (int i = g.first; i < g.first + g.count; ++i) c += a[i];
  return c / g.count;
}

std::string clock_text(double seconds) {
  char b[32];
  const long s = long(seconds + 0.5);
  if (s >= 3600)
    std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(b, sizeof b, "%ld:%02ld", s / 60, s % 60);
  return b;
}

void write_final(const std::string& path, const Model& m, const State& s) {
  std::ofstream f(path);
  f << "# id x y z radius vx vy vz  (SI units)\n";
  f.precision(10);
  for (int i = 0; i < m.n_grains; ++i)
    f << i << ' ' << s.pos[i].x() << ' ' << s.pos[i].y() << ' ' << s.pos[i].z() << ' ' << m.grain_radius[i] << ' '
      << s.vel[i].x() << ' ' << s.vel[i].y() << ' ' << s.vel[i].z() << '\n';
}

}  // namespace

RunReport run_scenario(Scenario& sc, State& s, const RunOptions& opt) {
  const Model& m = sc.model;
  RunReport rep;
  const bool write = !opt.out_dir.empty();
  if (write) make_dirs(opt.out_dir);

  std::vector<const GrainGroup*> tracked;
  for (const auto& g : sc.groups)
    if (g.count <= kTrackedGroupMax) tracked.push_back(&g);
  std::vector<std::string> cols = {"t",           "step",          "E_trans",        "E_rot",      "E_pot",
                                   "E_elastic",   "E_total",       "contacts",       "wall_contacts",
                                   "coordination", "max_overlap_ratio", "rms_speed", "max_speed"};
  for (const auto* g : tracked)
    for (const char* c : {"_x", "_y", "_z", "_vx", "_vy", "_vz"}) cols.push_back(g->name + c);
  CsvSeries series;
  if (write) series.open(opt.out_dir + "/series.csv", cols);

  std::vector<uint8_t> held(m.n_grains, 0);
  if (!s.forces_valid) prime(m, s);
  rep.initial = energy(m, s);
  auto sample = [&] {
    const Energy e = energy(m, s);
    const Speeds sp = grain_speeds(m, s, held);
    std::vector<double> row = {s.time,
                               double(s.step),
                               e.translational,
                               e.rotational,
                               e.potential,
                               e.elastic,
                               e.total(),
                               double(s.stats.contacts),
                               double(s.stats.wall_contacts),
                               coordination_number(m, s),
                               s.stats.max_overlap_ratio,
                               sp.rms,
                               sp.max};
    for (const auto* g : tracked) {
      const Vec3 p = group_mean(s.pos, *g), v = group_mean(s.vel, *g);
      row.insert(row.end(), {p.x(), p.y(), p.z(), v.x(), v.y(), v.z()});
    }
    series.row(row);
  };

  double total_time = 0;
  for (const auto& st : sc.stages) total_time += st.duration;
  const auto t0 = Clock::now();
  auto last_progress = t0;
  const double t_start = s.time;
  double next_sample = s.time;

  try {
    for (size_t k = 0; k < sc.stages.size(); ++k) {
      const Stage& st = sc.stages[k];
      int removed = 0;
      if (st.trim) {  // remove every grain above the trim height
        std::vector<uint8_t> drop(m.n_grains, 0);
        for (int i = 0; i < m.n_grains; ++i) drop[i] = s.pos[i].z() > st.trim_above;
        removed = remove_grains(sc, s, drop);
        held.assign(m.n_grains, 0);
      }
      if (st.stiffness_scale > 0 && sc.scene_kn > 0) {
        // Same steps per contact at the new stiffness. Live springs keep their
        // extension; the law table is rebuilt for the new k_n.
        sc.model.kn = sc.scene_kn * st.stiffness_scale;
        if (sc.scene_body_kn > 0) sc.model.body_kn = sc.scene_body_kn * st.stiffness_scale;
        sc.model.dt = sc.scene_dt / std::sqrt(st.stiffness_scale);
        finalize_model(sc.model);
        s.forces_valid = false;
      }
      const Vec3 g_from = m.gravity;
      if (st.set_gravity && st.gravity_ramp <= 0) sc.model.gravity = st.gravity;
      const double t_ramp0 = s.time;
      std::fill(held.begin(), held.end(), 0);
      std::vector<Vec3> held_pos;
      std::vector<int> held_ids;
      for (const auto& name : st.remove_walls)
        for (size_t w = 0; w < m.walls.size(); ++w)
          if (m.walls[w].name == name) {
            s.wall_on[w] = 0;
            s.rebuild_requested = true;
          }
      for (const auto& name : st.hold) {
        const GrainGroup* g = sc.group(name);
        for (int i = g->first; i < g->first + g->count; ++i) {
          held[i] = 1;
          held_ids.push_back(i);
          held_pos.push_back(s.pos[i]);
        }
      }
      const double t_stage1 = s.time + st.duration;
      double next_check = s.time + st.check_every;
      double next_quench = s.time + st.quench_every;
      StageReport sr{st.name, 0, "duration", removed};
      while (s.time < t_stage1 - 0.5 * m.dt) {
        if (st.set_gravity && st.gravity_ramp > 0) {
          // Geometric in magnitude, linear in direction, over gravity_ramp seconds.
          const double f = std::min(1.0, (s.time - t_ramp0) / st.gravity_ramp);
          const double a = g_from.norm(), b = st.gravity.norm();
          if (f >= 1.0 || a == 0 || b == 0) {
            sc.model.gravity = f >= 1.0 ? st.gravity : Vec3(g_from + f * (st.gravity - g_from));
          } else {
            const Vec3 dir = ((1 - f) * g_from / a + f * st.gravity / b).normalized();
            sc.model.gravity = dir * (a * std::pow(b / a, f));
          }
        }
        if (s.time >= next_sample - 0.5 * m.dt) {
          if (write) sample();
          next_sample += sc.output_every;
        }
        step(m, s);
        if (st.minimize) {
          const int n = m.n_grains;
          const Vec3 g = m.gravity;
#pragma omp parallel for schedule(static) if (n >= m.parallel_min_grains)
          for (int i = 0; i < n; ++i) {
            if (m.grain_inv_mass[i] == 0) continue;
            const Vec3 f = s.force[i] + g / m.grain_inv_mass[i];
            const double p = s.vel[i].dot(f), f2 = f.squaredNorm();
            s.vel[i] = p > 0 && f2 > 0 ? Vec3(f * (p / f2)) : Vec3::Zero();
            const double pw = s.omega[i].dot(s.torque[i]), t2 = s.torque[i].squaredNorm();
            s.omega[i] = pw > 0 && t2 > 0 ? Vec3(s.torque[i] * (pw / t2)) : Vec3::Zero();
          }
        }
        if (st.release_springs) {
          for (auto* l : {&s.pairs.spring_t, &s.pairs.spring_r, &s.wall_pairs.spring_t, &s.wall_pairs.spring_r})
            std::fill(l->begin(), l->end(), Vec3::Zero());
          std::fill(s.pairs.spring_w.begin(), s.pairs.spring_w.end(), 0.0);
          std::fill(s.wall_pairs.spring_w.begin(), s.wall_pairs.spring_w.end(), 0.0);
        }
        if (st.quench_every > 0 && s.time >= next_quench - 0.5 * m.dt) {
          next_quench += st.quench_every;
          for (int i = 0; i < m.n_grains; ++i) {
            s.vel[i].setZero();
            s.omega[i].setZero();
          }
        }
        rep.max_overlap_ratio = std::max(rep.max_overlap_ratio, s.stats.max_overlap_ratio);
        for (size_t h = 0; h < held_ids.size(); ++h) {  // held grains stay put
          s.pos[held_ids[h]] = held_pos[h];
          s.vel[held_ids[h]].setZero();
          s.omega[held_ids[h]].setZero();
        }
        if ((st.until_rms_speed >= 0 || st.until_max_speed >= 0) && s.time >= next_check) {
          next_check += st.check_every;
          const Speeds sp = grain_speeds(m, s, held);
          if ((st.until_rms_speed < 0 || sp.rms < st.until_rms_speed) &&
              (st.until_max_speed < 0 || sp.max < st.until_max_speed)) {
            sr.reason = "criteria";
            break;
          }
        }
        if (opt.progress_every > 0) {
          const auto now = Clock::now();
          if (std::chrono::duration<double>(now - last_progress).count() >= opt.progress_every) {
            last_progress = now;
            const double wall = std::chrono::duration<double>(now - t0).count();
            // Remaining: this stage's rest plus the later stages (at most).
            double left = t_stage1 - s.time;
            for (size_t q = k + 1; q < sc.stages.size(); ++q) left += sc.stages[q].duration;
            const double rate = (s.time - t_start) / std::max(wall, 1e-9);
            const double steps_s = double(s.step) / std::max(wall, 1e-9);
            std::fprintf(stderr, "[%s] stage %zu/%zu '%s'  t = %.4g s of %.4g s  %.3g steps/s  %.3g grain-steps/s  ETA %s\n",
                         sc.name.c_str(), k + 1, sc.stages.size(), st.name.c_str(), s.time, total_time, steps_s,
                         steps_s * m.n_grains, clock_text(left / std::max(rate, 1e-300)).c_str());
          }
        }
      }
      sr.t_end = s.time;
      rep.stages.push_back(sr);
      if (write && opt.stage_snapshots) write_snapshot(opt.out_dir + "/" + st.name + ".bed", m, s);
    }
    if (write) sample();
  } catch (const BlowUpError& e) {
    rep.status = "blow_up";
    rep.message = e.what();
  }
  rep.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  rep.steps = s.step;
  rep.sim_time = s.time;
  if (rep.status == "ok") rep.final = energy(m, s);

  if (write) {
    series.close();
    if (rep.status == "ok") write_final(opt.out_dir + "/final_grains.txt", m, s);
    JsonObject j;
    j.str("scenario", sc.name).str("file", sc.file).str("status", rep.status);
    if (!rep.message.empty()) j.str("message", rep.message);
    j.num("grains", m.n_grains).num("walls", double(m.walls.size()));
    j.str("contact_model", m.contact_model == ContactModel::Linear ? "linear" : "hertz_mindlin");
    j.num("kn", m.kn).num("dt", m.dt).num("skin", m.skin).num("partitions", m.partitions).num("threads", opt.threads);
    j.num("steps", double(rep.steps)).num("sim_time", rep.sim_time).num("wall_seconds", rep.wall_seconds);
    j.num("steps_per_second", rep.steps / std::max(rep.wall_seconds, 1e-9));
    j.num("grain_steps_per_second", double(rep.steps) * m.n_grains / std::max(rep.wall_seconds, 1e-9));
    j.num("list_rebuilds", double(s.rebuilds)).num("max_overlap_ratio", rep.max_overlap_ratio);
    JsonObject res;
    for (const auto& r : sc.resolution) res.num(r.label, r.steps);
    j.obj("steps_per_contact", res);
    JsonObject warn;
    for (size_t i = 0; i < sc.warnings.size(); ++i) warn.str(std::to_string(i), sc.warnings[i]);
    j.obj("warnings", warn);
    auto energy_json = [](const Energy& e) {
      JsonObject o;
      o.num("translational", e.translational).num("rotational", e.rotational).num("potential", e.potential);
      o.num("elastic", e.elastic).num("total", e.total());
      return o;
    };
    j.obj("energy_initial", energy_json(rep.initial));
    if (rep.status == "ok") j.obj("energy_final", energy_json(rep.final));
    JsonObject stages;
    for (const auto& r : rep.stages) {
      JsonObject o;
      o.num("t_end", r.t_end).str("ended_by", r.reason);
      if (r.grains_removed) o.num("grains_removed", r.grains_removed);
      stages.obj(r.name, o);
    }
    j.obj("stages", stages);
    JsonObject groups;
    for (const auto* g : tracked) {
      const Vec3 p = group_mean(s.pos, *g), v = group_mean(s.vel, *g);
      JsonObject o;
      o.nums("position", {p.x(), p.y(), p.z()}).nums("velocity", {v.x(), v.y(), v.z()});
      groups.obj(g->name, o);
    }
    j.obj("tracked_groups", groups);
    j.write(opt.out_dir + "/summary.json");
  }
  return rep;
}

}  // namespace rt
