// Integrate stage: kick–drift–kick leapfrog (velocity Verlet) for grains.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// v += h (F/m + g), omega += h T/I for every free grain; flags non-finite values.
void kick(const Model& m, State& s, double h);
// x += h v; tracks the largest displacement since the last list build.
void drift(const Model& m, State& s, double h);

// kick(hk) then drift(hd) in one pass over the grains (the step's first half).
void kick_drift(const Model& m, State& s, double hk, double hd);

}  // namespace rt
