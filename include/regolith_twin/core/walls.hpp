// Geometry of grain contact with analytic walls (docs/model.md §5): for a sphere
// of centre p and radius r, the unit normal from the grain towards the wall
// and the overlap (negative when apart).
#pragma once

#include "regolith_twin/core/model.hpp"

namespace rt {

struct WallGap {
  Vec3 n;          // unit normal from the grain centre towards the wall
  double overlap;  // r - distance to the surface (> 0: touching), m
};

// Closest-approach geometry of a sphere with a wall.
WallGap wall_gap(const Wall& w, const Vec3& p, double r);

// Unit-length helpers used when building walls from user input.
Wall make_plane(const Vec3& point, const Vec3& normal, int material);
Wall make_cylinder(const Vec3& base, const Vec3& axis, double radius, double length, bool inner,
                   int material);

}  // namespace rt
