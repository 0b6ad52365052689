// A landing file made ready to run: scenario + landing block read (with
// overrides), the bed relaxed once under the scene gravity and cached as an
// exact checkpoint, the perturbed repeat applied and the lander placed.
// Shared by regolith_land, the sweep and the ROS node, so all three start a
// landing from the same state.
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/observe/landing.hpp"
#include "regolith_twin/scene/scenario.hpp"

namespace rt {

struct LandingScene {
  std::string file;       // landing file it was read from
  Scenario sc;            // model gravity set from the landing block
  LandingSpec spec;       // as given
  LandingSpec run_spec;   // with the perturbation of the repeat applied (aim)
  Perturbation pert;
  int lander = -1;        // body index of the lander
  State start;            // relaxed bed, lander placed, time 0
  std::string bed_cache;  // checkpoint of the relaxed bed
  double packing = 0;     // grains below the trim plane / container volume
  double bulk_density = 0;  // kg/m^3
};

struct LandingSetupOptions {
  std::string cache_dir;    // relaxed beds (empty: default_cache_dir())
  std::string relax_out;    // output folder of a bed relaxation (empty: none written)
  bool quiet = false;       // no progress lines
};

// $REGOLITH_CACHE, else ~/.cache/regolith_twin.
std::string default_cache_dir();

// Throws InputError for bad input, BlowUpError if the bed relaxation fails.
LandingScene prepare_landing(const std::string& file, const std::vector<std::string>& overrides,
                             const LandingSetupOptions& opt);

// summary.json of a landing: input, bed, outcome, run figures.
void write_landing_summary(const std::string& path, const LandingScene& ls, const LandingOutcome& o, int threads);

}  // namespace rt
