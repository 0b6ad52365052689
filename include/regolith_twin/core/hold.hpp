// Grains held at rest: the one home of "this grain does not move"
// (docs/model.md §19). Model::grain_hold keeps one bit per policy that holds
// a grain; a grain is held while any bit is set, and free when none is.
// A held grain has infinite mass and stays at rest: its inverse mass and
// inertia are 0, so the integrator leaves it where it is and the contact law
// sees only its partner's mass; the contact search skips pairs of two held
// grains. Freed, its inverse mass and inertia come back from its mass and
// radius (grain_inverse_mass, the same numbers finalize_model gives).
//
// Two other ways a grain stays put are not policies of this mask, because
// they are not "infinite mass at rest": a sleeping grain (core/sleep.hpp) is
// a saving that leaves the step while its neighbourhood is quiet and wakes on
// a force change; a held group of a stage (run/stage_fixes.hpp) is put back
// where the stage began after every step, keeping its mass in the contacts.
#pragma once

#include <cstdint>

#include "regolith_twin/core/state.hpp"

namespace rt {

enum HoldPolicy : uint8_t {
  kHoldGlued = 1,        // glued by the scene file (`fixed: true`) or by a scene (the incline's rain)
  kHoldOutsideZone = 2,  // beyond the landing's active zone (observers/active_zone.hpp)
  kHoldAnchored = 4,     // below the plume's anchoring plane (scenes/plume/erosion.hpp)
};

inline bool held(const Model& m, int i) { return m.grain_hold[i] != 0; }

// Inverse mass and inertia of free grain i from its mass and radius.
struct InverseMass {
  double mass, inertia;  // 1/kg, 1/(kg m^2)
};
InverseMass grain_inverse_mass(const Model& m, int i);

// Hold grain i by policy p: infinite mass, at rest. Lists and pair constants
// follow at the next rebuild: the caller sets s.rebuild_requested.
void hold_grain(Model& m, State& s, int i, HoldPolicy p);
// Let policy p go of grain i (nothing if p does not hold it); the grain is
// free again once no policy holds it.
void release_grain(Model& m, int i, HoldPolicy p);

}  // namespace rt
