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

// A graded fill (docs/scenes.md E.1, "Graded fills"): a grain's drawn radius is
// multiplied by scale(p), p its generated position. The generated heights are
// mapped to the settled bed's by z_bed = base + compaction (z - base); below
// the fine layer (depth under `surface` beyond fine_depth) and beyond the fine
// zone (horizontal distance from `center` beyond fine_radius) the mean
// diameter grows by depth_rate and radial_rate per metre of excess:
//   scale = min(max_scale, 1 + (depth_rate e_depth + radial_rate e_radial) / mean_diameter).
struct Grading {
  double surface = 0;        // z of the settled bed's surface, m
  double base = 0;           // z of the fill's floor: the height map's fixed point, m
  double compaction = 1;     // settled over generated height above `base`
  double center_x = 0, center_y = 0;  // the fine zone's vertical axis, m
  double fine_depth = 0;     // m below the surface
  double fine_radius = 0;    // m around the axis (no radial growth when radial_rate = 0)
  double depth_rate = 0;     // mean-diameter growth per metre of depth beyond the fine layer
  double radial_rate = 0;    // mean-diameter growth per metre of distance beyond the fine zone
  double max_scale = 1;      // largest radius factor
  double mean_diameter = 0;  // of the drawn (unscaled) distribution, m
  double scale(const Vec3& p) const;
};

// As above, with each grain's radius scaled by grading->scale at the place
// drawn for it (the whole scaled sphere inside the region); a place is kept
// with probability 1/scale^3, so that the solid fraction stays uniform where
// the grains grow. grading = nullptr is random_sites without grading (the
// same draws, the same sites).
RandomFill random_sites(const Region& r, const std::vector<double>& radii, double margin, double gap, int attempts,
                        std::mt19937_64& rng, const Grading* grading = nullptr);

// A random fill to a solid fraction instead of a count: radii are drawn one at
// a time from `dist` and placed as random_sites does (scaled by `grading` when
// given) until the grains' volume reaches `fraction` of the region's. Fewer
// grains (volume short of the target, reported by the caller) when one found
// no room in `attempts` draws.
RandomFill random_fraction(const Region& r, const RadiusDist& dist, double fraction, double margin, double gap,
                           int attempts, std::mt19937_64& rng, const Grading* grading = nullptr);

// The region's volume, m^3.
double region_volume(const Region& r);

}  // namespace rt
