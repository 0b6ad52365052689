// Compact bed snapshots: grain centres and radii in float32 (16 bytes a
// grain) or float64 (32 bytes: for stiff scenes, where float32 rounding of a
// position, ~1.5e-8 m at 0.2 m, exceeds the equilibrium overlaps; docs/model.md
// §14), small enough to ship with the repository, with a checksum. A snapshot
// holds no velocities or contact history: a loaded bed is relaxed again
// before use (deterministically), and exact states go to checkpoints.
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/core/state.hpp"

namespace rt {

struct SnapshotGrain {
  Vec3 pos;       // m (stored as float32 or float64)
  double radius;  // m
};

enum class SnapshotPrecision { Float32, Float64 };

// Write the free grains (fixed grains are skipped unless include_fixed) atomically.
void write_snapshot(const std::string& path, const Model& m, const State& s, bool include_fixed = false,
                    SnapshotPrecision precision = SnapshotPrecision::Float32);

// Read a snapshot; throws InputError naming the file when it is missing,
// truncated, corrupted or of another format.
std::vector<SnapshotGrain> read_snapshot(const std::string& path);

// True when the file starts with the snapshot header.
bool is_snapshot(const std::string& path);

}  // namespace rt
