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
// truncated or corrupted file, or one whose state could not be stepped.
State load_checkpoint(const std::string& path, const Model& m);

// The same in two halves, so a caller can keep file I/O apart from the
// state (the node holds its simulation lock only for the in-memory halves):
// the bytes of a checkpoint of s; writing bytes to path atomically; reading
// a file's bytes; a state from bytes (`path` names the source in errors).
std::string checkpoint_image(const Model& m, const State& s);
void write_checkpoint_file(const std::string& path, const std::string& image);
std::string read_checkpoint_file(const std::string& path);
State state_from_checkpoint(const std::string& path, const std::string& data, const Model& m);

}  // namespace rt
