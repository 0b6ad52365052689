// Integrate stage: kick–drift–kick leapfrog. Per-grain loops are independent,
// so any thread split gives the same result.
#include "regolith_twin/core/integrate.hpp"

#include <algorithm>

namespace rt {

void kick(const Model& m, State& s, double h) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  bool finite = true;
#pragma omp parallel for schedule(static) reduction(&& : finite) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    const double im = m.grain_inv_mass[i];
    if (im == 0) continue;  // glued grain
    s.vel[i] += h * (s.force[i] * im + g);
    s.omega[i] += (h * m.grain_inv_inertia[i]) * s.torque[i];
    // NaN and inf both fail this comparison.
    finite = finite && (s.vel[i].squaredNorm() + s.omega[i].squaredNorm() < 1e300);
  }
  s.stats.finite = finite;
}

void kick_drift(const Model& m, State& s, double hk, double hd) {
  const int n = m.n_grains;
  const Vec3 g = m.gravity;
  bool finite = true;
  double max_d2 = s.stats.max_disp2;
#pragma omp parallel for schedule(static) reduction(&& : finite) reduction(max : max_d2) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    const double im = m.grain_inv_mass[i];
    if (im == 0) continue;
    const Vec3 v = s.vel[i] + hk * (s.force[i] * im + g);
    s.vel[i] = v;
    s.omega[i] += (hk * m.grain_inv_inertia[i]) * s.torque[i];
    finite = finite && (v.squaredNorm() + s.omega[i].squaredNorm() < 1e300);
    s.pos[i] += hd * v;
    max_d2 = std::max(max_d2, (s.pos[i] - s.pos_at_build[i]).squaredNorm());
  }
  s.stats.finite = finite;
  s.stats.max_disp2 = max_d2;
}

void drift(const Model& m, State& s, double h) {
  const int n = m.n_grains;
  double max_d2 = s.stats.max_disp2;
#pragma omp parallel for schedule(static) reduction(max : max_d2) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    if (m.grain_inv_mass[i] == 0) continue;
    s.pos[i] += h * s.vel[i];
    max_d2 = std::max(max_d2, (s.pos[i] - s.pos_at_build[i]).squaredNorm());
  }
  s.stats.max_disp2 = max_d2;
}

}  // namespace rt
