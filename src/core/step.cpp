// The time step: a short pipeline of stages (see step.hpp).
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/hold.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "regolith_twin/core/energy.hpp"

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/forces.hpp"
#include "regolith_twin/core/integrate.hpp"
#include "regolith_twin/core/neighbours.hpp"
#include "regolith_twin/core/sleep.hpp"

namespace rt {

void prime(const Model& m, State& s) {
  for (const auto& f : m.fields)
    if (f->state_values() > int(s.field_values.size()))
      throw InputError(std::string("field '") + f->name() + "' reads " + std::to_string(f->state_values()) +
                       " entries of the state's field values; the state holds " +
                       std::to_string(s.field_values.size()));
  build_neighbour_lists(m, s);
  s.contact_count.assign(m.n_grains, 0);  // the guard's counts (sized here: steps allocate nothing)
  // Forces of the current state without advancing any contact history: the
  // springs and touching flags of the lists are put back after the pass, and
  // body–body points keep the springs they carried in (hold_body_springs).
  s.vel_mid = s.vel;
  s.omega_mid = s.omega;
  for (BodyState& b : s.bodies) {
    b.vel_mid = b.vel;
    b.omega_mid = b.omega;
  }
  const PairList springs = s.pairs;
  const WallList wall_springs = s.wall_pairs;
  const BodyGrainList body_springs = s.body_grains;
  s.hold_body_springs = true;  // body–body points keep the springs they carry in
  try {
    compute_forces(m, s);
    apply_fields(m, s);  // fields see v(n) here (vel == vel_mid)
  } catch (...) {
    s.hold_body_springs = false;
    throw;
  }
  s.hold_body_springs = false;
  s.body_grains.spring_t = body_springs.spring_t;
  s.body_grains.spring_r = body_springs.spring_r;
  s.body_grains.spring_w = body_springs.spring_w;
  s.body_grains.touching = body_springs.touching;
  s.body_grains.mesh_slots = body_springs.mesh_slots;
  s.pairs.spring_t = springs.spring_t;
  s.pairs.spring_r = springs.spring_r;
  s.pairs.spring_w = springs.spring_w;
  s.pairs.touching = springs.touching;
  s.wall_pairs.spring_t = wall_springs.spring_t;
  s.wall_pairs.spring_r = wall_springs.spring_r;
  s.wall_pairs.spring_w = wall_springs.spring_w;
  s.wall_pairs.touching = wall_springs.touching;
}

void step(const Model& m, State& s) {
  if (!s.forces_valid) prime(m, s);
  kick_drift(m, s, 0.5 * m.dt, m.dt);                              // integrate: half kick, drift
  kick_drift_bodies(m, s, 0.5 * m.dt, m.dt);
  check_guards(m, s);
  s.stats.lists_built = lists_need_rebuild(m, s);
  if (s.stats.lists_built)                                         // neighbours
    build_neighbour_lists(m, s);
  else if (body_list_needs_rebuild(m, s))
    build_body_list(m, s);
  compute_forces(m, s);                                            // contacts -> forces
  if (s.stats.lists_built) count_contacts(m, s);
  apply_fields(m, s);                                              // fields -> forces
  finish_kick(m, s, 0.5 * m.dt);                                   // integrate: half kick
  finish_kick_bodies(m, s, 0.5 * m.dt);
  s.time += m.dt;
  ++s.step;
  s.ticks += s.tick_len;
  check_guards(m, s);                                              // guards
  update_sleep(m, s);                                              // sleep: wake and put quiet cells to sleep
}

namespace {
std::string at(const State& s) {
  std::ostringstream os;
  os << "numerical blow-up at step " << s.step << " (t = " << s.time << " s): ";
  return os.str();
}
}  // namespace

int contacts_limit(const Model& m) {
  if (m.guards.max_contacts_per_grain != 0) return m.guards.max_contacts_per_grain;
  if (m.n_grains == 0 || !(m.min_radius > 0)) return -1;
  // Small grains (r_min) around the largest (r_max), overlapping it and each
  // other by at most the overlap limit (taken as at most 1.5): their centres
  // are at most r_max + r_min away and at least (2 - q) r_min apart, so each
  // holds a cap of half angle a, sin a = (2 - q) r_min / (2 (r_max + r_min)),
  // and at most 2 / (1 - cos a) fit. Twice that, plus walls and bodies.
  const double q = std::min(m.guards.max_overlap_ratio, 1.5);
  const double sa = (2 - q) * m.min_radius / (2 * (m.max_radius + m.min_radius));
  const double caps = 2 / (1 - std::sqrt(1 - sa * sa));
  return int(std::ceil(2 * caps)) + 6;
}

void count_contacts(const Model& m, State& s) {
  std::vector<int>& c = s.contact_count;
  c.assign(m.n_grains, 0);
  const PairList& pl = s.pairs;
  for (int k = 0; k < pl.size(); ++k)
    if (pl.touching[k]) {
      ++c[pl.owner[k]];
      ++c[pl.partner[k]];
    }
  for (int k = 0; k < s.wall_pairs.size(); ++k) c[s.wall_pairs.grain[k]] += s.wall_pairs.touching[k];
  const BodyGrainList& bl = s.body_grains;
  for (int k = 0; k < bl.size(); ++k) {
    if (bl.mesh_first[k] < 0) {
      c[bl.grain[k]] += bl.touching[k];
      continue;
    }
    for (int q = 0; q < kMeshSlots; ++q) c[bl.grain[k]] += bl.mesh_slots[bl.mesh_first[k] + q].touching != 0;
  }
  s.stats.max_contacts = 0;
  s.stats.max_contacts_grain = -1;
  for (int i = 0; i < m.n_grains; ++i)
    if (c[i] > s.stats.max_contacts) {
      s.stats.max_contacts = c[i];
      s.stats.max_contacts_grain = i;
    }
}

void EnergyWatch::check(const Model& m, const State& s) {
  int frozen = 0;
  long frozen_sum = 0;
  double weight = 0;  // Σ m |g| d_mean over the free grains
  double d_sum = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    d_sum += 2 * m.grain_radius[i];
    if (held(m, i)) {
      ++frozen;
      frozen_sum += i;
    } else {
      weight += m.grain_mass[i];
    }
  }
  const double d_mean = m.n_grains > 0 ? d_sum / m.n_grains : 0;
  const Energy e = energy(m, s);
  const double total = e.total();
  const double mobile = e.kinetic() + e.elastic;
  if (!valid_ || m.n_grains != n_grains_ || frozen != n_frozen_ || frozen_sum != frozen_sum_ || m.kn != kn_ ||
      m.dt != dt_ || m.gravity != g_) {
    valid_ = true;
    n_grains_ = m.n_grains;
    n_frozen_ = frozen;
    frozen_sum_ = frozen_sum;
    kn_ = m.kn;
    dt_ = m.dt;
    g_ = m.gravity;
    e_min_ = total;
    scale_ = std::max(mobile, weight * m.gravity.norm() * d_mean);
    return;
  }
  const double limit = m.guards.max_energy_growth * scale_;
  if (total - e_min_ > limit && limit > 0) {
    // The fastest free grain, and the fastest free body.
    int fast = -1;
    double v2 = -1;
    for (int i = 0; i < m.n_grains; ++i)
      if (!held(m, i) && s.vel[i].squaredNorm() > v2) {
        v2 = s.vel[i].squaredNorm();
        fast = i;
      }
    std::ostringstream os;
    os << at(s) << "the total energy of a scene without energy input rose to " << total << " J, "
       << total - e_min_ << " J above its lowest value since the last check point (limit " << limit
       << " J = guards.max_energy_growth " << m.guards.max_energy_growth << " x the scene's energy scale " << scale_
       << " J)";
    if (fast >= 0) os << "; fastest grain " << fast << " at " << std::sqrt(v2) << " m/s";
    int fb = -1;
    double bv2 = -1;
    for (size_t b = 0; b < m.bodies.size(); ++b)
      if (!m.bodies[b].fixed && s.bodies[b].vel.squaredNorm() > bv2) {
        bv2 = s.bodies[b].vel.squaredNorm();
        fb = int(b);
      }
    if (fb >= 0) os << ", body '" << m.bodies[fb].name << "' at " << std::sqrt(bv2) << " m/s";
    os << "; reduce dt or k_n (see the steps-per-contact report), or set guards.max_energy_growth (0: off)";
    throw BlowUpError(os.str());
  }
  e_min_ = std::min(e_min_, total);
  scale_ = std::max(scale_, mobile);
}

void check_guards(const Model& m, const State& s) {
  const StepStats& st = s.stats;
  if (!st.finite && st.bad_body >= 0) {
    const BodyState& b = s.bodies[st.bad_body];
    std::ostringstream os;
    os << "numerical blow-up at step " << s.step << " (t = " << s.time << " s): the state of body '"
       << m.bodies[st.bad_body].name << "' became NaN or infinite (position " << b.pos.transpose() << ", velocity "
       << b.vel.transpose() << ", force " << b.force.transpose()
       << "); check the body's initial state and applied wrench, reduce dt or the body stiffness (body_kn)";
    throw BlowUpError(os.str());
  }
  if (!st.finite) {
    std::ostringstream os;
    os << "numerical blow-up at step " << s.step << " (t = " << s.time
       << " s): a grain velocity became NaN or infinite; reduce dt or k_n (see the steps-per-contact report)";
    throw BlowUpError(os.str());
  }
  if (m.guards.max_body_step_ratio > 0 && m.body_step_limit > 0 &&
      st.max_body_step > m.guards.max_body_step_ratio * m.body_step_limit) {
    const int b = st.max_body_step_body;
    std::ostringstream os;
    os << "numerical blow-up at step " << s.step << " (t = " << s.time << " s): body '" << m.bodies[b].name
       << "' moved " << st.max_body_step << " m in one step (speed " << s.bodies[b].vel_mid.norm()
       << " m/s), more than " << m.guards.max_body_step_ratio * m.body_step_limit
       << " m (the contact skin or the thinnest body shape, docs/model.md §13): it could pass through what it "
          "should hit; reduce dt (or the body's speed), or set guards.max_body_step_ratio";
    throw BlowUpError(os.str());
  }
  if (m.guards.max_grain_step_ratio > 0 && st.max_grain_step > m.guards.max_grain_step_ratio * m.skin) {
    // The grain: the fastest without a free-flight reach.
    int g = -1;
    double v2 = -1;
    for (int i = 0; i < m.n_grains; ++i)
      if ((s.reach.empty() || !(s.reach[i] > 0)) && !held(m, i) && s.vel_mid[i].squaredNorm() > v2) {
        v2 = s.vel_mid[i].squaredNorm();
        g = i;
      }
    std::ostringstream os;
    os << at(s) << "grain " << g << " moved " << st.max_grain_step << " m in one step (speed " << std::sqrt(v2)
       << " m/s), more than " << m.guards.max_grain_step_ratio * m.skin
       << " m (the list skin, docs/model.md §13): it could pass a grain it should hit; reduce dt or k_n, lower "
          "the impact speed, or set guards.max_grain_step_ratio";
    throw BlowUpError(os.str());
  }
  if (m.guards.max_body_overlap_ratio > 0 && st.max_body_overlap_ratio > m.guards.max_body_overlap_ratio) {
    std::ostringstream os;
    os << at(s) << "bodies '" << m.bodies[st.body_overlap_a].name << "' and '" << m.bodies[st.body_overlap_b].name
       << "' overlap by " << st.max_body_overlap_ratio
       << " of the thinner shape's half thickness, beyond the limit " << m.guards.max_body_overlap_ratio
       << " (guards.max_body_overlap_ratio); raise body_kn, lower the impact speed or reduce dt";
    throw BlowUpError(os.str());
  }
  if (st.lists_built && st.max_contacts > 0) {
    const int limit = contacts_limit(m);
    if (limit >= 0 && st.max_contacts > limit) {
      std::ostringstream os;
      os << at(s) << "grain " << st.max_contacts_grain << " touches " << st.max_contacts
         << " grains, walls or bodies at once, more than " << limit
         << " (guards.max_contacts_per_grain; 0: the bound of the scene's radii, docs/model.md §13): grains "
            "are piled into each other; check the initial positions, raise k_n or reduce dt";
      throw BlowUpError(os.str());
    }
  }
  if (st.max_overlap_ratio > m.guards.max_overlap_ratio) {
    std::ostringstream os;
    os << "numerical blow-up at step " << s.step << " (t = " << s.time << " s): overlap of grain "
       << st.max_overlap_grain << " reached " << st.max_overlap_ratio << " of its radius, beyond the limit "
       << m.guards.max_overlap_ratio << " (guards.max_overlap_ratio); raise k_n, lower the impact speed or reduce dt "
       << "(see the steps-per-contact report)";
    throw BlowUpError(os.str());
  }
}

}  // namespace rt
