// The time step as a pipeline of stages:
//   integrate (kick_drift) -> neighbours -> contacts/forces -> fields -> integrate (finish_kick) -> guards.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Build lists and forces for the current positions (done by the first step).
void prime(const Model& m, State& s);

// Advance the state by one time step m.dt. Throws BlowUpError when a guard trips.
void step(const Model& m, State& s);

// Throws BlowUpError with a diagnostic if the last step left non-finite
// velocities or an overlap beyond the model's limit.
void check_guards(const Model& m, const State& s);

}  // namespace rt
