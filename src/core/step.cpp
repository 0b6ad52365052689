// The time step: a short pipeline of stages (see step.hpp).
#include "regolith_twin/core/step.hpp"

#include <sstream>

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/forces.hpp"
#include "regolith_twin/core/integrate.hpp"
#include "regolith_twin/core/neighbours.hpp"
#include "regolith_twin/core/sleep.hpp"

namespace rt {

void prime(const Model& m, State& s) {
  build_neighbour_lists(m, s);
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
  if (lists_need_rebuild(m, s))                                    // neighbours
    build_neighbour_lists(m, s);
  else if (body_list_needs_rebuild(m, s))
    build_body_list(m, s);
  compute_forces(m, s);                                            // contacts -> forces
  apply_fields(m, s);                                              // fields -> forces
  finish_kick(m, s, 0.5 * m.dt);                                   // integrate: half kick
  finish_kick_bodies(m, s, 0.5 * m.dt);
  s.time += m.dt;
  ++s.step;
  s.ticks += s.tick_len;
  check_guards(m, s);                                              // guards
  update_sleep(m, s);                                              // sleep: wake and put quiet cells to sleep
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
