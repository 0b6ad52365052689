// Grain generation: truncated Gaussian radii, loose lattice fills and random
// (non-overlapping, uniformly placed) fills of a box or a cylinder, all driven
// by an explicit seed.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

struct RadiusDist {
  double mean = 0.005;  // m
  double sigma = 0;     // standard deviation as a fraction of the mean
  double cut = 1.0;     // truncation at +- cut * sigma
  double max() const { return mean * (1 + sigma * cut); }
};

// Draw n radii (rejection sampling of the truncated normal).
std::vector<double> draw_radii(const RadiusDist& d, int n, std::mt19937_64& rng);

enum class RegionShape { Box, Cylinder };

struct Region {
  RegionShape shape = RegionShape::Box;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // box corners; cylinder: z range from lo.z() to hi.z()
  Vec3 center = Vec3::Zero();                 // cylinder axis point (axis along z)
  double radius = 0;                          // cylinder radius
};

// Sites of a simple cubic lattice of the given spacing inside the region
// (keeping a margin of `margin` from its sides), each jittered in x and y by a
// uniform +-jitter, in z-major order (bottom layer first). Returns at most
// max_count sites.
std::vector<Vec3> lattice_sites(const Region& r, double spacing, double margin, double jitter, int max_count,
                                std::mt19937_64& rng);

// Random sequential addition: each grain of `radii`, in order, is put at a
// position uniform over the region (its whole sphere inside, with `margin`
// more from the sides) that keeps it at least `gap` from every grain placed
// before; up to `attempts` draws per grain. Returns the sites sorted
// bottom-up in layers of 2 r_max, then by y and x (neighbours stay close in
// memory), with the radii permuted alongside; fewer sites than radii when a
// grain found no room (the region is too full).
struct RandomFill {
  std::vector<Vec3> sites;
  std::vector<double> radii;
};
RandomFill random_sites(const Region& r, const std::vector<double>& radii, double margin, double gap, int attempts,
                        std::mt19937_64& rng);

}  // namespace rt
