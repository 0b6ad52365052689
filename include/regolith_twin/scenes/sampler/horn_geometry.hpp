// The sampler horn's inner volume, for counting grains per segment
// (docs/scenes.md B.1, B.3): the inner wall profile of urdf/sampler_horn.urdf
// as piecewise-linear points, the five segments' boundaries, the filter, and
// the horn's placement in the world.
#pragma once

#include <array>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

struct HornGeometry {
  // Inner wall profile: (z along the axis from the bottom aperture, inner radius), m, z increasing.
  std::vector<std::array<double, 2>> profile;
  std::array<double, 6> segment_z{};  // boundaries of cylinders 1..5 along the axis, m
  double filter_bottom = 0, filter_top = 0;  // z of the filter plates, m
  Vec3 origin = Vec3::Zero();   // centre of the bottom aperture, world, m
  Vec3 axis = Vec3::UnitZ();    // unit, upward along the horn

  // The shipped horn (scripts/make_horn.py; a test checks it against the URDF).
  static HornGeometry shipped();
  // Axial coordinate and distance from the axis of a world point, m.
  double axial(const Vec3& p) const { return (p - origin).dot(axis); }
  double radial(const Vec3& p) const { return ((p - origin) - axial(p) * axis).norm(); }
  double inner_radius(double z) const;  // at axial z (clamped to the profile), m
  double top() const { return segment_z[5]; }
  double top_radius() const { return profile.back()[1]; }
  // Segment 0..4 holding a world point (its centre inside the inner wall), -1 outside the horn.
  int segment_of(const Vec3& p) const;
};

}  // namespace rt
