// Integrate stage: kick–drift–kick leapfrog (velocity Verlet). The first half
// also predicts the end-of-step velocities that the contact dashpots see; the
// springs advance with the mid-step velocities, as the positions do. Per-grain
// loops are independent, so any thread split gives the same result.
#include "regolith_twin/core/integrate.hpp"

#include <algorithm>

namespace rt {

void kick_drift(const Model& m, State& s, double h, double dt) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  bool finite = true;
  double max_d2 = s.stats.max_disp2;
#pragma omp parallel for schedule(static) reduction(&& : finite) reduction(max : max_d2) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    const double im = m.grain_inv_mass[i];
    if (im == 0) {  // glued grain
      s.vel_mid[i] = s.vel[i];
      s.omega_mid[i] = s.omega[i];
      continue;
    }
    const Vec3 dv = h * (s.force[i] * im + g);
    const Vec3 dw = (h * m.grain_inv_inertia[i]) * s.torque[i];
    const Vec3 v_mid = s.vel[i] + dv, w_mid = s.omega[i] + dw;
    s.vel_mid[i] = v_mid;
    s.omega_mid[i] = w_mid;
    s.pos[i] += dt * v_mid;
    s.vel[i] = v_mid + dv;    // predicted v(n+1) with a(n)
    s.omega[i] = w_mid + dw;  // predicted omega(n+1)
    // NaN and inf both fail this comparison.
    finite = finite && (v_mid.squaredNorm() + w_mid.squaredNorm() < 1e300);
    max_d2 = std::max(max_d2, (s.pos[i] - s.pos_at_build[i]).squaredNorm());
  }
  s.stats.finite = finite;
  s.stats.max_disp2 = max_d2;
}

void finish_kick(const Model& m, State& s, double h) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  bool finite = true;
#pragma omp parallel for schedule(static) reduction(&& : finite) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    const double im = m.grain_inv_mass[i];
    if (im == 0) continue;
    s.vel[i] = s.vel_mid[i] + h * (s.force[i] * im + g);
    s.omega[i] = s.omega_mid[i] + (h * m.grain_inv_inertia[i]) * s.torque[i];
    finite = finite && (s.vel[i].squaredNorm() + s.omega[i].squaredNorm() < 1e300);
  }
  s.stats.finite = finite;
}

}  // namespace rt
