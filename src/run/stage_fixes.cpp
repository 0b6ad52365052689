// The run's own fixes (see stage_fixes.hpp).
#include "regolith_twin/run/stage_fixes.hpp"
#include "regolith_twin/core/hold.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/step.hpp"

namespace rt {

// --- stage edits ----------------------------------------------------------------

void StageEdits::stage_start(const Stage& st, Model& m, State& s, StageReport& rep) {
  if (st.trim) {  // every grain above the trim height goes (its centre, or its top with trim_tops)
    std::vector<uint8_t> drop(m.n_grains, 0);
    double lowest = 1e300;
    for (int i = 0; i < m.n_grains; ++i) {
      const double z = s.pos[i].z() + (st.trim_tops ? m.grain_radius[i] : 0.0);
      drop[i] = z > st.trim_above;
      lowest = std::min(lowest, z);
    }
    if (m.n_grains > 0 && std::find(drop.begin(), drop.end(), 0) == drop.end()) {
      // Nothing would be left to measure: a trim plane below the bed is an input error.
      const std::ptrdiff_t k = &st - plan_.stages.data();
      const std::string key = k >= 0 && k < std::ptrdiff_t(plan_.stages.size())
                                  ? "stages[" + std::to_string(k) + "].trim_above"
                                  : "trim_above of stage '" + st.name + "'";
      char b[200];
      std::snprintf(b, sizeof b, " = %.6g m removes every grain (the lowest %s is at %.6g m): raise it", st.trim_above,
                    st.trim_tops ? "grain top" : "grain centre", lowest);
      throw InputError("key '" + key + "'" + b);
    }
    rep.grains_removed = remove_grains(m, s, drop, plan_.groups);
  }
  if (st.stiffness_scale > 0 && plan_.scene_kn > 0) {
    // Same steps per contact at the new stiffness. Live springs keep their
    // extension; the law table is rebuilt for the new k_n. Changing k_n on
    // live contacts changes their elastic energy at fixed positions
    // (Σ ½ Δk x² and the spring terms that scale with k_n): measured here
    // against the grains' kinetic energy (docs/model.md §4).
    const double kn_old = m.kn;
    const double el_old = energy(m, s).elastic;
    m.kn = plan_.scene_kn * st.stiffness_scale;
    if (plan_.scene_body_kn > 0) m.body_kn = plan_.scene_body_kn * st.stiffness_scale;
    m.dt = plan_.scene_dt / std::sqrt(st.stiffness_scale);
    finalize_model(m);
    s.forces_valid = false;
    if (m.kn != kn_old) {
      const Energy e = energy(m, s);
      const double injected = e.elastic - el_old, kinetic = e.kinetic();
      rep.stiffness_injection = injected;
      rep.kinetic_at_switch = kinetic;
      const double frac = kinetic > 0 ? injected / kinetic : (injected > 0 ? INFINITY : 0.0);
      if (verbose_)
        std::fprintf(stderr,
                     "[%s] stage '%s': k_n %.4g -> %.4g N/m, dt %.4g s; elastic energy changed by %.3g J "
                     "(%.3g %% of the kinetic energy %.3g J)\n",
                     plan_.name.c_str(), st.name.c_str(), kn_old, m.kn, m.dt, injected, 100 * frac, kinetic);
      if (st.max_injection >= 0 && frac > st.max_injection) {
        char b[400];
        std::snprintf(b, sizeof b,
                      "stage '%s': raising k_n from %.4g to %.4g N/m injects %.3g J, %.3g %% of the grains' kinetic "
                      "energy %.3g J (limit %.3g %%): relax further at the softer stiffness, or raise it in "
                      "smaller steps",
                      st.name.c_str(), kn_old, m.kn, injected, 100 * frac, kinetic, 100 * st.max_injection);
        throw BlowUpError(b);
      }
    }
  }
  for (const auto& name : st.remove_walls)
    for (size_t w = 0; w < m.walls.size(); ++w)
      if (m.walls[w].name == name) {
        s.wall_on[w] = 0;
        s.rebuild_requested = true;
      }
}

// --- gravity ----------------------------------------------------------------------

void StageGravity::stage_start(const Stage& st, Model& m, State& s, StageReport&) {
  from_ = m.gravity;
  if (st.set_gravity && st.gravity_ramp <= 0) m.gravity = st.gravity;
  t0_ = s.time;
}

void StageGravity::before_step(const Stage& st, Model& m, State& s) {
  if (!(st.set_gravity && st.gravity_ramp > 0)) return;
  const double f = std::min(1.0, (s.time - t0_) / st.gravity_ramp);
  const double a = from_.norm(), b = st.gravity.norm();
  if (f >= 1.0 || a == 0 || b == 0) {
    m.gravity = f >= 1.0 ? st.gravity : Vec3(from_ + f * (st.gravity - from_));
  } else {
    const Vec3 dir = ((1 - f) * from_ / a + f * st.gravity / b).normalized();
    m.gravity = dir * (a * std::pow(b / a, f));
  }
}

// --- damping of bed preparation -----------------------------------------------------

void StageDamping::stage_start(const Stage& st, Model&, State& s, StageReport&) {
  next_quench_ = s.time + st.quench_every;
}

void StageDamping::after_step(const Stage& st, Model& m, State& s) {
  if (st.minimize) {  // quick-min: keep only the velocity along the net force
    const int n = m.n_grains;
    const Vec3 g = m.gravity;
#pragma omp parallel for schedule(static) if (n >= m.parallel_min_grains)
    for (int i = 0; i < n; ++i) {
      if (held(m, i)) continue;
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
  if (st.quench_every > 0 && s.time >= next_quench_ - 0.5 * m.dt) {
    next_quench_ += st.quench_every;
    for (int i = 0; i < m.n_grains; ++i) {
      s.vel[i].setZero();
      s.omega[i].setZero();
    }
  }
}

// --- held groups --------------------------------------------------------------------

void HeldGroups::stage_start(const Stage& st, Model& m, State& s, StageReport&) {
  held_.assign(m.n_grains, 0);
  ids_.clear();
  pos_.clear();
  for (const auto& name : st.hold)
    for (const GrainGroup& g : groups_)
      if (g.name == name)
        for (int i = g.first; i < g.first + g.count; ++i) {
          held_[i] = 1;
          ids_.push_back(i);
          pos_.push_back(s.pos[i]);
        }
}

void HeldGroups::after_step(const Stage&, Model&, State& s) {
  for (size_t h = 0; h < ids_.size(); ++h) {
    s.pos[ids_[h]] = pos_[h];
    s.vel[ids_[h]].setZero();
    s.omega[ids_[h]].setZero();
  }
}

void HeldGroups::grains_added(const Model& m, const State&, int first) {
  if (int(held_.size()) == first) held_.resize(m.n_grains, 0);
}

void HeldGroups::grains_removed(const std::vector<int>& old_to_new) {
  // Held grains follow their new numbers (a held grain that left is let go).
  const long n_new = std::count_if(old_to_new.begin(), old_to_new.end(), [](int j) { return j >= 0; });
  std::vector<uint8_t> held(n_new, 0);
  size_t k = 0;
  for (size_t h = 0; h < ids_.size(); ++h) {
    const int j = old_to_new[ids_[h]];
    if (j < 0) continue;
    held[j] = 1;
    ids_[k] = j;
    pos_[k++] = pos_[h];
  }
  ids_.resize(k);
  pos_.resize(k);
  if (held_.size() == old_to_new.size()) held_ = std::move(held);
}

// --- stiffness schedule (docs/model.md §17) ----------------------------------------

void StiffnessSchedule::start(Model& m, State& s) {
  on_ = m.schedule.enabled;
  if (!on_) return;
  if (!(m.schedule.speed > 0)) throw InputError("schedule.speed: the design speed must be > 0 m/s");
  if (m.contact_model != ContactModel::Linear)
    throw InputError("schedule.enabled: the stiffness schedule scales the linear law's k_n; "
                     "contact.model hertz_mindlin has no k_n to scale");
  for (const Stage& st : plan_.stages)
    if (st.stiffness_scale > 0)
      throw InputError("stage '" + st.name + "' sets a stiffness scale and the stiffness schedule "
                       "(schedule.enabled) sets k_n too: use one of them");
  // The model is the scene's (a resumed state carries the factor it ran at).
  kn0_ = m.kn;
  body_kn0_ = m.body_kn;
  dt0_ = m.dt;
  // Three durations of the longest contact, in steps (the same at any factor).
  double steps = 0;
  for (const PairResolution& r : pair_resolution(m, m.schedule.speed))
    if (r.label.rfind("body-body", 0) != 0) steps = std::max(steps, r.steps);  // contacts of grains
  hold_ = std::max(1L, long(std::ceil(3 * steps)));
  ScheduleState& q = s.schedule;
  if (!q.started) {  // a fresh start: the grains' speeds are measured now
    q = ScheduleState{};
    q.started = true;
    q.t_start = s.time;
    q.dt_min = q.dt_max = m.dt;
    q.kinetic_ref = energy(m, s).kinetic();
    check(m, s, true);
  } else if (q.scale != 1.0) {  // a resumed state runs on at the factor it was saved with
    set_scale(m, s, q.scale, false);
  }
}

void StiffnessSchedule::end_step(Model& m, State& s, bool grains_added) {
  if (on_) check(m, s, grains_added);
}

void StiffnessSchedule::report(const State& s, RunReport& rep) const {
  if (!on_) return;
  rep.schedule = true;
  rep.dt_scene = dt0_;
  rep.sched = s.schedule;
}

std::string StiffnessSchedule::progress(const Model& m, const State&) const {
  if (!on_) return "";
  char b[128];
  std::snprintf(b, sizeof b, "dt %.3g s (v_fast %.3g m/s: %s)", m.dt, vfast_, why_);
  return b;
}

void StiffnessSchedule::set_scale(Model& m, State& s, double scale, bool account) {
  ScheduleState& q = s.schedule;
  // A raise shortens every stored spring (tangential, rolling, twisting) by
  // the ratio of the factors, so that their forces stay what they were and
  // their energy falls by that ratio: only the overlaps, which cannot be
  // changed, take on energy.
  if (account && scale > q.scale) scale_contact_springs(s, q.scale / scale);
  const double el_old = account ? energy(m, s).elastic : 0.0;
  m.kn = kn0_ * scale;
  if (body_kn0_ > 0) m.body_kn = body_kn0_ * scale;
  m.dt = dt0_ / std::sqrt(scale);
  finalize_model(m);
  s.tick_len = m.dt / dt0_;
  if (account) {
    // Live contacts keep their overlaps and springs: their elastic energy
    // changes with k_n (Σ ½ Δk x² and the spring terms that scale with it).
    const Energy e = energy(m, s);
    const double d = e.elastic - el_old, kin = e.kinetic();
    q.kinetic_ref = std::max(q.kinetic_ref, kin);
    if (scale > q.scale) {
      ++q.raised;
      q.injected += d;
      q.max_injected_fraction = std::max(q.max_injected_fraction, kin > 0 ? d / kin : (d > 0 ? INFINITY : 0.0));
      const double limit = m.schedule.max_injected * q.kinetic_ref;
      if (m.schedule.max_injected > 0 && q.injected > limit) {
        std::ostringstream os;
        os << "t = " << s.time << " s: the stiffness schedule's raises of k_n have added " << q.injected
           << " J to live contacts (" << q.raised << " raises; this one " << d << " J, to " << scale
           << " of the scene's k_n, set by " << why_ << " at v_fast " << vfast_ << " m/s), more than "
           << "schedule.max_injected " << m.schedule.max_injected << " x the largest kinetic energy seen, "
           << q.kinetic_ref << " J: the run would go on with energy the scene does not have. "
           << "Raise schedule.floor (smaller and fewer raises), turn the schedule off, or set "
           << "schedule.max_injected (0: off)";
        q.scale = scale;
        throw BlowUpError(os.str());
      }
    } else {
      ++q.lowered;
      q.released -= d;
    }
    s.forces_valid = false;  // forces of the new law before the next step
    if (verbose_)
      std::fprintf(stderr, "[%s] t = %.6g s: k_n %.4g -> %.4g N/m (x%.3g of the scene's), dt %.4g s%s\n",
                   plan_.name.c_str(), s.time, kn0_ * q.scale, m.kn, scale, m.dt,
                   scale > q.scale ? " (raised: a faster grain or body)" : "");
  }
  q.scale = scale;
  q.min_scale = std::min(q.min_scale, scale);
  q.dt_min = q.dt_min > 0 ? std::min(q.dt_min, m.dt) : m.dt;
  q.dt_max = std::max(q.dt_max, m.dt);
}

void StiffnessSchedule::check(Model& m, State& s, bool grains_now) {
  const ScheduleParams& p = m.schedule;
  ScheduleState& q = s.schedule;
  if (grains_now || s.step % p.check_every == 0) {  // at fixed steps: a resumed run checks where this one did
    double v2 = 0;
    const int n = m.n_grains;
    for (int i = 0; i < n; ++i) v2 = std::max(v2, s.vel[i].squaredNorm());
    q.v_grains = std::sqrt(v2);
  }
  double vb = 0;  // fastest point of a body: |v| + |omega| times its bounding radius
  for (size_t b = 0; b < s.bodies.size(); ++b)
    vb = std::max(vb, s.bodies[b].vel.norm() + s.bodies[b].omega.norm() * m.bodies[b].bound_radius);
  // Fastest possible approach: two grains head-on, or a grain and a body point.
  if (grains_now || !(m_min_ > 0)) {
    m_min_ = std::numeric_limits<double>::infinity();
    for (int i = 0; i < m.n_grains; ++i) m_min_ = std::min(m_min_, m.grain_mass[i]);
  }
  // The deepest contact of the last force pass, as the factor that brings its
  // overlap to the design overlap: the scene's k_n takes the smallest grains
  // head-on at the design speed to x_d = speed sqrt(m_min / (2 k_scene)), so a
  // contact at overlap ratio rho (of the pair's smaller radius, compared as
  // rho r_min) under factor f asks for f rho r_min / x_d. An overlap held by a
  // load grows as 1/f when k_n is lowered, so what it asks for does not change
  // with f; a collision's grows as 1/sqrt(f), so the rule is on the safe side
  // for it. Expressed as the speed whose target
  // it is (v_fast, the progress line and the diagnostics).
  const double x_d = p.speed * std::sqrt(m_min_ / (2 * kn0_));
  const double t_overlap =
      m.n_grains > 0 && x_d > 0 ? p.margin * q.scale * s.stats.max_overlap_ratio * m.min_radius / x_d : 0.0;
  const double v_overlap = p.speed * std::sqrt(t_overlap) / p.margin;
  // Raised at once for anything faster. Lowered only once the target has
  // stayed below a quarter of the current factor for three durations of the
  // longest contact: lowering k_n takes ½ Δk x² out of every live contact, so
  // it waits until collisions begun at the higher speed are over.
  const auto target = [&](double v_fast) {
    const double r = p.margin * v_fast / p.speed;
    return std::clamp(r * r, p.floor, 1.0);
  };
  // Only speeds raise k_n: what the deepest contact asks for holds k_n up
  // (no lowering below it) but does not raise it. A raise puts ½ Δk x² into
  // every loaded contact, and the demand of a bed's deepest contact swings by
  // more than the factor of 2 between a lowering and the next raise.
  const double v_grains = 2 * q.v_grains, v_body = vb + q.v_grains;
  const double v_moving = std::max(v_grains, v_body);
  vfast_ = std::max(v_moving, v_overlap);
  why_ = vfast_ == v_overlap ? "a loaded contact" : vfast_ == v_body ? "a body" : "grains";
  const double t_raise = target(v_moving), t = target(vfast_);
  // Twice the target on either change.
  if (t_raise > q.scale) {
    q.low_since = -1;
    ++(v_moving == v_body ? q.raised_body : q.raised_grains);
    vfast_ = v_moving;  // what the diagnostics name
    why_ = v_moving == v_body ? "a body" : "grains";
    set_scale(m, s, std::min(1.0, 2 * t_raise), true);
  } else if (t < 0.25 * q.scale && s.time - q.t_start >= p.after) {
    if (q.low_since < 0) q.low_since = s.step;
    if (s.step - q.low_since >= hold_) {
      q.low_since = -1;
      set_scale(m, s, t <= p.floor ? p.floor : 2 * t, true);
    }
  } else {
    q.low_since = -1;
  }
}

}  // namespace rt
