// Contact history of a list (pair rows, grain–wall, grain–body): the
// tangential, rolling and twisting springs and the touching flag beside each
// entry. Helpers shared by the neighbour lists and grain edits.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Size the history arrays of list l to n entries.
template <class List>
void size_history(List& l, int n) {
  l.spring_t.resize(n);
  l.spring_r.resize(n);
  l.spring_w.resize(n);
  l.touching.resize(n);
}

// Entry `to` of list `dst` takes the history of entry `from` of `src`.
template <class List>
void copy_history(const List& src, int from, List& dst, int to) {
  dst.spring_t[to] = src.spring_t[from];
  dst.spring_r[to] = src.spring_r[from];
  dst.spring_w[to] = src.spring_w[from];
  dst.touching[to] = src.touching[from];
}

// Entry k starts without history.
template <class List>
void clear_history(List& l, int k) {
  l.spring_t[k].setZero();
  l.spring_r[k].setZero();
  l.spring_w[k] = 0;
  l.touching[k] = 0;
}

// The grain–body list also carries the slots of its mesh entries: both
// entries must already have their mesh_first (-1 for other shapes).
inline void copy_history(const BodyGrainList& src, int from, BodyGrainList& dst, int to) {
  copy_history<BodyGrainList>(src, from, dst, to);
  const int a = src.mesh_first[from], b = dst.mesh_first[to];
  if (a >= 0 && b >= 0)
    for (int q = 0; q < kMeshSlots; ++q) dst.mesh_slots[b + q] = src.mesh_slots[a + q];
}

inline void clear_history(BodyGrainList& l, int k) {
  clear_history<BodyGrainList>(l, k);
  if (const int a = l.mesh_first[k]; a >= 0)
    for (int q = 0; q < kMeshSlots; ++q) l.mesh_slots[a + q] = MeshSlot{};
}

}  // namespace rt
