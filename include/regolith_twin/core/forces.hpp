// Contacts and forces stage: grain–grain and grain–wall contact forces from
// the lists, accumulated per fixed work partition and merged in partition
// order, so results do not depend on the thread count.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Zero and recompute s.force and s.torque (contacts only; gravity is applied
// by the integrator, fields by apply_fields in field.hpp) and s.stats.
void compute_forces(const Model& m, State& s);

}  // namespace rt
