// The one run loop (see run.hpp).
#include "regolith_twin/run/run.hpp"
#include "regolith_twin/core/hold.hpp"

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
#include "regolith_twin/run/stage_fixes.hpp"

namespace rt {

using Clock = std::chrono::steady_clock;

GrainSpeeds grain_speeds(const Model& m, const State& s, const std::vector<uint8_t>& skip) {
  double sum = 0, mx = 0;
  long n = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i) || skip[i]) continue;
    const double v2 = s.vel[i].squaredNorm();
    sum += v2;
    mx = std::max(mx, v2);
    ++n;
  }
  return {n ? std::sqrt(sum / n) : 0.0, std::sqrt(mx)};
}

std::string clock_text(double seconds) {
  // A rate near zero or an estimate of years is not a clock time.
  if (!(seconds < 100 * 86400.0)) return "> 100 days";
  char b[32];
  const long s = long(std::max(seconds, 0.0) + 0.5);
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
    : m_(m), s_(s), plan_(std::move(plan)), opt_(opt) {
  const bool verbose = opt_.progress_every > 0;
  edits_ = std::make_unique<StageEdits>(plan_, verbose);
  gravity_ = std::make_unique<StageGravity>();
  damping_ = std::make_unique<StageDamping>();
  held_ = std::make_unique<HeldGroups>(plan_.groups);
  schedule_ = std::make_unique<StiffnessSchedule>(plan_, verbose);
  fixes_ = {edits_.get(), gravity_.get(), damping_.get(), held_.get(), schedule_.get()};
}

Run::~Run() = default;

void Run::add_observer(Observer* o) { obs_.push_back(o); }
void Run::add_fix(Fix* f) { fixes_.push_back(f); }
const std::vector<uint8_t>& Run::held() const { return held_->held(); }

bool Run::ended() { return !settle(); }

// Steps the stages' durations need at their time steps (a stage that scales
// k_n runs at the scene's dt / sqrt(scale)); open-ended stages count nothing.
static double planned_steps(const RunPlan& plan, const Model& m) {
  double n = 0;
  for (const Stage& st : plan.stages) {
    if (!std::isfinite(st.duration)) continue;
    const double dt = st.stiffness_scale > 0 && plan.scene_dt > 0 ? plan.scene_dt / std::sqrt(st.stiffness_scale) : m.dt;
    n += st.duration / dt;
  }
  return n;
}

void Run::start() {
  if (!(opt_.max_steps >= 1)) throw InputError("run '" + plan_.name + "': the step limit must be at least 1");
  if (const double n = planned_steps(plan_, m_); n > double(opt_.max_steps)) {
    char b[256];
    std::snprintf(b, sizeof b, "the stages' durations need %.3g steps at dt = %.3g s, more than the limit of %ld",
                  n, m_.dt, opt_.max_steps);
    throw InputError("run '" + plan_.name + "': " + b +
                     ": shorten the durations or raise dt (contact.steps_per_contact), or raise the limit "
                     "(--max-steps; the node's ~max_steps) if the run is meant to be this long");
  }
  started_ = true;
  t0_ = last_progress_ = Clock::now();
  t_start_ = rate_t_ = s_.time;
  step0_ = s_.step;
  rebuilds0_ = s_.rebuilds;
  body_rebuilds0_ = s_.body_rebuilds;
  awake0_ = s_.sleep.awake_grain_steps;
  next_sample_ = s_.time;
  for (Fix* f : fixes_) f->prepare(m_, s_);
  if (!s_.forces_valid) prime(m_, s_);
  for (Observer* o : obs_) o->start(m_, s_);
  for (Fix* f : fixes_) f->start(m_, s_);
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
    for (const Fix* f : fixes_) f->columns(cols);
    series_.open(opt_.out_dir + "/series.csv", cols);
  }
}

// Stage transitions up to the next step (the first call starts the run).
bool Run::settle() {
  if (ended_) return false;
  if (!started_) start();
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

// Stage start: the fixes carry out what the stage asks for (trim, stiffness,
// gravity, walls taken away, groups held).
void Run::begin_stage() {
  const Stage& st = plan_.stages[k_];
  energy_watch_.reset();
  sr_ = StageReport{st.name, 0, "duration"};
  for (Fix* f : fixes_) f->stage_start(st, m_, s_, sr_);
  t_stage_end_ = s_.time + st.duration;
  stage_t0_ = s_.time;
  rate_ = -1;
  next_check_ = s_.time + st.check_every;
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
  for (Fix* f : fixes_) f->before_step(st, m_, s_);
  if (s_.time >= next_sample_ - 0.5 * m_.dt) {  // series row before the step
    if (!opt_.out_dir.empty()) sample();
    next_sample_ += opt_.sample_every;
  }
  if (s_.step == step0_ && s_.forces_valid) watch_energy();  // the energy guard's first reference
  if (s_.step - step0_ >= opt_.max_steps) {
    char b[160];
    std::snprintf(b, sizeof b, "the run reached its limit of %ld steps at t = %.6g s", opt_.max_steps, s_.time);
    throw StepLimitError(std::string(b) + " (raise it with --max-steps, the node's ~max_steps, if the run is meant to be "
                                          "this long)");
  }
  step(m_, s_);
  rep_.max_overlap_ratio = std::max(rep_.max_overlap_ratio, s_.stats.max_overlap_ratio);
  for (Fix* f : fixes_) f->after_step(st, m_, s_);
  const int n_before = m_.n_grains;
  add_grains();
  const bool end = measure();
  for (Fix* f : fixes_) f->after_measures(m_, s_);
  remove_leaving();
  for (Fix* f : fixes_) f->end_step(m_, s_, m_.n_grains > n_before);
  watch_energy();
  if (end) {
    rep_.ended_by_observer = true;
    end_stage("observer");
    ended_ = true;
    return true;
  }
  if (criteria_met()) {
    end_stage("criteria");
    return true;
  }
  if (opt_.progress_every > 0) progress();
  return true;
}

bool Run::measure() {
  bool end = false;
  for (Observer* o : obs_) end = o->after_step(m_, s_) || end;
  return end;
}

bool Run::criteria_met() {
  const Stage& st = plan_.stages[k_];
  if (!(st.until_rms_speed >= 0 || st.until_max_speed >= 0) || s_.time < next_check_) return false;
  next_check_ += st.check_every;
  const GrainSpeeds sp = grain_speeds(m_, s_, held_->held());
  return (st.until_rms_speed < 0 || sp.rms < st.until_rms_speed) &&
         (st.until_max_speed < 0 || sp.max < st.until_max_speed);
}

void Run::watch_energy() {
  const Guards& gd = m_.guards;
  if (!(gd.max_energy_growth > 0) || gd.energy_check_every <= 0) return;
  // Energy put in this step: a field, an applied wrench, a fix (the stiffness schedule, held grains), or
  // gravity along a periodic axis (a grain wrapped downhill keeps its speed but its potential
  // energy jumps up by m g L: an inclined periodic bed is driven without bound; docs/model.md §13).
  const bool periodic_drive = (m_.periodic.x && m_.gravity.x() != 0) || (m_.periodic.y && m_.gravity.y() != 0);
  bool input = !m_.fields.empty() || periodic_drive;
  for (const Fix* f : fixes_) input = input || f->energy_input();
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
  for (Fix* f : fixes_) f->add_grains(m_, s_);
  if (m_.n_grains == n_old) return;
  energy_watch_.reset();
  drop_.assign(m_.n_grains, 0);
  for (Fix* f : fixes_) f->grains_added(m_, s_, n_old);
  for (Observer* o : obs_) o->grains_added(m_, s_, n_old);
}

void Run::remove_leaving() {
  if (int(drop_.size()) != m_.n_grains) drop_.assign(m_.n_grains, 0);  // all zero between steps
  bool any = false;
  for (Observer* o : obs_) any = o->leaving(m_, s_, drop_) || any;
  if (!any) return;
  remove_grains(m_, s_, drop_, plan_.groups, &old_to_new_);
  energy_watch_.reset();
  drop_.assign(m_.n_grains, 0);
  for (Fix* f : fixes_) f->grains_removed(old_to_new_);
  for (Observer* o : obs_) o->grains_removed(old_to_new_);
}

void Run::sample() {
  std::vector<double> row = {s_.time};
  for (const Observer* o : obs_) o->row(m_, s_, row);
  for (const Fix* f : fixes_) f->row(m_, s_, row);
  series_.row(row);
}

void Run::progress() {
  const auto now = Clock::now();
  const double since = std::chrono::duration<double>(now - last_progress_).count();
  if (since < opt_.progress_every) return;
  last_progress_ = now;
  const double wall = std::chrono::duration<double>(now - t0_).count();
  const double steps_s = double(s_.step - step0_) / std::max(wall, 1e-9);
  // Simulated seconds per wall second, averaged over about the last minute
  // (kRateWindow): it follows the load of the machine and the run's own
  // phases; it starts afresh with each stage (a relaxation and a landing
  // differ in cost), from the run's average.
  const double rate_now = (s_.time - rate_t_) / std::max(since, 1e-9);
  rate_t_ = s_.time;
  if (rate_ < 0) rate_ = (s_.time - t_start_) / std::max(wall, 1e-9);
  else rate_ += (1 - std::exp(-since / kRateWindow)) * (rate_now - rate_);
  const double rate = rate_;
  // Time left: the rest of the stages with a duration, or what the measures
  // expect (an estimate) or know as a bound.
  double left = 0, total = s_.time;
  bool bounded = true;
  for (size_t q = k_; q < plan_.stages.size(); ++q) {
    const double d = q == k_ ? t_stage_end_ - s_.time : plan_.stages[q].duration;
    if (std::isfinite(d)) left += d;
    else bounded = false;
  }
  total += left;
  std::string text;
  double obs_left = -1, expected = -1;
  for (const Observer* o : obs_) {
    const std::string p = o->progress(m_, s_);
    if (!p.empty()) text += "  " + p;
    const double l = o->time_left(s_);
    if (l >= 0) obs_left = obs_left < 0 ? l : std::min(obs_left, l);
    const double e = o->expected_time_left(s_);
    if (e >= 0) expected = expected < 0 ? e : std::min(expected, e);
  }
  const auto wall_text = [&](double sim) { return clock_text(sim / std::max(rate, 1e-300)); };
  std::string eta = "ETA ?";
  if (bounded) eta = "ETA " + wall_text(left);
  else if (expected >= 0) eta = "ETA ~" + wall_text(expected);
  else if (obs_left >= 0) eta = "at most " + wall_text(obs_left);
  char head[256];
  if (bounded) {
    std::snprintf(head, sizeof head, "[%s] stage %zu/%zu '%s'  t = %.4g s of %.4g s (%.0f %%)", plan_.name.c_str(),
                  k_ + 1, plan_.stages.size(), plan_.stages[k_].name.c_str(), s_.time, total,
                  total > 0 ? 100 * s_.time / total : 100.0);
  } else if (expected >= 0) {  // the share of the stage done, as expected
    const double done = s_.time - stage_t0_;
    std::snprintf(head, sizeof head, "[%s] %s  t = %.4g s of ~%.4g s (~%.0f %%)", plan_.name.c_str(),
                  plan_.stages[k_].name.c_str(), s_.time, s_.time + expected,
                  done + expected > 0 ? 100 * done / (done + expected) : 100.0);
  } else {
    std::snprintf(head, sizeof head, "[%s] %s  t = %.4g s", plan_.name.c_str(), plan_.stages[k_].name.c_str(),
                  s_.time);
  }
  if (sleep_active(m_, s_)) {
    char b[64];
    std::snprintf(b, sizeof b, "  awake %zu", s_.sleep.awake.size());
    text += b;
  }
  for (const Fix* f : fixes_) {
    const std::string p = f->progress(m_, s_);
    if (!p.empty()) text += "  " + p;
  }
  std::fprintf(stderr, "%s%s  %.3g steps/s  %.3g grain-steps/s  %s\n", head, text.c_str(), steps_s,
               steps_s * m_.n_grains, eta.c_str());
}

void Run::finish() {
  if (finished_) return;
  finished_ = true;
  for (Observer* o : obs_) o->finish(m_, s_);
  for (Fix* f : fixes_) f->finish(m_, s_);
}

RunReport Run::run() {
  try {
    while (advance()) {
    }
  } catch (const StepLimitError& e) {
    rep_.status = "step_limit";
    rep_.message = e.what();
    ended_ = true;
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
  for (const Fix* f : fixes_) f->report(s_, rep_);
  if (!opt_.out_dir.empty()) {
    if (rep_.status == "ok") sample();
    series_.close();
  }
  return rep_;
}

}  // namespace rt
