// Fixes: what acts on a run's model or state, at named points of the step
// and of the run (docs/architecture.md, "Measures and fixes"). A measure
// (observer.hpp) reads; a fix changes things: a stage's gravity ramp or
// damping, held groups, the stiffness schedule, the active zone, a second
// projectile. The run (run.hpp) calls every fix at each hook in the order
// the fixes were added; its own stage fixes (stage_fixes.hpp) come first.
//
// One step, as the run takes it:
//   before_step          gravity ramp
//   (series row, engine step)
//   after_step           damping of bed preparation, held grains put back
//   add_grains           grains that join the run now (grains_added follows)
//   (measures' after_step and end conditions)
//   after_measures       actions on what the step did (the active zone follows the body)
//   (grains the measures take out; grains_removed follows)
//   end_step             last word on the step (the stiffness schedule)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "regolith_twin/core/state.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {

struct Stage;
struct StageReport;
struct RunReport;

class Fix {
 public:
  virtual ~Fix() = default;
  // Run start, before the forces of the start state: a fix that changes the
  // model does it here (and clears s.forces_valid when forces must be recomputed).
  virtual void prepare(Model& m, State& s) {}
  // Run start, once the forces are known and the measures have started.
  virtual void start(Model& m, State& s) {}
  // Each stage's start, in order; what the fix did goes into the stage's report.
  virtual void stage_start(const Stage& st, Model& m, State& s, StageReport& rep) {}
  virtual void before_step(const Stage& st, Model& m, State& s) {}
  virtual void after_step(const Stage& st, Model& m, State& s) {}
  // Grains to add to the run now (rt::add_grain, core/edit.hpp).
  virtual void add_grains(Model& m, State& s) {}
  virtual void after_measures(Model& m, State& s) {}
  // grains_added: true when grains joined the run in this step.
  virtual void end_step(Model& m, State& s, bool grains_added) {}
  // Grains [first, m.n_grains) joined the run; or grains left it
  // (old_to_new[i]: grain i's new index, or -1): per-grain data follows.
  virtual void grains_added(const Model& m, const State& s, int first) {}
  virtual void grains_removed(const std::vector<int>& old_to_new) {}
  // True while the fix puts energy in: the energy-growth guard (docs/model.md §13)
  // then takes a new reference instead of checking.
  virtual bool energy_input() const { return false; }
  // At the run end (also after a blow-up), and what the fix reports.
  virtual void finish(Model& m, State& s) {}
  virtual void summary(JsonObject& out) const {}
  // Columns of series.csv (after the measures'), and their values now.
  virtual void columns(std::vector<std::string>& out) const {}
  virtual void row(const Model& m, const State& s, std::vector<double>& out) const {}
  virtual void report(const State& s, RunReport& rep) const {}
  // Text for the progress line ("" for none).
  virtual std::string progress(const Model& m, const State& s) const { return ""; }
};

}  // namespace rt
