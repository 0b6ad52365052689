// Runs a scenario's stages on a state, sampling observers into the output
// folder: series.csv (energy, contacts, overlap, small groups' motion),
// summary.json (run figures and outcome), final_grains.txt (end state).
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/scene/scenario.hpp"

namespace rt {

struct RunOptions {
  std::string out_dir;          // created if missing; empty: write nothing
  double progress_every = 2.0;  // wall seconds between progress lines (<= 0: none)
  int threads = 0;              // recorded in the summary (set by the caller)
  bool stage_snapshots = false; // write out_dir/<stage>.bed (compact snapshot) after every stage
};

struct StageReport {
  std::string name;
  double t_end = 0;         // simulated time at the end of the stage, s
  std::string reason;       // "duration" or "criteria"
  int grains_removed = 0;   // by the stage's trim
};

struct RunReport {
  std::string status = "ok";  // ok | blow_up
  std::string message;        // diagnostic when not ok
  long steps = 0;
  double sim_time = 0;        // s
  double wall_seconds = 0;
  double max_overlap_ratio = 0;
  Energy initial, final;
  std::vector<StageReport> stages;
};

// Stages may change the scenario's model (gravity, trimmed grains), so the
// scenario is taken by reference and left as the last stage had it.
RunReport run_scenario(Scenario& sc, State& s, const RunOptions& opt);

}  // namespace rt
