// Measures: what reads a run, behind one small interface (docs/architecture.md,
// "Measures and fixes"). The run loop (run.hpp) calls start() once before the
// first step, after_step() after every step (where a measure may end the run),
// asks each measure for its columns of the time series when a row is due, and
// calls finish() at the run end; summary() gives its figures for summary.json.
// A measure sees the model and state read-only; what changes them is a fix
// (fix.hpp). Measures may ask for grains to be taken out of the run (grains
// that left the scene). Scene kinds compose their runs from both.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "regolith_twin/core/state.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {

class Observer {
 public:
  virtual ~Observer() = default;
  // Before the first step, once the forces of the start state are known.
  virtual void start(const Model& m, const State& s) {}
  // Grains [first, m.n_grains) were just added by a fix (a second
  // projectile): measures that keep per-grain data grow it here.
  virtual void grains_added(const Model& m, const State& s, int first) {}
  // After every step; true ends the run (a landing that has lifted off and flown).
  virtual bool after_step(const Model& m, const State& s) { return false; }
  // Grains to take out of the run: set drop[i] = 1 (drop has one zero entry
  // per grain) and return true if any. Asked after every step, after after_step().
  virtual bool leaving(const Model& m, const State& s, std::vector<uint8_t>& drop) { return false; }
  // Grains were removed: old_to_new[i] is grain i's new index, or -1.
  // Measures that keep per-grain data renumber it here.
  virtual void grains_removed(const std::vector<int>& old_to_new) {}
  // Names of this measure's columns of series.csv, and their values now.
  virtual void columns(std::vector<std::string>& out) const {}
  virtual void row(const Model& m, const State& s, std::vector<double>& out) const {}
  // At the run end (also after a blow-up).
  virtual void finish(const Model& m, const State& s) {}
  // Its figures for summary.json (after finish).
  virtual void summary(JsonObject& out) const {}
  // Text for the progress line ("" for none).
  virtual std::string progress(const Model& m, const State& s) const { return ""; }
  // Simulated time left at most, s, when the measure knows it (< 0: it does not).
  virtual double time_left(const State& s) const { return -1; }
  // Simulated time left as the measure expects it, s: an estimate, not a bound
  // (< 0: it has none). The progress line's ETA prefers it to the bound.
  virtual double expected_time_left(const State& s) const { return -1; }
};

}  // namespace rt
