// Editing the grains of a scene between steps: removing grains (trimming a
// bed, making room for a body) and adding one (a projectile). Survivors keep
// their kinematics and every contact they keep keeps its springs: the pair,
// grain–wall and grain–body lists are renumbered in place (still sorted, so
// the next list build carries their history over), every per-grain array of
// the Model and the State follows the new numbering, and the lists,
// partitions, pair constants and forces are rebuilt by the next step.
#pragma once

#include <cstdint>
#include <vector>

#include "regolith_twin/core/state.hpp"

namespace rt {

// Remove the grains i with drop[i] != 0 (drop has n_grains entries); the
// others keep their order. Contacts of removed grains go with them. If
// old_to_new is given it receives, for every old grain, its new index or -1.
// Returns the number removed (0: nothing changed).
int remove_grains(Model& m, State& s, const std::vector<uint8_t>& drop, std::vector<int>* old_to_new = nullptr);

// Append one free grain of the given radius and material index with its
// kinematics (omega in rad/s); its mass follows as in finalize_model. Every
// other grain and contact is untouched. Returns the new grain's index.
// Throws InputError for a radius <= 0 or an unknown material.
int add_grain(Model& m, State& s, double radius, int material, const Vec3& pos, const Vec3& vel, const Vec3& omega);

// Rotate every grain about the vertical axis through the origin by `angle`
// (rad), with its velocities, forces and springs (a bed turned for a
// perturbed repeat of a run).
void rotate_grains_about_z(const Model& m, State& s, double angle);

// Renumber a per-grain array after remove_grains: v[old_to_new[i]] = v[i]
// for every kept i (old_to_new[i] <= i, so in place), then shrink.
template <class T>
void renumber_grains(std::vector<T>& v, const std::vector<int>& old_to_new) {
  size_t kept = 0;
  for (size_t i = 0; i < old_to_new.size() && i < v.size(); ++i)
    if (old_to_new[i] >= 0) {
      v[old_to_new[i]] = v[i];
      ++kept;
    }
  v.resize(kept);
}

}  // namespace rt
