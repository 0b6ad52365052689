// Checkpoints: the whole evolving state (kinematics, forces, neighbour lists
// with spring history) in a versioned binary file with a checksum, written
// atomically. Loading one and stepping continues bit-identically.
#pragma once

#include <string>

#include "regolith_twin/core/state.hpp"

namespace rt {

// Write s to path (temporary file + rename: a crash leaves any previous file intact).
void save_checkpoint(const std::string& path, const Model& m, const State& s);

// Read a checkpoint written for the same model (grain count, radii and
// materials must match). Throws InputError naming the file on a wrong,
// truncated or corrupted file.
State load_checkpoint(const std::string& path, const Model& m);

}  // namespace rt
