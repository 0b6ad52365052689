// The plain scenario kind: a file without a kind block runs its stages,
// writing series.csv (energy, contacts, overlap, small groups' motion),
// summary.json (run figures, stages) and final_grains.txt (end state).
// docs/scenes.md, "Plain scenarios".
#pragma once

#include <memory>

#include "regolith_twin/run/scene.hpp"

namespace rt {

// The kind the registry falls back to.
std::shared_ptr<const SceneKind> scenario_kind();

// A scenario's stages on s, with the outputs of the plain kind in
// opt.out_dir (series rows every sc.output_every). Stages may change the
// model (gravity, stiffness, trimmed grains): sc.model and sc.groups are left
// as the last stage had them.
RunReport run_scenario(Scenario& sc, State& s, const RunOptions& opt, int threads = 0);

}  // namespace rt
