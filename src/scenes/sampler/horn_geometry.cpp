// The sampler horn's inner volume (see horn_geometry.hpp).
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"

namespace rt {

HornGeometry HornGeometry::shipped() {
  // docs/scenes.md B.1: inner diameters (mm) at z (mm), bottom to top.
  HornGeometry h;
  const double mm = 1e-3;
  const double pts[][2] = {{0, 138.0},   {220, 126.0}, {440, 108.0}, {640, 86.0},
                           {770, 80.0},  {800, 55.5},  {860, 55.5},  {1007, 48.0}};
  for (const auto& q : pts) h.profile.push_back({q[0] * mm, 0.5 * q[1] * mm});
  h.segment_z = {0, 0.220, 0.440, 0.640, 0.860, 1.007};
  h.filter_bottom = 0.835;
  h.filter_top = 0.845;
  return h;
}

double HornGeometry::inner_radius(double z) const {
  if (z <= profile.front()[0]) return profile.front()[1];
  for (size_t k = 1; k < profile.size(); ++k)
    if (z <= profile[k][0]) {
      const double f = (z - profile[k - 1][0]) / (profile[k][0] - profile[k - 1][0]);
      return profile[k - 1][1] + f * (profile[k][1] - profile[k - 1][1]);
    }
  return profile.back()[1];
}

int HornGeometry::segment_of(const Vec3& p) const {
  const double z = axial(p);
  if (z < segment_z[0] || z >= segment_z[5]) return -1;
  if (radial(p) >= inner_radius(z)) return -1;
  for (int k = 0; k < 5; ++k)
    if (z < segment_z[k + 1]) return k;
  return -1;
}

}  // namespace rt
