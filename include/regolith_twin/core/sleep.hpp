// Sleep stage: quiescent regions of a bed leave the step (docs/model.md §16).
// Grains are binned in cubic cells; the decisions are taken cell by cell at
// checks (every few steps) and from the forces on sleeping grains (every
// step), serially and in grain order, so they are the same for any thread
// count and across a checkpoint resume.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// After a step's force pass and second half kick: wake cells that something
// reached, put quiet cells to sleep. Does nothing unless m.sleep.enabled.
// Woken grains get the forces of the contacts the last pass skipped (springs
// held), so the next step starts from their full forces; any change
// recomputes the force pass's entry segments.
void update_sleep(const Model& m, State& s);

// Wake every grain (sleep state kept initialised), completing their forces.
void wake_all(const Model& m, State& s);

// Speed, time and force thresholds of the sleep rule for model m.
struct SleepThresholds {
  double speed;  // m/s
  double time;   // s
  double force_per_mass;  // N/kg (times the grain mass)
  double cell;   // m
  double margin; // how far a grain may travel between checks without reaching a sleeping grain unseen, m
};
// d: the mean grain diameter (State::sleep.d_mean once sleeping has started).
SleepThresholds sleep_thresholds(const Model& m, double d);
SleepThresholds sleep_thresholds(const Model& m);  // d from the model's grains

// Number of sleeping grains.
long sleeping_grains(const State& s);

// Derived lists (awake, watch) and the force pass's entry segments for the
// current pair list and sleep flags (called by partition_work).
void sleep_segments(const Model& m, State& s);

}  // namespace rt
