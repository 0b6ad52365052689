// Beds for any scene: the scenario's stages relax the bed once, and the
// exact relaxed state (a checkpoint with contact history) is cached, so every
// later run on the same bed starts from it bit-identically. The key covers the
// bed (grain radii, start positions), the model (materials, walls, bodies
// other than those the scene places, k_n, dt, skin, partitions) and the scene
// gravity. docs/scenes.md, "Beds".
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/run/scene.hpp"

namespace rt {

struct RelaxedBed {
  State state;            // relaxed bed
  std::string cache;      // its checkpoint
  bool from_cache = false;
};

// Cache key of the bed in (sc.model, s); bodies listed in `placed` are left
// out (the scene moves them away for the relaxation and places them after).
std::string bed_key(const Model& m, const State& s, const std::vector<int>& placed);

// The bed of s relaxed by the scenario's stages (sc.model as the stages
// leave it, without its fields, sleeping or stiffness schedule), or the cached one (sc.model untouched). `label` prefixes the
// progress lines. Throws InputError without stages, BlowUpError if the
// relaxation fails.
RelaxedBed relax_bed(Scenario& sc, const State& s, const std::vector<int>& placed, const SceneOptions& opt,
                     const std::string& label);

}  // namespace rt
