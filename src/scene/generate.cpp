// Seeded grain generation.
#include "regolith_twin/scene/generate.hpp"

#include <cmath>

namespace rt {

std::vector<double> draw_radii(const RadiusDist& d, int n, std::mt19937_64& rng) {
  std::vector<double> r(n, d.mean);
  if (d.sigma <= 0) return r;
  std::normal_distribution<double> normal(0.0, 1.0);
  for (auto& x : r) {
    double z;
    do z = normal(rng);
    while (std::fabs(z) > d.cut);
    x = d.mean * (1 + d.sigma * z);
  }
  return r;
}

std::vector<Vec3> lattice_sites(const Region& r, double spacing, double margin, double jitter, int max_count,
                                std::mt19937_64& rng) {
  std::vector<Vec3> out;
  std::uniform_real_distribution<double> u(-jitter, jitter);
  const Vec3 lo = r.lo + Vec3::Constant(margin), hi = r.hi - Vec3::Constant(margin);
  const int nx = int(std::floor((hi.x() - lo.x()) / spacing)) + 1;
  const int ny = int(std::floor((hi.y() - lo.y()) / spacing)) + 1;
  const int nz = int(std::floor((hi.z() - lo.z()) / spacing)) + 1;
  if (hi.x() < lo.x() || hi.y() < lo.y() || hi.z() < lo.z()) return out;
  // Centre the lattice in x and y.
  const double ox = lo.x() + 0.5 * ((hi.x() - lo.x()) - (nx - 1) * spacing);
  const double oy = lo.y() + 0.5 * ((hi.y() - lo.y()) - (ny - 1) * spacing);
  const double limit = r.radius - margin;
  for (int k = 0; k < nz && int(out.size()) < max_count; ++k)
    for (int j = 0; j < ny && int(out.size()) < max_count; ++j)
      for (int i = 0; i < nx && int(out.size()) < max_count; ++i) {
        Vec3 p(ox + i * spacing, oy + j * spacing, lo.z() + k * spacing);
        if (r.shape == RegionShape::Cylinder) {
          const double dx = p.x() - r.center.x(), dy = p.y() - r.center.y();
          if (dx * dx + dy * dy > limit * limit) continue;
        }
        // Jitter keeps grains apart when jitter <= (spacing - 2 r_max) / 2.
        p.x() += u(rng);
        p.y() += u(rng);
        out.push_back(p);
      }
  return out;
}

}  // namespace rt
