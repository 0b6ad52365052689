// Scenario files: a YAML description of materials, walls, grain groups, run
// stages and outputs, turned into a Model and an initial State. Every error
// names the file, the key and the allowed range.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "regolith_twin/core/model.hpp"
#include "regolith_twin/core/state.hpp"

namespace YAML {
class Node;
}

namespace rt {

// A named, contiguous range of grain ids created by one `grains` entry.
struct GrainGroup {
  std::string name;
  int first = 0;   // first grain id
  int count = 0;   // number of grains
};

// One phase of a run.
struct Stage {
  std::string name;
  double duration = 0;                // s of simulated time (maximum)
  std::vector<std::string> hold;      // groups held in place during the stage
  std::vector<std::string> remove_walls;  // walls taken away when the stage starts (a lifted cylinder)
  double until_rms_speed = -1;        // end early once RMS grain speed is below this, m/s (<0: off)
  double until_max_speed = -1;        // ... and the max grain speed below this, m/s (<0: off)
  double check_every = 0.01;          // s between checks of the criteria
  bool set_gravity = false;           // change gravity at the start of the stage
  Vec3 gravity = Vec3::Zero();        // new gravity, m/s^2
  double gravity_ramp = 0;            // s over which gravity moves geometrically to the new value (0: at once)
  double stiffness_scale = 0;         // > 0: k_n of this stage = scale * the scene's, dt = scene dt / sqrt(scale)
  double max_injection = -1;          // >= 0: the elastic energy the change of k_n adds must stay below this
                                      // fraction of the kinetic energy, or the run stops (docs/model.md §4)
                                      //      (softer springs for bed preparation); 0: keep the current values
  double quench_every = 0;            // > 0: every this many seconds, all grain velocities and spins are
                                      //      set to zero (bed preparation: a quasi-static descent)
  bool minimize = false;              // after every step, each grain keeps only the part of its velocity
                                      //   along its net force, none if it moves against it (quick-min:
                                      //   a damped descent to static equilibrium for bed preparation)
  bool release_springs = false;       // with minimize: tangential, rolling and twisting springs are
                                      //   emptied after every step, so frictional contacts cannot hold
                                      //   the overlaps of a higher gravity while it is lowered
  bool trim = false;                  // remove grains at the start of the stage
  double trim_above = 0;              // ... whose centre lies above this height (z), m
  bool trim_tops = false;             // ... or, when set, whose top (z + r) lies above it
};

struct Scenario {
  std::string file;                   // path it was read from ("<string>" when parsed from text)
  std::string name;
  uint64_t seed = 1;
  Model model;
  State initial;
  std::vector<GrainGroup> groups;
  std::vector<Stage> stages;
  double output_every = 0.01;         // s of simulated time between time-series rows
  double v_ref = 1.0;                 // reference impact speed for resolution reports, m/s
  std::vector<PairResolution> resolution;  // steps per contact of every pair type
  std::vector<std::string> warnings;  // non-fatal remarks (under-resolved contacts, ...)
  double scene_kn = 0, scene_dt = 0;  // k_n and dt as parsed (stages may scale the model's)
  double scene_body_kn = 0;           // contact.body_kn as parsed (0: the scene k_n; stages scale it too)
  int carved_grains = 0;              // grains removed where bodies with 'carve: true' sit
  std::vector<int> carve;             // bodies with 'carve: true'
  const GrainGroup* group(const std::string& name) const;
};

// Read a scenario file. `overrides` are "dotted.key=yaml-value" strings applied
// to the document before it is interpreted (command-line --set).
Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides = {});

// Read a YAML document and apply "dotted.key=yaml-value" overrides, for tools
// that take extra top-level blocks out before parse_scenario. A top-level
// `base: FILE` (relative to the document) starts from FILE: mappings merge key
// by key, lists and scalars given here replace the base's.
YAML::Node load_document(const std::string& path, const std::vector<std::string>& overrides = {});

// What a scene kind derives from its own keys instead of reading it from `contact:` and `schedule:`
// (the sampler: k_n and dt from its shot speed, and that speed as the stiffness schedule's design
// speed; docs/model.md §4, §17). 0: read from the file as usual. A derived k_n or dt that the file
// also gives is refused: the file would say one thing and the run do another.
struct DerivedContact {
  double kn = 0;            // N/m
  double dt = 0;            // s
  double design_speed = 0;  // m/s: schedule.speed where the file does not give it
  std::string by;           // who derives them, for the message ("sampler.speed")
};

// Interpret an already parsed document; `source` names it in error messages.
Scenario parse_scenario(const YAML::Node& root, const std::string& source, const DerivedContact& derived = {});
Scenario parse_scenario_text(const std::string& yaml_text, const std::string& source = "<string>");

// Remove the grains flagged in `drop` from the scenario's model and from the
// state (rt::remove_grains, core/edit.hpp: survivors keep their kinematics and
// the springs of the contacts they keep; lists are rebuilt at the next step).
// Grain groups shrink accordingly. Returns the number removed.
int remove_grains(Scenario& sc, State& s, const std::vector<uint8_t>& drop);
int remove_grains(Model& m, State& s, const std::vector<uint8_t>& drop, std::vector<GrainGroup>& groups,
                  std::vector<int>* old_to_new = nullptr);

// Published materials (docs/model.md §9): gravel, moderate, glass_beads, glass_beads_b.
// "bodies[0].name = 'a', bodies[1].name = 'b'": the bodies a kind's key may
// name, for its message when it names none of them.
std::string body_names_text(const Model& m);

bool material_preset(const std::string& name, Material& out);

}  // namespace rt
