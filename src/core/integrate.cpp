// Integrate stage: kick–drift–kick leapfrog (velocity Verlet). The first half
// also predicts the end-of-step velocities that the contact dashpots see; the
// springs advance with the mid-step velocities, as the positions do. Per-grain
// loops are independent, so any thread split gives the same result; the split
// is static (contiguous halves at 2 threads), so that each thread integrates
// nearly the grains whose forces it merged (forces.cpp).
#include "regolith_twin/core/integrate.hpp"

#include <algorithm>

namespace rt {

void kick_drift(const Model& m, State& s, double h, double dt) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  // Raw restrict pointers: a store through one array cannot change another's
  // data pointer, so the loop does not reload them for every grain.
  const double* __restrict inv_mass = m.grain_inv_mass.data();
  const double* __restrict inv_inertia = m.grain_inv_inertia.data();
  const Vec3* __restrict force = s.force.data();
  const Vec3* __restrict torque = s.torque.data();
  const Vec3* __restrict pos_at_build = s.pos_at_build.data();
  Vec3* __restrict pos = s.pos.data();
  Vec3* __restrict vel = s.vel.data();
  Vec3* __restrict omega = s.omega.data();
  Vec3* __restrict vel_mid = s.vel_mid.data();
  Vec3* __restrict omega_mid = s.omega_mid.data();
  bool finite = true;
  double max_d2 = s.stats.max_disp2;
  // Free flight (model.md §18): grains with a reach are measured apart.
  const bool free = !s.reach.empty();
  const double* __restrict reach = s.reach.data();
  double max_f2 = s.stats.max_free_disp2, margin = s.stats.free_margin;
  double max_v2 = 0;  // fastest grain without a reach: the grain-step guard (model.md §13)
  // With sleeping, only the awake grains (ascending ids); sleeping grains
  // keep zero velocities and do not move (model.md §16).
  const bool sleeping = sleep_active(m, s);
  const int* __restrict awake = s.sleep.awake.data();
  const int count = sleeping ? int(s.sleep.awake.size()) : n;
#pragma omp parallel for schedule(static) reduction(&& : finite) reduction(max : max_d2, max_f2, max_v2) \
    reduction(min : margin) if (n >= m.parallel_min_grains)
  for (int q = 0; q < count; ++q) {
    const int i = sleeping ? awake[q] : q;
    const double im = inv_mass[i];
    if (im == 0) {  // glued grain
      vel_mid[i] = vel[i];
      omega_mid[i] = omega[i];
      continue;
    }
    const Vec3 dv = h * (force[i] * im + g);
    const Vec3 dw = (h * inv_inertia[i]) * torque[i];
    const Vec3 v_mid = vel[i] + dv, w_mid = omega[i] + dw;
    vel_mid[i] = v_mid;
    omega_mid[i] = w_mid;
    const Vec3 x = pos[i] + dt * v_mid;
    pos[i] = x;
    vel[i] = v_mid + dv;    // predicted v(n+1) with a(n)
    omega[i] = w_mid + dw;  // predicted omega(n+1)
    // NaN and inf both fail this comparison.
    finite = finite & (v_mid.squaredNorm() + w_mid.squaredNorm() < 1e300);
    const double d2 = (x - pos_at_build[i]).squaredNorm();
    if (free && reach[i] > 0) {
      max_f2 = std::max(max_f2, d2);
      margin = std::min(margin, reach[i] - std::sqrt(d2));
    } else {
      max_d2 = std::max(max_d2, d2);
      max_v2 = std::max(max_v2, v_mid.squaredNorm());
    }
  }
  s.stats.finite = finite;
  s.stats.max_grain_step = dt * std::sqrt(max_v2);
  s.stats.max_disp2 = max_d2;
  s.stats.max_free_disp2 = max_f2;
  s.stats.free_margin = margin;
}

void finish_kick(const Model& m, State& s, double h) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  const double* __restrict inv_mass = m.grain_inv_mass.data();
  const double* __restrict inv_inertia = m.grain_inv_inertia.data();
  const Vec3* __restrict force = s.force.data();
  const Vec3* __restrict torque = s.torque.data();
  const Vec3* __restrict vel_mid = s.vel_mid.data();
  const Vec3* __restrict omega_mid = s.omega_mid.data();
  Vec3* __restrict vel = s.vel.data();
  Vec3* __restrict omega = s.omega.data();
  bool finite = true;
  const bool sleeping = sleep_active(m, s);
  const int* __restrict awake = s.sleep.awake.data();
  const int count = sleeping ? int(s.sleep.awake.size()) : n;
#pragma omp parallel for schedule(static) reduction(&& : finite) if (n >= m.parallel_min_grains)
  for (int q = 0; q < count; ++q) {
    const int i = sleeping ? awake[q] : q;
    const double im = inv_mass[i];
    if (im == 0) continue;
    const Vec3 v = vel_mid[i] + h * (force[i] * im + g);
    const Vec3 w = omega_mid[i] + (h * inv_inertia[i]) * torque[i];
    vel[i] = v;
    omega[i] = w;
    finite = finite & (v.squaredNorm() + w.squaredNorm() < 1e300);
  }
  s.stats.finite = finite;
}

}  // namespace rt

namespace rt {

namespace {
// Contact force and torque of the last pass plus any applied wrench.
inline Vec3 total_force(const State& s, size_t b) {
  return s.body_applied_force.empty() ? s.bodies[b].force : Vec3(s.bodies[b].force + s.body_applied_force[b]);
}
inline Vec3 total_torque(const State& s, size_t b) {
  return s.body_applied_torque.empty() ? s.bodies[b].torque : Vec3(s.bodies[b].torque + s.body_applied_torque[b]);
}
}  // namespace

// Bodies: the same kick–drift–kick on the centre of mass; the rotation is a
// kick of the world angular momentum by the torque, then the exact-flow
// splitting of the free rigid body over dt (free_rotation), then the second
// kick. Angular velocities follow from L and the current orientation.
void kick_drift_bodies(const Model& m, State& s, double h, double dt) {
  s.stats.bad_body = -1;
  s.stats.max_body_step = 0;
  s.stats.max_body_step_body = -1;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyModel& bm = m.bodies[b];
    BodyState& bs = s.bodies[b];
    if (bm.fixed) continue;
    const Vec3 force = total_force(s, b), torque = total_torque(s, b);
    const Vec3 dv = h * (force / bm.mass + m.gravity);
    bs.vel_mid = bs.vel + dv;
    bs.pos += dt * bs.vel_mid;
    bs.ang_mom += h * torque;  // L(n+1/2)
    bs.q = free_rotation(bm.inertia, bs.q, bs.ang_mom, dt);
    const Mat3 inv_i = inverse_inertia_world(bm, bs.q);
    bs.omega_mid = inv_i * bs.ang_mom;
    bs.vel = bs.vel_mid + dv;                     // predicted v(n+1)
    bs.omega = inv_i * (bs.ang_mom + h * torque);  // predicted omega(n+1)
    if (!(bs.vel.squaredNorm() + bs.omega.squaredNorm() < 1e300) || !bs.pos.allFinite() || !bs.q.coeffs().allFinite()) {
      s.stats.finite = false;
      if (s.stats.bad_body < 0) s.stats.bad_body = int(b);
    }
    // Largest drift of a point of the body in this step (tunnelling guard, docs/model.md §13).
    const double drift = dt * (bs.vel_mid.norm() + bs.omega_mid.norm() * bm.bound_radius);
    if (drift > s.stats.max_body_step) {
      s.stats.max_body_step = drift;
      s.stats.max_body_step_body = int(b);
    }
  }
}

void finish_kick_bodies(const Model& m, State& s, double h) {
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyModel& bm = m.bodies[b];
    BodyState& bs = s.bodies[b];
    if (bm.fixed) continue;
    bs.vel = bs.vel_mid + h * (total_force(s, b) / bm.mass + m.gravity);
    bs.ang_mom += h * total_torque(s, b);
    bs.omega = inverse_inertia_world(bm, bs.q) * bs.ang_mom;
    if (!(bs.vel.squaredNorm() + bs.omega.squaredNorm() < 1e300)) {
      s.stats.finite = false;
      if (s.stats.bad_body < 0) s.stats.bad_body = int(b);
    }
  }
}

}  // namespace rt
