// Maxwell's Z-model and its fit to a measured velocity field
// (definitions in include/regolith_twin/scenes/sampler/zmodel.hpp).
#include "regolith_twin/scenes/sampler/zmodel.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace rt {

namespace {

constexpr double kDeg = 180.0 / kPi;

double wrap_angle(double a) {
  while (a > kPi) a -= 2 * kPi;
  while (a <= -kPi) a += 2 * kPi;
  return a;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError("Z-model fit: " + what);
}

void check_options(const ZFitOptions& o) {
  require(std::isfinite(o.cell) && o.cell > 0, "cell must be > 0");
  require(std::isfinite(o.x_min) && std::isfinite(o.x_max) && o.x_min >= 0 && o.x_max > o.x_min,
          "need 0 <= x_min < x_max");
  require(std::isfinite(o.depth_min) && std::isfinite(o.depth_max) && o.depth_max > o.depth_min,
          "need depth_min < depth_max");
  require(std::isfinite(o.speed_min) && o.speed_min >= 0, "speed_min must be >= 0");
  require(o.min_grains >= 1, "min_grains must be >= 1");
  require(o.z_min > 2 && o.z_max > o.z_min && std::isfinite(o.z_max), "need 2 < z_min < z_max");
  require(o.z_steps >= 3 && o.z_tol > 0, "need z_steps >= 3 and z_tol > 0");
  require(std::isfinite(o.h0), "h0 must be finite");
  if (o.fit_h0) {
    require(std::isfinite(o.h0_min) && std::isfinite(o.h0_max) && o.h0_max > o.h0_min, "need h0_min < h0_max");
    require(o.h0_steps >= 3 && o.h0_tol > 0, "need h0_steps >= 3 and h0_tol > 0");
  }
}

// Number of cells of side `cell` covering [lo, hi) (the last may be cut).
int cell_count(double lo, double hi, double cell) {
  return std::max(1, static_cast<int>(std::ceil((hi - lo) / cell - 1e-9)));
}

// Minimum of f over [lo, hi]: a scan of `steps` points, then golden-section
// search between the neighbours of the best scan point. Returns (x, f(x)).
template <class F>
std::pair<double, double> minimise_1d(F&& f, double lo, double hi, int steps, double tol) {
  const double h = (hi - lo) / (steps - 1);
  int best = 0;
  double f_best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < steps; ++k) {
    const double v = f(lo + k * h);
    if (v < f_best) {
      f_best = v;
      best = k;
    }
  }
  double x_best = lo + best * h;
  double a = lo + std::max(best - 1, 0) * h;
  double b = lo + std::min(best + 1, steps - 1) * h;
  const double g = (std::sqrt(5.0) - 1) / 2;  // 0.618...
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  while (b - a > tol) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  const double x_end = fc < fd ? c : d;
  const double f_end = std::min(fc, fd);
  if (f_end < f_best) {
    x_best = x_end;
    f_best = f_end;
  }
  return {x_best, f_best};
}

}  // namespace

double zmodel_velocity_angle(double Z, double theta) {
  const double s = std::sin(theta), c = std::cos(theta);
  const double vx = s * (1 + (Z - 1) * c);
  const double vz = (1 + c) * ((Z - 2) - (Z - 1) * c);
  return std::atan2(vz, vx);
}

double zmodel_polar_angle(double x, double depth, double h0) { return std::atan2(x, h0 + depth); }

double zmodel_streamline_radius(double Z, double R, double theta) {
  return R * std::pow(1 - std::cos(theta), 1 / (Z - 2));
}

Vec3 zmodel_direction(double Z, const Vec3& p, const Vec3& impact, double h0) {
  const Vec3 d = p - impact;
  const double x = std::hypot(d.x(), d.y());
  if (x == 0) return Vec3(0, 0, -1);
  const double a = zmodel_velocity_angle(Z, zmodel_polar_angle(x, -d.z(), h0));
  const Vec3 radial(d.x() / x, d.y() / x, 0);
  return radial * std::cos(a) + Vec3(0, 0, std::sin(a));
}

std::vector<ZCell> zmodel_cells(const std::vector<Vec3>& pos, const std::vector<Vec3>& vel,
                                const ZFitOptions& opt) {
  check_options(opt);
  require(pos.size() == vel.size(), "positions and velocities differ in number");
  const double depth_hi = opt.surface_only ? std::min(opt.depth_max, opt.depth_min + opt.cell) : opt.depth_max;
  const int nx = cell_count(opt.x_min, opt.x_max, opt.cell);
  const int nd = cell_count(opt.depth_min, depth_hi, opt.cell);
  std::vector<double> sum_x(static_cast<size_t>(nx) * nd, 0.0), sum_z(sum_x.size(), 0.0);
  std::vector<int> count(sum_x.size(), 0);
  for (size_t k = 0; k < pos.size(); ++k) {
    const Vec3& v = vel[k];
    const double speed = v.norm();
    if (!(speed > opt.speed_min) || !std::isfinite(speed)) continue;
    const Vec3 d = pos[k] - opt.impact;
    const double x = std::hypot(d.x(), d.y());
    const double depth = -d.z();
    if (!(x >= opt.x_min && x < opt.x_max && depth >= opt.depth_min && depth < depth_hi)) continue;
    const int i = std::min(nx - 1, static_cast<int>(std::floor((x - opt.x_min) / opt.cell)));
    const int j = std::min(nd - 1, static_cast<int>(std::floor((depth - opt.depth_min) / opt.cell)));
    const Vec3 u = v / speed;
    const double radial = x > 0 ? (u.x() * d.x() + u.y() * d.y()) / x : 0.0;
    const size_t c = static_cast<size_t>(j) * nx + i;
    sum_x[c] += radial;
    sum_z[c] += u.z();
    ++count[c];
  }
  std::vector<ZCell> cells;
  for (int j = 0; j < nd; ++j)
    for (int i = 0; i < nx; ++i) {
      const size_t c = static_cast<size_t>(j) * nx + i;
      if (count[c] < opt.min_grains || (sum_x[c] == 0 && sum_z[c] == 0)) continue;
      ZCell z;
      const double x0 = opt.x_min + i * opt.cell, d0 = opt.depth_min + j * opt.cell;
      z.x = (x0 + std::min(x0 + opt.cell, opt.x_max)) / 2;
      z.depth = (d0 + std::min(d0 + opt.cell, depth_hi)) / 2;
      z.angle = std::atan2(sum_z[c], sum_x[c]);
      z.grains = count[c];
      cells.push_back(z);
    }
  return cells;
}

double zmodel_rms(const std::vector<ZCell>& cells, double Z, double h0) {
  if (cells.empty()) return std::numeric_limits<double>::quiet_NaN();
  double s2 = 0;
  for (const ZCell& c : cells) {
    const double e = wrap_angle(c.angle - zmodel_velocity_angle(Z, zmodel_polar_angle(c.x, c.depth, h0)));
    s2 += e * e;
  }
  return std::sqrt(s2 / cells.size());
}

ZFit fit_zmodel(const std::vector<ZCell>& cells, const ZFitOptions& opt) {
  check_options(opt);
  ZFit fit;
  fit.h0 = opt.h0;
  fit.cells = static_cast<int>(cells.size());
  for (const ZCell& c : cells) fit.grains += c.grains;
  if (cells.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    fit.z = fit.misfit_mean_deg = fit.misfit_sd_deg = fit.misfit_rms_deg = nan;
    return fit;
  }
  auto best_z = [&](double h0) {
    return minimise_1d([&](double z) { return zmodel_rms(cells, z, h0); }, opt.z_min, opt.z_max, opt.z_steps,
                       opt.z_tol);
  };
  if (opt.fit_h0) {
    fit.h0 = minimise_1d([&](double h0) { return best_z(h0).second; }, opt.h0_min, opt.h0_max, opt.h0_steps,
                         opt.h0_tol)
                 .first;
  }
  fit.z = best_z(fit.h0).first;
  std::vector<double> e(cells.size());
  double sum = 0, sum2 = 0;
  for (size_t k = 0; k < cells.size(); ++k) {
    const ZCell& c = cells[k];
    e[k] = wrap_angle(c.angle - zmodel_velocity_angle(fit.z, zmodel_polar_angle(c.x, c.depth, fit.h0))) * kDeg;
    sum += e[k];
    sum2 += e[k] * e[k];
  }
  const double n = static_cast<double>(cells.size());
  fit.misfit_mean_deg = sum / n;
  fit.misfit_rms_deg = std::sqrt(sum2 / n);
  double dev2 = 0;
  for (double ek : e) dev2 += (ek - fit.misfit_mean_deg) * (ek - fit.misfit_mean_deg);
  fit.misfit_sd_deg = std::sqrt(dev2 / n);
  return fit;
}

ZFit fit_zmodel(const std::vector<Vec3>& pos, const std::vector<Vec3>& vel, const ZFitOptions& opt) {
  return fit_zmodel(zmodel_cells(pos, vel, opt), opt);
}

}  // namespace rt
