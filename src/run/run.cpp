// The one run loop (see run.hpp).
#include "regolith_twin/run/run.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/sleep.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/io/snapshot.hpp"

namespace rt {

using Clock = std::chrono::steady_clock;

GrainSpeeds grain_speeds(const Model& m, const State& s, const std::vector<uint8_t>& skip) {
  double sum = 0, mx = 0;
  long n = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (m.grain_inv_mass[i] == 0 || skip[i]) continue;
    const double v2 = s.vel[i].squaredNorm();
    sum += v2;
    mx = std::max(mx, v2);
    ++n;
  }
  return {n ? std::sqrt(sum / n) : 0.0, std::sqrt(mx)};
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

RunPlan RunPlan::of(const Scenario& sc) {
  RunPlan p;
  p.name = sc.name;
  p.stages = sc.stages;
  p.groups = sc.groups;
  p.scene_kn = sc.scene_kn;
  p.scene_dt = sc.scene_dt;
  p.scene_body_kn = sc.scene_body_kn;
  return p;
}

RunPlan RunPlan::open_ended(const std::string& name, const std::string& stage) {
  RunPlan p;
  p.name = name;
  Stage st;
  st.name = stage;
  st.duration = std::numeric_limits<double>::infinity();
  p.stages.push_back(st);
  return p;
}

Run::Run(Model& m, State& s, RunPlan plan, const RunOptions& opt)
    : m_(m), s_(s), plan_(std::move(plan)), opt_(opt) {}

Run::~Run() = default;

void Run::add_observer(Observer* o) { obs_.push_back(o); }

bool Run::ended() { return !settle(); }

// The first call: observers prepared, forces primed, observers started, the
// series opened. Then stage transitions up to the next step.

bool Run::settle() {
  if (ended_) return false;
  if (!started_) {
    started_ = true;
    t0_ = last_progress_ = Clock::now();
    t_start_ = s_.time;
    step0_ = s_.step;
    rebuilds0_ = s_.rebuilds;
    body_rebuilds0_ = s_.body_rebuilds;
    awake0_ = s_.sleep.awake_grain_steps;
    next_sample_ = s_.time;
    for (Observer* o : obs_) o->prepare(m_, s_);
    if (!s_.forces_valid) prime(m_, s_);
    for (Observer* o : obs_) o->start(m_, s_);
    schedule_start();
    if (!opt_.out_dir.empty()) {
      make_dirs(opt_.out_dir);
      // A summary of an earlier run would look finished beside this run's
      // partial series (docs/files.md, outputs): e.g. a landing's
      // bed_relax/ folder, relaxed again after a run was killed.
      const std::string summary = opt_.out_dir + "/summary.json";
      if (std::remove(summary.c_str()) != 0 && errno != ENOENT)
        throw InputError(summary + ": cannot remove the summary of an earlier run (" + std::strerror(errno) + ")");
      std::vector<std::string> cols = {"t"};
      for (const Observer* o : obs_) o->columns(cols);
      series_.open(opt_.out_dir + "/series.csv", cols);
    }
  }
  for (;;) {
    if (in_stage_) {
      if (s_.time < t_stage_end_ - 0.5 * m_.dt) return true;
      end_stage("duration");
    }
    if (k_ >= plan_.stages.size()) {
      ended_ = true;
      return false;
    }
    begin_stage();
  }
}

// Stage start: trim, stiffness, gravity, walls taken away, groups held.
void Run::begin_stage() {
  const Stage& st = plan_.stages[k_];
  energy_watch_.reset();
  int removed = 0;
  if (st.trim) {  // every grain above the trim height goes (its centre, or its top with trim_tops)
    std::vector<uint8_t> drop(m_.n_grains, 0);
    for (int i = 0; i < m_.n_grains; ++i)
      drop[i] = s_.pos[i].z() + (st.trim_tops ? m_.grain_radius[i] : 0.0) > st.trim_above;
    removed = remove_grains(m_, s_, drop, plan_.groups);
  }
  double injected = 0, kinetic = 0;
  if (st.stiffness_scale > 0 && plan_.scene_kn > 0) {
    // Same steps per contact at the new stiffness. Live springs keep their
    // extension; the law table is rebuilt for the new k_n. Changing k_n on
    // live contacts changes their elastic energy at fixed positions
    // (Σ ½ Δk x² and the spring terms that scale with k_n): measured here
    // against the grains' kinetic energy (docs/model.md §4).
    const double kn_old = m_.kn;
    const double el_old = energy(m_, s_).elastic;
    m_.kn = plan_.scene_kn * st.stiffness_scale;
    if (plan_.scene_body_kn > 0) m_.body_kn = plan_.scene_body_kn * st.stiffness_scale;
    m_.dt = plan_.scene_dt / std::sqrt(st.stiffness_scale);
    finalize_model(m_);
    s_.forces_valid = false;
    if (m_.kn != kn_old) {
      const Energy e = energy(m_, s_);
      injected = e.elastic - el_old;
      kinetic = e.kinetic();
      const double frac = kinetic > 0 ? injected / kinetic : (injected > 0 ? INFINITY : 0.0);
      if (opt_.progress_every > 0)
        std::fprintf(stderr,
                     "[%s] stage '%s': k_n %.4g -> %.4g N/m, dt %.4g s; elastic energy changed by %.3g J "
                     "(%.3g %% of the kinetic energy %.3g J)\n",
                     plan_.name.c_str(), st.name.c_str(), kn_old, m_.kn, m_.dt, injected, 100 * frac, kinetic);
      if (st.max_injection >= 0 && frac > st.max_injection) {
        char b[400];
        std::snprintf(b, sizeof b,
                      "stage '%s': raising k_n from %.4g to %.4g N/m injects %.3g J, %.3g %% of the grains' kinetic "
                      "energy %.3g J (limit %.3g %%): relax further at the softer stiffness, or raise it in "
                      "smaller steps",
                      st.name.c_str(), kn_old, m_.kn, injected, 100 * frac, kinetic, 100 * st.max_injection);
        throw BlowUpError(b);
      }
    }
  }
  g_from_ = m_.gravity;
  if (st.set_gravity && st.gravity_ramp <= 0) m_.gravity = st.gravity;
  t_ramp0_ = s_.time;
  held_.assign(m_.n_grains, 0);
  held_ids_.clear();
  held_pos_.clear();
  for (const auto& name : st.remove_walls)
    for (size_t w = 0; w < m_.walls.size(); ++w)
      if (m_.walls[w].name == name) {
        s_.wall_on[w] = 0;
        s_.rebuild_requested = true;
      }
  for (const auto& name : st.hold)
    for (const GrainGroup& g : plan_.groups)
      if (g.name == name)
        for (int i = g.first; i < g.first + g.count; ++i) {
          held_[i] = 1;
          held_ids_.push_back(i);
          held_pos_.push_back(s_.pos[i]);
        }
  t_stage_end_ = s_.time + st.duration;
  next_check_ = s_.time + st.check_every;
  next_quench_ = s_.time + st.quench_every;
  sr_ = StageReport{st.name, 0, "duration", removed, injected, kinetic};
  in_stage_ = true;
}

void Run::end_stage(const char* reason) {
  sr_.reason = reason;
  sr_.t_end = s_.time;
  rep_.stages.push_back(sr_);
  if (!opt_.out_dir.empty() && opt_.stage_snapshots)
    write_snapshot(opt_.out_dir + "/" + plan_.stages[k_].name + ".bed", m_, s_);
  in_stage_ = false;
  ++k_;
}

bool Run::advance() {
  if (!settle()) return false;
  const Stage& st = plan_.stages[k_];
  if (st.set_gravity && st.gravity_ramp > 0) {
    // Geometric in magnitude, linear in direction, over gravity_ramp seconds.
    const double f = std::min(1.0, (s_.time - t_ramp0_) / st.gravity_ramp);
    const double a = g_from_.norm(), b = st.gravity.norm();
    if (f >= 1.0 || a == 0 || b == 0) {
      m_.gravity = f >= 1.0 ? st.gravity : Vec3(g_from_ + f * (st.gravity - g_from_));
    } else {
      const Vec3 dir = ((1 - f) * g_from_ / a + f * st.gravity / b).normalized();
      m_.gravity = dir * (a * std::pow(b / a, f));
    }
  }
  if (s_.time >= next_sample_ - 0.5 * m_.dt) {  // series row before the step
    if (!opt_.out_dir.empty()) sample();
    next_sample_ += opt_.sample_every;
  }
  if (s_.step == step0_ && s_.forces_valid) watch_energy();  // the energy guard's first reference
  step(m_, s_);
  if (st.minimize) {  // quick-min: keep only the velocity along the net force
    const int n = m_.n_grains;
    const Vec3 g = m_.gravity;
#pragma omp parallel for schedule(static) if (n >= m_.parallel_min_grains)
    for (int i = 0; i < n; ++i) {
      if (m_.grain_inv_mass[i] == 0) continue;
      const Vec3 f = s_.force[i] + g / m_.grain_inv_mass[i];
      const double p = s_.vel[i].dot(f), f2 = f.squaredNorm();
      s_.vel[i] = p > 0 && f2 > 0 ? Vec3(f * (p / f2)) : Vec3::Zero();
      const double pw = s_.omega[i].dot(s_.torque[i]), t2 = s_.torque[i].squaredNorm();
      s_.omega[i] = pw > 0 && t2 > 0 ? Vec3(s_.torque[i] * (pw / t2)) : Vec3::Zero();
    }
  }
  if (st.release_springs) {
    for (auto* l : {&s_.pairs.spring_t, &s_.pairs.spring_r, &s_.wall_pairs.spring_t, &s_.wall_pairs.spring_r})
      std::fill(l->begin(), l->end(), Vec3::Zero());
    std::fill(s_.pairs.spring_w.begin(), s_.pairs.spring_w.end(), 0.0);
    std::fill(s_.wall_pairs.spring_w.begin(), s_.wall_pairs.spring_w.end(), 0.0);
  }
  if (st.quench_every > 0 && s_.time >= next_quench_ - 0.5 * m_.dt) {
    next_quench_ += st.quench_every;
    for (int i = 0; i < m_.n_grains; ++i) {
      s_.vel[i].setZero();
      s_.omega[i].setZero();
    }
  }
  rep_.max_overlap_ratio = std::max(rep_.max_overlap_ratio, s_.stats.max_overlap_ratio);
  for (size_t h = 0; h < held_ids_.size(); ++h) {  // held grains stay put
    s_.pos[held_ids_[h]] = held_pos_[h];
    s_.vel[held_ids_[h]].setZero();
    s_.omega[held_ids_[h]].setZero();
  }
  const int n_before = m_.n_grains;
  add_grains();
  bool end = false;
  for (Observer* o : obs_) end = o->after_step(m_, s_) || end;
  remove_leaving();
  schedule_check(m_.n_grains > n_before);
  watch_energy();
  if (end) {
    rep_.ended_by_observer = true;
    end_stage("observer");
    ended_ = true;
    return true;
  }
  if ((st.until_rms_speed >= 0 || st.until_max_speed >= 0) && s_.time >= next_check_) {
    next_check_ += st.check_every;
    const GrainSpeeds sp = grain_speeds(m_, s_, held_);
    if ((st.until_rms_speed < 0 || sp.rms < st.until_rms_speed) &&
        (st.until_max_speed < 0 || sp.max < st.until_max_speed)) {
      end_stage("criteria");
      return true;
    }
  }
  if (opt_.progress_every > 0) progress();
  return true;
}

void Run::watch_energy() {
  const Guards& gd = m_.guards;
  if (!(gd.max_energy_growth > 0) || gd.energy_check_every <= 0) return;
  // Energy put in this step: a field, an applied wrench, the stiffness schedule, held grains, or
  // gravity along a periodic axis (a grain wrapped downhill keeps its speed but its potential
  // energy jumps up by m g L: an inclined periodic bed is driven without bound; docs/model.md §13).
  const bool periodic_drive = (m_.periodic.x && m_.gravity.x() != 0) || (m_.periodic.y && m_.gravity.y() != 0);
  bool input = !m_.fields.empty() || sched_on_ || !held_ids_.empty() || periodic_drive;
  for (size_t b = 0; b < s_.body_applied_force.size() && !input; ++b)
    input = s_.body_applied_force[b] != Vec3::Zero() || s_.body_applied_torque[b] != Vec3::Zero();
  energy_input_ = energy_input_ || input;
  if ((s_.step - step0_) % gd.energy_check_every != 0) return;
  if (energy_input_) {
    energy_watch_.reset();
    energy_input_ = false;
    return;
  }
  energy_watch_.check(m_, s_);
}

void Run::add_grains() {
  const int n_old = m_.n_grains;
  for (Observer* o : obs_) o->add_grains(m_, s_);
  if (m_.n_grains == n_old) return;
  energy_watch_.reset();
  if (int(held_.size()) == n_old) held_.resize(m_.n_grains, 0);
  drop_.assign(m_.n_grains, 0);
  for (Observer* o : obs_) o->grains_added(m_, s_, n_old);
}

void Run::remove_leaving() {
  if (int(drop_.size()) != m_.n_grains) drop_.assign(m_.n_grains, 0);  // all zero between steps
  bool any = false;
  for (Observer* o : obs_) any = o->leaving(m_, s_, drop_) || any;
  if (!any) return;
  const int n_old = m_.n_grains;
  remove_grains(m_, s_, drop_, plan_.groups, &old_to_new_);
  energy_watch_.reset();
  // Held grains follow their new numbers (a held grain that left is let go).
  std::vector<uint8_t> held(m_.n_grains, 0);
  size_t k = 0;
  for (size_t h = 0; h < held_ids_.size(); ++h) {
    const int j = old_to_new_[held_ids_[h]];
    if (j < 0) continue;
    held[j] = 1;
    held_ids_[k] = j;
    held_pos_[k++] = held_pos_[h];
  }
  held_ids_.resize(k);
  held_pos_.resize(k);
  if (int(held_.size()) == n_old) held_ = std::move(held);
  drop_.assign(m_.n_grains, 0);
  for (Observer* o : obs_) o->grains_removed(old_to_new_);
}

void Run::sample() {
  std::vector<double> row = {s_.time};
  for (const Observer* o : obs_) o->row(m_, s_, row);
  series_.row(row);
}

void Run::progress() {
  const auto now = Clock::now();
  if (std::chrono::duration<double>(now - last_progress_).count() < opt_.progress_every) return;
  last_progress_ = now;
  const double wall = std::chrono::duration<double>(now - t0_).count();
  const double steps_s = double(s_.step - step0_) / std::max(wall, 1e-9);
  const double rate = (s_.time - t_start_) / std::max(wall, 1e-9);
  // Time left: the rest of the stages with a duration, or what the observers know.
  double left = 0, total = s_.time;
  bool bounded = true;
  for (size_t q = k_; q < plan_.stages.size(); ++q) {
    const double d = q == k_ ? t_stage_end_ - s_.time : plan_.stages[q].duration;
    if (std::isfinite(d)) left += d;
    else bounded = false;
  }
  total += left;
  std::string text;
  double obs_left = -1;
  for (const Observer* o : obs_) {
    const std::string p = o->progress(m_, s_);
    if (!p.empty()) text += "  " + p;
    const double l = o->time_left(s_);
    if (l >= 0) obs_left = obs_left < 0 ? l : std::min(obs_left, l);
  }
  std::string eta = "ETA ?";
  if (bounded) eta = "ETA " + clock_text(left / std::max(rate, 1e-300));
  else if (obs_left >= 0) eta = "at most " + clock_text(obs_left / std::max(rate, 1e-300));
  char head[256];
  if (bounded)
    std::snprintf(head, sizeof head, "[%s] stage %zu/%zu '%s'  t = %.4g s of %.4g s (%.0f %%)", plan_.name.c_str(),
                  k_ + 1, plan_.stages.size(), plan_.stages[k_].name.c_str(), s_.time, total,
                  total > 0 ? 100 * s_.time / total : 100.0);
  else
    std::snprintf(head, sizeof head, "[%s] %s  t = %.4g s", plan_.name.c_str(), plan_.stages[k_].name.c_str(),
                  s_.time);
  if (sleep_active(m_, s_)) {
    char b[64];
    std::snprintf(b, sizeof b, "  awake %zu", s_.sleep.awake.size());
    text += b;
  }
  if (sched_on_) {
    char b[128];
    std::snprintf(b, sizeof b, "  dt %.3g s (v_fast %.3g m/s: %s)", m_.dt, sched_vfast_, sched_why_);
    text += b;
  }
  std::fprintf(stderr, "%s%s  %.3g steps/s  %.3g grain-steps/s  %s\n", head, text.c_str(), steps_s,
               steps_s * m_.n_grains, eta.c_str());
}

// --- stiffness schedule (docs/model.md §17) ----------------------------------

void Run::schedule_start() {
  sched_on_ = m_.schedule.enabled;
  if (!sched_on_) return;
  if (!(m_.schedule.speed > 0)) throw InputError("schedule.speed: the design speed must be > 0 m/s");
  for (const Stage& st : plan_.stages)
    if (st.stiffness_scale > 0)
      throw InputError("stage '" + st.name + "' sets a stiffness scale and the stiffness schedule "
                       "(schedule.enabled) sets k_n too: use one of them");
  // The model is the scene's (a resumed state carries the factor it ran at).
  sched_kn0_ = m_.kn;
  sched_body_kn0_ = m_.body_kn;
  sched_dt0_ = m_.dt;
  // Three durations of the longest contact, in steps (the same at any factor).
  double steps = 0;
  for (const PairResolution& r : pair_resolution(m_, m_.schedule.speed))
    if (r.label.rfind("body-body", 0) != 0) steps = std::max(steps, r.steps);  // contacts of grains
  sched_hold_ = std::max(1L, long(std::ceil(3 * steps)));
  ScheduleState& q = s_.schedule;
  if (!q.started) {  // a fresh start: the grains' speeds are measured now
    q = ScheduleState{};
    q.started = true;
    q.t_start = s_.time;
    q.dt_min = q.dt_max = m_.dt;
    schedule_check(true);
  } else if (q.scale != 1.0) {  // a resumed state runs on at the factor it was saved with
    set_stiffness_scale(q.scale, false);
  }
}

void Run::set_stiffness_scale(double scale, bool account) {
  ScheduleState& q = s_.schedule;
  const double el_old = account ? energy(m_, s_).elastic : 0.0;
  m_.kn = sched_kn0_ * scale;
  if (sched_body_kn0_ > 0) m_.body_kn = sched_body_kn0_ * scale;
  m_.dt = sched_dt0_ / std::sqrt(scale);
  finalize_model(m_);
  s_.tick_len = m_.dt / sched_dt0_;
  if (account) {
    // Live contacts keep their overlaps and springs: their elastic energy
    // changes with k_n (Σ ½ Δk x² and the spring terms that scale with it).
    const Energy e = energy(m_, s_);
    const double d = e.elastic - el_old, kin = e.kinetic();
    if (scale > q.scale) {
      ++q.raised;
      q.injected += d;
      q.max_injected_fraction = std::max(q.max_injected_fraction, kin > 0 ? d / kin : (d > 0 ? INFINITY : 0.0));
    } else {
      ++q.lowered;
      q.released -= d;
    }
    s_.forces_valid = false;  // forces of the new law before the next step
    if (opt_.progress_every > 0)
      std::fprintf(stderr, "[%s] t = %.6g s: k_n %.4g -> %.4g N/m (x%.3g of the scene's), dt %.4g s%s\n",
                   plan_.name.c_str(), s_.time, sched_kn0_ * q.scale, m_.kn, scale, m_.dt,
                   scale > q.scale ? " (raised: a faster grain or body)" : "");
  }
  q.scale = scale;
  q.min_scale = std::min(q.min_scale, scale);
  q.dt_min = q.dt_min > 0 ? std::min(q.dt_min, m_.dt) : m_.dt;
  q.dt_max = std::max(q.dt_max, m_.dt);
}

void Run::schedule_check(bool grains_now) {
  if (!sched_on_) return;
  const ScheduleParams& p = m_.schedule;
  ScheduleState& q = s_.schedule;
  if (grains_now || s_.step % p.check_every == 0) {  // at fixed steps: a resumed run checks where this one did
    double v2 = 0;
    const int n = m_.n_grains;
    for (int i = 0; i < n; ++i) v2 = std::max(v2, s_.vel[i].squaredNorm());
    q.v_grains = std::sqrt(v2);
  }
  double vb = 0;  // fastest point of a body: |v| + |omega| times its bounding radius
  for (size_t b = 0; b < s_.bodies.size(); ++b)
    vb = std::max(vb, s_.bodies[b].vel.norm() + s_.bodies[b].omega.norm() * m_.bodies[b].bound_radius);
  // Fastest possible approach: two grains head-on, or a grain and a body point.
  // Speed stored in the deepest contact of the last force pass: a contact at
  // overlap x holds the energy of an approach at x sqrt(k_n / m*), bounded with
  // the smallest grain (m* >= m_min / 2).
  if (grains_now || !(sched_m_min_ > 0)) {
    sched_m_min_ = std::numeric_limits<double>::infinity();
    for (int i = 0; i < m_.n_grains; ++i) sched_m_min_ = std::min(sched_m_min_, m_.grain_mass[i]);
  }
  const double v_overlap =
      m_.n_grains > 0 ? s_.stats.max_overlap_ratio * m_.min_radius * std::sqrt(2 * m_.kn / sched_m_min_) : 0.0;
  // Raised at once for anything faster. Lowered only once the target has
  // stayed below a quarter of the current factor for three durations of the
  // longest contact: lowering k_n takes ½ Δk x² out of every live contact, so
  // it waits until collisions begun at the higher speed are over.
  const auto target = [&](double v_fast) {
    const double r = p.margin * v_fast / p.speed;
    return std::clamp(r * r, p.floor, 1.0);
  };
  const double v_grains = 2 * q.v_grains, v_body = vb + q.v_grains;
  sched_vfast_ = std::max({v_grains, v_body, v_overlap});
  sched_why_ = sched_vfast_ == v_overlap ? "a loaded contact" : sched_vfast_ == v_body ? "a body" : "grains";
  const double t = target(sched_vfast_);
  // Twice the target on either change.
  if (t > q.scale) {
    q.low_since = -1;
    set_stiffness_scale(std::min(1.0, 2 * t), true);
  } else if (t < 0.25 * q.scale && s_.time - q.t_start >= p.after) {
    if (q.low_since < 0) q.low_since = s_.step;
    if (s_.step - q.low_since >= sched_hold_) {
      q.low_since = -1;
      set_stiffness_scale(t <= p.floor ? p.floor : 2 * t, true);
    }
  } else {
    q.low_since = -1;
  }
}

void Run::finish() {
  if (finished_) return;
  finished_ = true;
  for (Observer* o : obs_) o->finish(m_, s_);
}

RunReport Run::run() {
  try {
    while (advance()) {
    }
  } catch (const BlowUpError& e) {
    rep_.status = "blow_up";
    rep_.message = e.what();
    ended_ = true;
  }
  finish();
  rep_.wall_seconds = std::chrono::duration<double>(Clock::now() - t0_).count();
  rep_.steps = s_.step - step0_;
  rep_.rebuilds = s_.rebuilds - rebuilds0_;
  rep_.body_rebuilds = s_.body_rebuilds - body_rebuilds0_;
  rep_.sim_time = s_.time;
  if (sleep_active(m_, s_)) {
    const SleepState& z = s_.sleep;
    rep_.sleep = true;
    rep_.sleeping_at_end = sleeping_grains(s_);
    rep_.mean_awake = rep_.steps > 0 ? (z.awake_grain_steps - awake0_) / double(rep_.steps) : 0;
    rep_.fell_asleep = z.fell_asleep;
    rep_.woke = z.woke;
    rep_.discarded_energy = z.discarded_energy;
    rep_.discarded_max_speed = z.discarded_max_speed;
  }
  if (m_.free_flight.enabled) {
    rep_.free_flight = true;
    rep_.free_grains_max = s_.free_grains_max;
  }
  if (sched_on_) {
    rep_.schedule = true;
    rep_.dt_scene = sched_dt0_;
    rep_.sched = s_.schedule;
  }
  if (!opt_.out_dir.empty()) {
    if (rep_.status == "ok") sample();
    series_.close();
  }
  return rep_;
}

}  // namespace rt
