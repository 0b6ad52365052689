// Contact history of a list (pair rows, grain–wall, grain–body): the
// tangential, rolling and twisting springs and the touching flag beside each
// entry. Helpers shared by the neighbour lists and grain edits.
#pragma once

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

}  // namespace rt
