// Grains held at rest (see hold.hpp).
#include "regolith_twin/core/hold.hpp"

namespace rt {

InverseMass grain_inverse_mass(const Model& m, int i) {
  const double mass = m.grain_mass[i], r = m.grain_radius[i];
  return {1.0 / mass, 1.0 / (0.4 * mass * r * r)};
}

void hold_grain(Model& m, State& s, int i, HoldPolicy p) {
  m.grain_hold[i] |= p;
  m.grain_inv_mass[i] = 0;
  m.grain_inv_inertia[i] = 0;
  s.vel[i].setZero();
  s.omega[i].setZero();
}

void release_grain(Model& m, int i, HoldPolicy p) {
  if (!(m.grain_hold[i] & p)) return;
  m.grain_hold[i] &= uint8_t(~p);
  if (held(m, i)) return;
  const InverseMass im = grain_inverse_mass(m, i);
  m.grain_inv_mass[i] = im.mass;
  m.grain_inv_inertia[i] = im.inertia;
}

}  // namespace rt
