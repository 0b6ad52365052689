// The time step as a pipeline of stages:
//   integrate (kick_drift) -> neighbours -> contacts/forces -> fields -> integrate (finish_kick) -> guards.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Build lists and forces for the current positions (done by the first step).
void prime(const Model& m, State& s);

// Advance the state by one time step m.dt. Throws BlowUpError when a guard trips.
void step(const Model& m, State& s);

// Throws BlowUpError with a diagnostic if the last step tripped a guard
// (docs/model.md §13): non-finite states, a grain or body step beyond its
// limit, a grain or body–body overlap beyond its limit, too many contacts on one grain.
void check_guards(const Model& m, const State& s);

// Touching contacts (grains, walls, bodies) of the grain with the most;
// sets s.stats.max_contacts and max_contacts_grain.
void count_contacts(const Model& m, State& s);

// The most contacts one grain may have: guards.max_contacts_per_grain, or when
// 0 the bound of the scene's radii and overlap limit (docs/model.md §13); < 0: none.
int contacts_limit(const Model& m);

// Energy-growth guard of a passive scene (docs/model.md §13), checked by the
// run loop: the total energy may exceed its lowest value since the last
// reset by at most guards.max_energy_growth times the scale, the largest of
// the mobile (kinetic + elastic) energy seen at earlier checks and
// Σ m |g| d_mean over the free grains.
class EnergyWatch {
 public:
  // Forget the reference (the scene was edited, or energy was put in).
  void reset() { valid_ = false; }
  // Throws BlowUpError when the energy grew beyond the limit.
  void check(const Model& m, const State& s);

 private:
  bool valid_ = false;
  double e_min_ = 0, scale_ = 0;
  // What the reference was taken with: a change resets it.
  int n_grains_ = 0, n_frozen_ = 0;
  long frozen_sum_ = 0;
  double kn_ = 0, dt_ = 0;
  Vec3 g_ = Vec3::Zero();
};

}  // namespace rt
