// Crater depth and radius, and the packing below the filter (see crater.hpp,
// packing_below_filter.hpp; docs/scenes.md B.3).
#include "regolith_twin/scenes/sampler/crater.hpp"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>

#include "regolith_twin/scenes/sampler/packing_below_filter.hpp"

namespace rt {
namespace {


// Area of the intersection of a disk of radius a whose centre is at distance
// d from the origin with the disk of radius R about the origin.
double lens_area(double a, double d, double R) {
  if (R <= 0 || a <= 0) return 0;
  if (d >= a + R) return 0;
  if (d <= std::abs(R - a)) return kPi * std::min(a, R) * std::min(a, R);
  const double ca = std::clamp((d * d + a * a - R * R) / (2 * d * a), -1.0, 1.0);
  const double cR = std::clamp((d * d + R * R - a * a) / (2 * d * R), -1.0, 1.0);
  const double k = (-d + a + R) * (d + a - R) * (d - a + R) * (d + a + R);
  return a * a * std::acos(ca) + R * R * std::acos(cR) - 0.5 * std::sqrt(std::max(0.0, k));
}

// 24-point Gauss-Legendre nodes and weights on [-1, 1] (positive half).
const double kX[12] = {0.0640568928626056, 0.1911188674736163, 0.3150426796961634, 0.4337935076260451,
                       0.5454214713888396, 0.6480936519369755, 0.7401241915785544, 0.8200019859739029,
                       0.8864155270044011, 0.9382745520027328, 0.9747285559713095, 0.9951872199970213};
const double kW[12] = {0.1279381953467522, 0.1258374563468283, 0.1216704729278034, 0.1155056680537256,
                       0.1074442701159656, 0.0976186521041139, 0.0861901615319533, 0.0733464814110803,
                       0.0592985849154368, 0.0442774388174198, 0.0285313886289337, 0.0123412297999872};

}  // namespace

double sphere_cell_volume(const Vec3& c, double r, double z0, double z1, double r_in, double r_out,
                          const Vec3& axis_point) {
  const double lo = std::max(z0, c.z() - r), hi = std::min(z1, c.z() + r);
  if (hi <= lo || r_out <= r_in) return 0;
  const double d = std::hypot(c.x() - axis_point.x(), c.y() - axis_point.y());
  if (d - r >= r_out || d + r <= r_in) return 0;
  const double mid = 0.5 * (hi + lo), half = 0.5 * (hi - lo);
  double v = 0;
  for (int k = 0; k < 12; ++k)
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      const double z = mid + sgn * half * kX[k];
      const double a2 = r * r - (z - c.z()) * (z - c.z());
      if (a2 <= 0) continue;
      const double a = std::sqrt(a2);
      v += kW[k] * (lens_area(a, d, r_out) - lens_area(a, d, r_in));
    }
  return v * half;
}

Crater::Crater(const Vec3& impact, int projectile, int every, double threshold, double column_radius, double layer,
               double max_depth, double ring_depth, double max_radius)
    : impact_(impact),
      not_bed_(projectile),
      every_(every),
      threshold_(threshold),
      col_r_(column_radius),
      layer_(layer),
      max_depth_(max_depth),
      ring_depth_(ring_depth),
      max_radius_(max_radius) {}

void Crater::profiles(const Model& m, const State& s, std::vector<double>& col, std::vector<double>& ring) const {
  const int nl = int(std::lround(max_depth_ / layer_)), nr = int(std::lround(max_radius_ / layer_));
  col.assign(nl, 0.0);
  ring.assign(nr, 0.0);
  const double top = impact_.z(), ring_lo = top - ring_depth_;
  for (int i = 0; i < m.n_grains; ++i) {
    if (not_bed_(i) || held(m, i)) continue;
    const Vec3& p = s.pos[i];
    const double r = m.grain_radius[i];
    if (p.z() - r >= top || p.z() + r <= top - max_depth_) continue;
    const double d = std::hypot(p.x() - impact_.x(), p.y() - impact_.y());
    if (d - r < col_r_) {  // column layers
      const int k0 = std::max(0, int(std::floor((top - (p.z() + r)) / layer_)));
      const int k1 = std::min(nl - 1, int(std::floor((top - (p.z() - r)) / layer_)));
      for (int k = k0; k <= k1; ++k)
        col[k] += sphere_cell_volume(p, r, top - (k + 1) * layer_, top - k * layer_, 0, col_r_, impact_);
    }
    if (p.z() + r > ring_lo && p.z() - r < top && d - r < max_radius_) {  // rings of the top layer
      const int j0 = std::max(0, int(std::floor((d - r) / layer_)));
      const int j1 = std::min(nr - 1, int(std::floor((d + r) / layer_)));
      for (int j = j0; j <= j1; ++j)
        ring[j] += sphere_cell_volume(p, r, ring_lo, top, j * layer_, (j + 1) * layer_, impact_);
    }
  }
  for (double& v : col) v /= kPi * col_r_ * col_r_ * layer_;
  for (int j = 0; j < nr; ++j) ring[j] /= kPi * ((j + 1) * (j + 1) - j * j) * layer_ * layer_ * ring_depth_;
}

void Crater::start(const Model& m, const State& s) {
  profiles(m, s, col0_, ring0_);
  col_ = col0_;
  ring_ = ring0_;
  measure(m, s);
}

bool Crater::after_step(const Model& m, const State& s) {
  if (ticks_crossed(s, every_)) measure(m, s);
  return false;
}

void Crater::measure(const Model& m, const State& s) {
  profiles(m, s, col_, ring_);
  auto edge = [&](const std::vector<double>& now, const std::vector<double>& before) {
    for (size_t k = 0; k < now.size(); ++k)
      if (before[k] > 0.1 && now[k] >= threshold_ * before[k]) return double(k) * layer_;
    return double(now.size()) * layer_;
  };
  depth_ = edge(col_, col0_);
  radius_ = edge(ring_, ring0_);
}

void Crater::grains_removed(const std::vector<int>& old_to_new) {
  not_bed_.removed(old_to_new);
}

void Crater::columns(std::vector<std::string>& out) const {
  out.push_back("crater_depth");
  out.push_back("crater_radius");
}

void Crater::row(const Model& m, const State& s, std::vector<double>& out) const {
  out.push_back(depth_);
  out.push_back(radius_);
}

void Crater::summary(JsonObject& out) const {
  auto mean = [](const std::vector<double>& v, size_t n) {
    double a = 0;
    n = std::min(n, v.size());
    for (size_t k = 0; k < n; ++k) a += v[k];
    return n ? a / n : 0.0;
  };
  JsonObject c;
  c.num("depth", depth_).num("radius", radius_).num("threshold", threshold_);
  c.num("column_radius", col_r_).num("layer", layer_).num("ring_depth", ring_depth_);
  c.num("initial_column_solid_fraction", mean(col0_, col0_.size()));
  c.num("initial_ring_solid_fraction", mean(ring0_, size_t(std::lround(0.1 / layer_))));
  out.obj("crater", c);
}

// --- packing below the filter ----------------------------------------------------------------

std::vector<double> PackingBelowFilter::profile(const Model& m, const State& s) const {
  std::vector<double> v(n_, 0.0);
  const double fb = g_.filter_bottom, lo = fb - n_ * slice_;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    const double z = g_.axial(s.pos[i]), r = m.grain_radius[i];
    if (z + r <= lo || z - r >= fb) continue;
    const Vec3 ph = Vec3(s.pos[i].x() - g_.origin.x(), s.pos[i].y() - g_.origin.y(), z);
    const int k0 = std::max(0, int(std::floor((fb - (z + r)) / slice_)));
    const int k1 = std::min(n_ - 1, int(std::floor((fb - (z - r)) / slice_)));
    for (int k = k0; k <= k1; ++k) {
      const double z1 = fb - k * slice_, z0 = z1 - slice_;
      v[k] += sphere_cell_volume(ph, r, z0, z1, 0, g_.inner_radius(0.5 * (z0 + z1)), Vec3::Zero());
    }
  }
  for (int k = 0; k < n_; ++k) {
    const double R = g_.inner_radius(g_.filter_bottom - (k + 0.5) * slice_);
    v[k] /= kPi * R * R * slice_;
  }
  return v;
}

void PackingBelowFilter::summary(JsonObject& out) const {
  JsonObject p;
  double mx = 0;
  for (double x : prof_) mx = std::max(mx, x);
  p.num("max_solid_fraction", mx).num("slice", slice_).nums("profile", prof_);
  out.obj("packing_below_filter", p);
}

}  // namespace rt
