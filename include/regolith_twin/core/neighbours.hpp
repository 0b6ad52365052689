// Neighbours stage: cell lists rebuilt when a grain has moved half a skin,
// giving the half pair list and the grain–wall list with carried-over history.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// True when some grain moved more than half the skin since the last build.
bool lists_need_rebuild(const Model& m, const State& s);

// Rebuild pair and wall lists from the current positions, keeping the spring
// history of every pair present in both the old and the new list, and the
// fixed partition of the rows used by the force pass.
void build_neighbour_lists(const Model& m, State& s);

// True when the grain–body list may have missed a contact: grain plus body
// displacement since its build exceeds the skin. Rebuilt with the other
// lists, and on its own when only bodies moved (a fast impactor).
bool body_list_needs_rebuild(const Model& m, const State& s);
void build_body_list(const Model& m, State& s);
// Split the grain–body entries into the fixed work partitions (done by every
// build; needed again after a checkpoint restores the list).
void partition_body_list(const Model& m, State& s);

// The box of the grains' centres, lo and hi (both zero without grains); the cell grids of the contact
// search and of sleeping are laid over it.
void grain_bounds(const Model& m, const State& s, Vec3& lo, Vec3& hi);

// Recompute the per-entry constants and the fixed work partition of the
// current lists (done by every build; needed again only after lists are
// restored from a checkpoint).
void partition_work(const Model& m, State& s);

}  // namespace rt
