// Seeded grain generation.
#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

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

RandomFill random_sites(const Region& r, const std::vector<double>& radii, double margin, double gap, int attempts,
                        std::mt19937_64& rng) {
  RandomFill out;
  if (radii.empty()) return out;
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const double reach = 2 * r_max + gap;  // no two centres of a cell's neighbourhood closer than this go unchecked
  const Vec3 lo = r.lo, hi = r.hi;
  int dim[3];
  for (int a = 0; a < 3; ++a) dim[a] = std::max(1, int(std::ceil((hi[a] - lo[a]) / reach)));
  const long n_cells = long(dim[0]) * dim[1] * dim[2];
  std::vector<int> head(size_t(n_cells), -1), next;
  auto cell_of = [&](const Vec3& p, int c[3]) {
    for (int a = 0; a < 3; ++a) c[a] = std::min(dim[a] - 1, std::max(0, int((p[a] - lo[a]) / reach)));
  };
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const double ri : radii) {
    const double keep = ri + margin;  // distance from every side
    const bool room = hi.z() - lo.z() > 2 * keep &&
                      (r.shape == RegionShape::Cylinder ? r.radius > keep : (hi - lo).head<2>().minCoeff() > 2 * keep);
    if (!room) break;
    bool placed = false;
    for (int t = 0; t < attempts && !placed; ++t) {
      Vec3 p;
      if (r.shape == RegionShape::Cylinder) {
        const double rad = r.radius - keep;
        // Uniform over the disk: radius from the square root.
        const double s = rad * std::sqrt(u01(rng)), phi = 2 * kPi * u01(rng);
        p = Vec3(r.center.x() + s * std::cos(phi), r.center.y() + s * std::sin(phi), 0);
      } else {
        p.x() = lo.x() + keep + (hi.x() - lo.x() - 2 * keep) * u01(rng);
        p.y() = lo.y() + keep + (hi.y() - lo.y() - 2 * keep) * u01(rng);
      }
      p.z() = lo.z() + keep + (hi.z() - lo.z() - 2 * keep) * u01(rng);
      int c[3];
      cell_of(p, c);
      bool clear = true;
      for (int dz = -1; dz <= 1 && clear; ++dz)
        for (int dy = -1; dy <= 1 && clear; ++dy)
          for (int dx = -1; dx <= 1 && clear; ++dx) {
            const int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
            if (x < 0 || y < 0 || z < 0 || x >= dim[0] || y >= dim[1] || z >= dim[2]) continue;
            for (int k = head[size_t((long(z) * dim[1] + y) * dim[0] + x)]; k >= 0; k = next[size_t(k)]) {
              const double need = ri + out.radii[size_t(k)] + gap;
              if ((out.sites[size_t(k)] - p).squaredNorm() < need * need) {
                clear = false;
                break;
              }
            }
          }
      if (!clear) continue;
      const size_t cell = size_t((long(c[2]) * dim[1] + c[1]) * dim[0] + c[0]);
      next.push_back(head[cell]);
      head[cell] = int(out.sites.size());
      out.sites.push_back(p);
      out.radii.push_back(ri);
      placed = true;
    }
    if (!placed) break;
  }
  // Bottom-up in layers, then by y and x: neighbours stay close in memory.
  std::vector<size_t> order(out.sites.size());
  std::iota(order.begin(), order.end(), size_t(0));
  auto key = [&](size_t i) {
    int c[3];
    cell_of(out.sites[i], c);
    return std::make_tuple(c[2], c[1], out.sites[i].x(), i);
  };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
  RandomFill sorted;
  for (const size_t i : order) {
    sorted.sites.push_back(out.sites[i]);
    sorted.radii.push_back(out.radii[i]);
  }
  return sorted;
}

}  // namespace rt
