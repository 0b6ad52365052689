// Integrate stage: kick–drift–kick leapfrog (velocity Verlet) for grains.
//
//   kick_drift:  v(n+1/2) = v(n) + h a(n);  x(n+1) = x(n) + dt v(n+1/2);
//                vel <- v(n+1/2) + h a(n), the predicted v(n+1) that the
//                contact dashpots see (a half-step-old velocity would bias the
//                restitution at first order in dt); vel_mid <- v(n+1/2).
//   finish_kick: v(n+1) = v(n+1/2) + h a(n+1).
// The same for spin. h = dt/2. Gravity is added here; glued grains stay put.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

void kick_drift(const Model& m, State& s, double h, double dt);
void finish_kick(const Model& m, State& s, double h);

// Rigid bodies: kick–drift with the free-rotation splitting for the
// orientation (docs/model.md §6), and the closing kick. Run after the grains'
// stage of the same name (they combine its finiteness check).
void kick_drift_bodies(const Model& m, State& s, double h, double dt);
void finish_kick_bodies(const Model& m, State& s, double h);

}  // namespace rt
