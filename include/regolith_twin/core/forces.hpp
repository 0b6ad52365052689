// Contacts and forces stage: grain–grain and grain–wall contact forces from
// the lists, accumulated per fixed work partition and merged in partition
// order, so results do not depend on the thread count.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Zero and recompute s.force and s.torque (contacts only; gravity is applied
// by the integrator, fields by apply_fields in field.hpp) and s.stats.
void compute_forces(const Model& m, State& s);

// Grains that wake (woken[i] = 1, already marked awake) get the forces of
// the contacts the last pass skipped because both grains slept, and of
// their wall contacts, evaluated with the springs held (both sides at rest),
// so the next step starts from their full forces (docs/model.md §16).
void add_woken_contacts(const Model& m, State& s, const std::vector<uint8_t>& woken);

}  // namespace rt
