// The grains of a sampler run that are not bed grains: the projectile and
// any grain added during the run (the second projectile), followed through
// removals (docs/scenes.md B.3). A handful at most: a linear search.
#pragma once

#include <vector>

namespace rt {

class NotBed {
 public:
  explicit NotBed(int projectile) {
    if (projectile >= 0) ids_.push_back(projectile);
  }
  bool operator()(int i) const {
    for (int j : ids_)
      if (j == i) return true;
    return false;
  }
  void added(int first, int n) {
    for (int i = first; i < n; ++i) ids_.push_back(i);
  }
  void removed(const std::vector<int>& old_to_new) {
    std::vector<int> kept;
    for (int j : ids_)
      if (j < int(old_to_new.size()) && old_to_new[j] >= 0) kept.push_back(old_to_new[j]);
    ids_ = kept;
  }

 private:
  std::vector<int> ids_;
};

}  // namespace rt
