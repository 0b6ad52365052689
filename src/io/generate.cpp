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

double Grading::scale(const Vec3& p) const {
  const double z_bed = base + compaction * (p.z() - base);
  const double e_depth = std::max(0.0, surface - z_bed - fine_depth);
  const double e_radial = std::max(0.0, std::hypot(p.x() - center_x, p.y() - center_y) - fine_radius);
  return std::min(max_scale, 1 + (depth_rate * e_depth + radial_rate * e_radial) / mean_diameter);
}

double region_volume(const Region& r) {
  const Vec3 size = r.hi - r.lo;
  return r.shape == RegionShape::Cylinder ? kPi * r.radius * r.radius * size.z() : size.x() * size.y() * size.z();
}

namespace {

// Random sequential addition on a cell grid of cells 2 r_max + gap wide.
class Rsa {
 public:
  Rsa(const Region& r, double r_max, double margin, double gap, const Grading* grading)
      : r_(r), margin_(margin), gap_(gap), grading_(grading), reach_(2 * r_max + gap) {
    for (int a = 0; a < 3; ++a) dim_[a] = std::max(1, int(std::ceil((r.hi[a] - r.lo[a]) / reach_)));
    head_.assign(size_t(long(dim_[0]) * dim_[1] * dim_[2]), -1);
  }

  // False when the region has no room for a grain of drawn radius ri at all.
  bool room(double ri) const {
    const double keep = ri + margin_;
    return r_.hi.z() - r_.lo.z() > 2 * keep &&
           (r_.shape == RegionShape::Cylinder ? r_.radius > keep : (r_.hi - r_.lo).head<2>().minCoeff() > 2 * keep);
  }

  // Up to `attempts` uniform draws for a grain of drawn radius ri; its radius
  // is ri, or ri scaled at the drawn place when graded. The placed radius, or 0.
  double place(double ri, int attempts, std::mt19937_64& rng) {
    const double keep = ri + margin_;  // distance from every side
    for (int t = 0; t < attempts;) {
      Vec3 p;
      if (r_.shape == RegionShape::Cylinder) {
        const double rad = r_.radius - keep;
        // Uniform over the disk: radius from the square root.
        const double s = rad * std::sqrt(u01_(rng)), phi = 2 * kPi * u01_(rng);
        p = Vec3(r_.center.x() + s * std::cos(phi), r_.center.y() + s * std::sin(phi), 0);
      } else {
        p.x() = r_.lo.x() + keep + (r_.hi.x() - r_.lo.x() - 2 * keep) * u01_(rng);
        p.y() = r_.lo.y() + keep + (r_.hi.y() - r_.lo.y() - 2 * keep) * u01_(rng);
      }
      p.z() = r_.lo.z() + keep + (r_.hi.z() - r_.lo.z() - 2 * keep) * u01_(rng);
      const double scale = grading_ ? grading_->scale(p) : 1.0;
      // Graded: a place is kept with probability 1/scale^3 (not counted as an attempt), so that the
      // grains' number density falls as their volume grows and the solid fraction stays uniform.
      if (scale > 1 && u01_(rng) * scale * scale * scale > 1) continue;
      ++t;
      const double rp = ri * scale;
      if (grading_ && !inside(p, rp + margin_)) continue;
      int c[3];
      cell_of(p, c);
      if (!clear(p, rp, c)) continue;
      const size_t cell = size_t((long(c[2]) * dim_[1] + c[1]) * dim_[0] + c[0]);
      next_.push_back(head_[cell]);
      head_[cell] = int(out_.sites.size());
      out_.sites.push_back(p);
      out_.radii.push_back(rp);
      return rp;
    }
    return 0;
  }

  // The sites bottom-up in layers, then by y and x: neighbours stay close in memory.
  RandomFill sorted() const {
    std::vector<size_t> order(out_.sites.size());
    std::iota(order.begin(), order.end(), size_t(0));
    auto key = [&](size_t i) {
      int c[3];
      cell_of(out_.sites[i], c);
      return std::make_tuple(c[2], c[1], out_.sites[i].x(), i);
    };
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
    RandomFill s;
    for (const size_t i : order) {
      s.sites.push_back(out_.sites[i]);
      s.radii.push_back(out_.radii[i]);
    }
    return s;
  }

 private:
  void cell_of(const Vec3& p, int c[3]) const {
    for (int a = 0; a < 3; ++a) c[a] = std::min(dim_[a] - 1, std::max(0, int((p[a] - r_.lo[a]) / reach_)));
  }

  // The whole sphere of radius `keep` around p inside the region.
  bool inside(const Vec3& p, double keep) const {
    if (p.z() - keep < r_.lo.z() || p.z() + keep > r_.hi.z()) return false;
    if (r_.shape == RegionShape::Cylinder)
      return std::hypot(p.x() - r_.center.x(), p.y() - r_.center.y()) + keep <= r_.radius;
    return p.x() - keep >= r_.lo.x() && p.x() + keep <= r_.hi.x() && p.y() - keep >= r_.lo.y() &&
           p.y() + keep <= r_.hi.y();
  }

  bool clear(const Vec3& p, double rp, const int c[3]) const {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
          if (x < 0 || y < 0 || z < 0 || x >= dim_[0] || y >= dim_[1] || z >= dim_[2]) continue;
          for (int k = head_[size_t((long(z) * dim_[1] + y) * dim_[0] + x)]; k >= 0; k = next_[size_t(k)]) {
            const double need = rp + out_.radii[size_t(k)] + gap_;
            if ((out_.sites[size_t(k)] - p).squaredNorm() < need * need) return false;
          }
        }
    return true;
  }

  const Region& r_;
  double margin_, gap_;
  const Grading* grading_;
  double reach_;  // no two centres of a cell's neighbourhood closer than this go unchecked
  int dim_[3];
  std::vector<int> head_, next_;
  RandomFill out_;
  std::uniform_real_distribution<double> u01_{0.0, 1.0};
};

}  // namespace

RandomFill random_sites(const Region& r, const std::vector<double>& radii, double margin, double gap, int attempts,
                        std::mt19937_64& rng, const Grading* grading) {
  if (radii.empty()) return RandomFill();
  const double r_max = *std::max_element(radii.begin(), radii.end()) * (grading ? grading->max_scale : 1.0);
  Rsa rsa(r, r_max, margin, gap, grading);
  for (const double ri : radii)
    if (!rsa.room(ri) || rsa.place(ri, attempts, rng) == 0) break;
  return rsa.sorted();
}

RandomFill random_fraction(const Region& r, const RadiusDist& dist, double fraction, double margin, double gap,
                           int attempts, std::mt19937_64& rng, const Grading* grading) {
  const double target = fraction * region_volume(r);
  Rsa rsa(r, dist.max() * (grading ? grading->max_scale : 1.0), margin, gap, grading);
  double volume = 0;
  while (volume < target) {
    const double ri = draw_radii(dist, 1, rng)[0];
    if (!rsa.room(ri)) break;
    const double rp = rsa.place(ri, attempts, rng);
    if (rp == 0) break;
    volume += 4.0 / 3.0 * kPi * rp * rp * rp;
  }
  return rsa.sorted();
}

}  // namespace rt
