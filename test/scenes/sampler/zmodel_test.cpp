// Maxwell's Z-model and its fit (scenes/sampler/zmodel.hpp): the velocity
// angle against the ejection angle, the fraction form and the streamlines;
// recovery of Z (and of the flow-centre height H₀) from synthetic fields made
// from the model with random angular noise per grain; grains too slow or
// outside the region left out.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "regolith_twin/scenes/sampler/zmodel.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;

struct Field {
  std::vector<Vec3> pos, vel;
};

// Grains spread uniformly over the toroidal region of `opt` (x, depth and
// azimuth uniform), each moving along the Z-model direction for a flow centre
// h0 above the impact point, turned by a random angle (normal, SD noise_deg)
// about a random axis normal to it; speeds 0.1 .. 1 m/s.
Field synthetic_field(double Z, double h0, int grains, double noise_deg, const rt::ZFitOptions& opt,
                      unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_deg * kDeg);
  const double depth_hi = opt.surface_only ? opt.depth_min + opt.cell : opt.depth_max;
  Field f;
  for (int k = 0; k < grains; ++k) {
    const double x = opt.x_min + (opt.x_max - opt.x_min) * unit(rng);
    const double depth = opt.depth_min + (depth_hi - opt.depth_min) * unit(rng);
    const double phi = 2 * kPi * unit(rng);
    const Vec3 p = opt.impact + Vec3(x * std::cos(phi), x * std::sin(phi), -depth);
    const Vec3 u = rt::zmodel_direction(Z, p, opt.impact, h0);
    const Vec3 n1 = u.unitOrthogonal(), n2 = u.cross(n1);
    const double psi = 2 * kPi * unit(rng);
    const Vec3 axis = n1 * std::cos(psi) + n2 * std::sin(psi);
    const Vec3 d = Eigen::AngleAxisd(noise(rng), axis) * u;
    f.pos.push_back(p);
    f.vel.push_back(d * (0.1 + 0.9 * unit(rng)));
  }
  return f;
}

rt::ZFitOptions default_options() {
  rt::ZFitOptions o;
  o.impact = Vec3(0.3, -0.2, 0.15);  // not the origin: the frame follows the impact point
  o.speed_min = 0.01;
  return o;
}

// 8 grains per cell on average over the default region (24 x 26 cells).
constexpr int kGrains = 8 * 24 * 26;
// With H₀ fitted too, Z's standard error is about 2.5 times larger (Z and H₀
// are correlated): 64 grains per cell keep 0.02 beyond four standard errors.
constexpr int kGrainsH0 = 64 * 24 * 26;
constexpr double kNoiseDeg = 5;

// Standard errors of (Z, H₀) of a least-squares fit over `cells` at (Z, h0)
// for a per-cell angle noise sigma (rad): sigma² (JᵀJ)⁻¹ with J the
// derivatives of the model angles, by central differences.
Eigen::Vector2d standard_errors(const std::vector<rt::ZCell>& cells, double Z, double h0, double sigma) {
  Eigen::MatrixXd J(cells.size(), 2);
  const double dz = 1e-5, dh = 1e-6;
  for (size_t k = 0; k < cells.size(); ++k) {
    const rt::ZCell& c = cells[k];
    auto angle = [&](double z, double h) {
      return rt::zmodel_velocity_angle(z, rt::zmodel_polar_angle(c.x, c.depth, h));
    };
    J(k, 0) = (angle(Z + dz, h0) - angle(Z - dz, h0)) / (2 * dz);
    J(k, 1) = (angle(Z, h0 + dh) - angle(Z, h0 - dh)) / (2 * dh);
  }
  const Eigen::Matrix2d cov = (J.transpose() * J).inverse() * sigma * sigma;
  return Eigen::Vector2d(std::sqrt(cov(0, 0)), std::sqrt(cov(1, 1)));
}

// Standard error of Z alone (H₀ held at h0): sigma / sqrt(sum (∂θ_v/∂Z)²).
double z_standard_error(const std::vector<rt::ZCell>& cells, double Z, double h0, double sigma) {
  double j2 = 0;
  for (const rt::ZCell& c : cells) {
    const double th = rt::zmodel_polar_angle(c.x, c.depth, h0);
    const double d = (rt::zmodel_velocity_angle(Z + 1e-5, th) - rt::zmodel_velocity_angle(Z - 1e-5, th)) / 2e-5;
    j2 += d * d;
  }
  return sigma / std::sqrt(j2);
}

TEST(ZModel, SurfaceAngleIsTheEjectionAngle) {
  for (double Z : {2.2, 2.5, 3.0, 3.5, 4.0, 5.0})
    EXPECT_NEAR(rt::zmodel_velocity_angle(Z, kPi / 2), std::atan(Z - 2), 1e-12) << "Z = " << Z;
  EXPECT_NEAR(rt::zmodel_velocity_angle(3.0, kPi / 2), kPi / 4, 1e-12);
}

TEST(ZModel, AngleMatchesTheFractionFormBelowTheSurface) {
  // atan{[(Z-2) sinθ - (Z-1) sinθ cosθ] / [1 + (Z-2) cosθ - (Z-1) cos²θ]}:
  // its denominator, (1 - cosθ)(1 + (Z-1) cosθ), is positive for 0 < θ <= π/2.
  for (double Z : {2.3, 3.0, 3.7, 5.5})
    for (double th = 0.01; th <= kPi / 2; th += 0.01) {
      const double s = std::sin(th), c = std::cos(th);
      const double expected = std::atan(((Z - 2) * s - (Z - 1) * s * c) / (1 + (Z - 2) * c - (Z - 1) * c * c));
      EXPECT_NEAR(rt::zmodel_velocity_angle(Z, th), expected, 1e-9) << "Z = " << Z << ", theta = " << th;
    }
  // Straight down on the axis; downward and outward just off it.
  EXPECT_NEAR(rt::zmodel_velocity_angle(3.0, 0.0), -kPi / 2, 1e-15);
  EXPECT_LT(rt::zmodel_velocity_angle(3.0, 0.2), -kPi / 4);
  EXPECT_GT(rt::zmodel_velocity_angle(3.0, 0.2), -kPi / 2);
}

TEST(ZModel, DirectionIsTangentToTheStreamlines) {
  // Points on r = R (1 - cosθ)^{1/(Z-2)} about a centre h0 above the impact
  // point, followed with θ increasing: the chord's direction between θ ± δ is
  // the model direction (also above the surface and for a centre below it).
  const Vec3 impact(0.1, 0.2, -0.05);
  const double az = 0.7;  // azimuth of the meridian plane
  const Vec3 radial(std::cos(az), std::sin(az), 0);
  for (double Z : {2.5, 3.0, 4.2})
    for (double h0 : {0.0, 0.01, -0.02})
      for (double th : {0.3, 0.8, 1.2, 1.5, 1.9}) {
        const double R = 0.07, dth = 1e-6;
        auto point = [&](double t) {
          const double r = rt::zmodel_streamline_radius(Z, R, t);
          return Vec3(impact + Vec3(0, 0, h0) + radial * (r * std::sin(t)) - Vec3(0, 0, r * std::cos(t)));
        };
        const Vec3 chord = (point(th + dth) - point(th - dth)).normalized();
        const Vec3 u = rt::zmodel_direction(Z, point(th), impact, h0);
        EXPECT_NEAR(u.norm(), 1.0, 1e-12);
        EXPECT_LT((u - chord).norm(), 1e-6) << "Z = " << Z << ", h0 = " << h0 << ", theta = " << th;
      }
}

TEST(ZModel, RecoversZFromNoisyFields) {
  const rt::ZFitOptions o = default_options();
  unsigned seed = 11;
  for (double Z : {2.5, 3.0, 3.5}) {
    const Field f = synthetic_field(Z, 0, kGrains, kNoiseDeg, o, seed++);
    const std::vector<rt::ZCell> cells = rt::zmodel_cells(f.pos, f.vel, o);
    const rt::ZFit fit = rt::fit_zmodel(cells, o);
    EXPECT_EQ(fit.cells, 24 * 26);
    EXPECT_EQ(fit.grains, kGrains);
    EXPECT_EQ(fit.h0, 0.0);
    EXPECT_NEAR(fit.z, Z, 0.02) << "Z = " << Z;
    // 0.02 is beyond four standard errors of the fit: a real recovery, not a wide margin.
    const double se = z_standard_error(cells, Z, 0, fit.misfit_sd_deg * kDeg);
    EXPECT_LT(4 * se, 0.02);
    // The residual is the cell-mean noise: about 5°/√2 in plane over 8 grains.
    EXPECT_LT(std::abs(fit.misfit_mean_deg), 0.3);
    EXPECT_LT(fit.misfit_sd_deg, 2.0);
    std::printf("Z = %.1f, H0 = 0 fixed: fitted Z = %.5f (error %+.5f, SE %.5f), misfit %.3f +- %.3f deg, %d cells\n",
                Z, fit.z, fit.z - Z, se, fit.misfit_mean_deg, fit.misfit_sd_deg, fit.cells);
    char name[32];
    std::snprintf(name, sizeof name, "z_error_%.1f", Z);
    RecordProperty(name, rt::test::figure(fit.z - Z));
  }
}

TEST(ZModel, RecoversZAndFlowCentreHeight) {
  // A flow centre 1 cm above the surface, 64 grains per cell. H₀ tolerance:
  // four standard errors of the least-squares fit, sigma² (JᵀJ)⁻¹ from the
  // model's derivatives over the cells used and the per-cell noise seen in
  // the residual (Z and H₀ are correlated: a higher centre steepens the
  // angles as a larger Z does). The cell-centre approximation alone (no
  // noise, 400 grains per cell) is off by about 1e-4 in Z and 5 µm in H₀,
  // far inside these tolerances.
  rt::ZFitOptions o = default_options();
  const double h0 = 0.01;
  unsigned seed = 21;
  for (double Z : {2.5, 3.0, 3.5}) {
    const Field f = synthetic_field(Z, h0, kGrainsH0, kNoiseDeg, o, seed++);
    const std::vector<rt::ZCell> cells = rt::zmodel_cells(f.pos, f.vel, o);
    o.fit_h0 = true;
    const rt::ZFit fit = rt::fit_zmodel(cells, o);
    o.fit_h0 = false;
    const rt::ZFit fixed = rt::fit_zmodel(cells, o);  // H₀ held at 0
    const Eigen::Vector2d se = standard_errors(cells, Z, h0, fit.misfit_sd_deg * kDeg);
    EXPECT_NEAR(fit.z, Z, 0.02) << "Z = " << Z;
    EXPECT_LT(4 * se(0), 0.02);
    EXPECT_NEAR(fit.h0, h0, 4 * se(1)) << "Z = " << Z;
    EXPECT_LT(4 * se(1), 1e-3);  // the tolerance resolves H₀ to better than half a cell
    EXPECT_LT(std::abs(fit.misfit_mean_deg), 0.3);
    // Holding the centre at the surface fits worse: a misfit beyond the noise.
    EXPECT_GT(fixed.misfit_rms_deg, 3 * fit.misfit_rms_deg) << "Z = " << Z;
    EXPECT_GT(std::abs(fixed.z - Z), 0.02);
    std::printf(
        "Z = %.1f, H0 = 10 mm fitted: Z = %.5f (error %+.5f, SE %.5f), H0 = %.3f mm (error %+.3f mm, SE %.3f mm), "
        "misfit %.3f +- %.3f deg (RMS %.3f); H0 fixed at 0: Z = %.4f, misfit %.3f +- %.3f deg (RMS %.3f)\n",
        Z, fit.z, fit.z - Z, se(0), fit.h0 * 1e3, (fit.h0 - h0) * 1e3, se(1) * 1e3, fit.misfit_mean_deg,
        fit.misfit_sd_deg, fit.misfit_rms_deg, fixed.z, fixed.misfit_mean_deg, fixed.misfit_sd_deg,
        fixed.misfit_rms_deg);
    char name[32];
    std::snprintf(name, sizeof name, "z_error_%.1f", Z);
    RecordProperty(name, rt::test::figure(fit.z - Z));
    std::snprintf(name, sizeof name, "h0_error_%.1f", Z);
    RecordProperty(name, rt::test::figure(fit.h0 - h0));
  }
}

TEST(ZModel, FitWithFreeCentreFindsZeroHeightWhenThereIsNone) {
  rt::ZFitOptions o = default_options();
  const Field f = synthetic_field(3.0, 0, kGrainsH0, kNoiseDeg, o, 31);
  const std::vector<rt::ZCell> cells = rt::zmodel_cells(f.pos, f.vel, o);
  o.fit_h0 = true;
  const rt::ZFit fit = rt::fit_zmodel(cells, o);
  const Eigen::Vector2d se = standard_errors(cells, 3.0, 0, fit.misfit_sd_deg * kDeg);
  EXPECT_NEAR(fit.z, 3.0, 0.02);
  EXPECT_NEAR(fit.h0, 0.0, 4 * se(1));
  std::printf("Z = 3, H0 = 0 fitted: Z = %.5f (error %+.5f, SE %.5f), H0 = %.3f mm (SE %.3f mm)\n", fit.z,
              fit.z - 3.0, se(0), fit.h0 * 1e3, se(1) * 1e3);
}

TEST(ZModel, SurfaceOnlyUsesTheTopLayer) {
  rt::ZFitOptions o = default_options();
  o.surface_only = true;
  // 24 cells only, all near θ = π/2 where the angle is atan(Z - 2): more
  // grains per cell (40) for a comparable precision.
  const Field f = synthetic_field(3.0, 0, 40 * 24, kNoiseDeg, o, 41);
  // Deeper grains pointing straight up are left out.
  rt::ZFitOptions deep = default_options();
  deep.depth_min = o.cell;
  Field g = synthetic_field(3.0, 0, 2000, 0, deep, 42);
  for (Vec3& v : g.vel) v = Vec3(0, 0, 0.5);
  Field all = f;
  all.pos.insert(all.pos.end(), g.pos.begin(), g.pos.end());
  all.vel.insert(all.vel.end(), g.vel.begin(), g.vel.end());
  const std::vector<rt::ZCell> cells = rt::zmodel_cells(all.pos, all.vel, o);
  ASSERT_EQ(cells.size(), 24u);
  for (const rt::ZCell& c : cells) EXPECT_NEAR(c.depth, o.cell / 2, 1e-15);
  const rt::ZFit fit = rt::fit_zmodel(cells, o);
  const double se_z = z_standard_error(cells, 3.0, 0, fit.misfit_sd_deg * kDeg);
  EXPECT_NEAR(fit.z, 3.0, 0.02);
  EXPECT_LT(4 * se_z, 0.02);
  std::printf("surface only, Z = 3: fitted Z = %.5f (error %+.5f, SE %.5f), %d cells, misfit %.3f +- %.3f deg\n",
              fit.z, fit.z - 3.0, se_z, fit.cells, fit.misfit_mean_deg, fit.misfit_sd_deg);
}

TEST(ZModel, SlowGrainsAreLeftOut) {
  const rt::ZFitOptions o = default_options();
  const Field f = synthetic_field(3.0, 0, kGrains, kNoiseDeg, o, 51);
  const rt::ZFit base = rt::fit_zmodel(f.pos, f.vel, o);
  // The same number of grains again, all pointing straight up, at or below speed_min.
  Field slow = synthetic_field(3.0, 0, kGrains, 0, o, 52);
  for (size_t k = 0; k < slow.vel.size(); ++k) slow.vel[k] = Vec3(0, 0, k % 2 ? o.speed_min : 0.5 * o.speed_min);
  Field all = f;
  all.pos.insert(all.pos.end(), slow.pos.begin(), slow.pos.end());
  all.vel.insert(all.vel.end(), slow.vel.begin(), slow.vel.end());
  const rt::ZFit with_slow = rt::fit_zmodel(all.pos, all.vel, o);
  EXPECT_EQ(with_slow.z, base.z);
  EXPECT_EQ(with_slow.misfit_sd_deg, base.misfit_sd_deg);
  EXPECT_EQ(with_slow.cells, base.cells);
  EXPECT_EQ(with_slow.grains, base.grains);
  // They would spoil the fit if counted.
  rt::ZFitOptions keep_all = o;
  keep_all.speed_min = 0;
  const rt::ZFit counted = rt::fit_zmodel(all.pos, all.vel, keep_all);
  EXPECT_EQ(counted.grains, 2 * kGrains);
  EXPECT_GT(counted.misfit_rms_deg, 5 * base.misfit_rms_deg);
}

TEST(ZModel, GrainsOutsideTheRegionAreLeftOut) {
  const rt::ZFitOptions o = default_options();
  const Field f = synthetic_field(3.0, 0, kGrains, kNoiseDeg, o, 61);
  const std::vector<rt::ZCell> base = rt::zmodel_cells(f.pos, f.vel, o);
  // Fast grains pointing straight up just outside each edge, and above the surface.
  Field all = f;
  for (int k = 0; k < 400; ++k) {
    const double phi = 0.1 * k, s = 0.001 * (k % 7);
    const Vec3 e(std::cos(phi), std::sin(phi), 0);
    const Vec3 rel[] = {e * (o.x_min - 1e-6 - s) - Vec3(0, 0, 0.01), e * (o.x_max + 1e-6 + s) - Vec3(0, 0, 0.01),
                        e * 0.06 - Vec3(0, 0, o.depth_max + 1e-6 + s), e * 0.06 + Vec3(0, 0, 1e-6 + s), e * 0.02};
    for (const Vec3& r : rel) {
      all.pos.push_back(o.impact + r);
      all.vel.push_back(Vec3(0, 0, 1));
    }
  }
  const std::vector<rt::ZCell> cells = rt::zmodel_cells(all.pos, all.vel, o);
  ASSERT_EQ(cells.size(), base.size());
  for (size_t k = 0; k < cells.size(); ++k) {
    EXPECT_EQ(cells[k].angle, base[k].angle);
    EXPECT_EQ(cells[k].grains, base[k].grains);
  }
  EXPECT_EQ(rt::fit_zmodel(all.pos, all.vel, o).z, rt::fit_zmodel(f.pos, f.vel, o).z);
  // A smaller region keeps only its own cells, centred inside it (the last
  // x cell cut by the edge at 5.9 cm).
  rt::ZFitOptions small = o;
  small.x_min = 0.05;
  small.x_max = 0.059;
  small.depth_min = 0.01;
  small.depth_max = 0.02;
  const std::vector<rt::ZCell> sc = rt::zmodel_cells(all.pos, all.vel, small);
  ASSERT_EQ(sc.size(), 4u * 4u);
  int n = 0;
  for (const rt::ZCell& c : sc) {
    EXPECT_GT(c.x, small.x_min);
    EXPECT_LT(c.x, small.x_max);
    EXPECT_GT(c.depth, small.depth_min);
    EXPECT_LT(c.depth, small.depth_max);
    n += c.grains;
  }
  EXPECT_NEAR(sc[3].x, (0.0575 + 0.059) / 2, 1e-12);
  int inside = 0;
  for (size_t k = 0; k < f.pos.size(); ++k) {
    const Vec3 d = f.pos[k] - o.impact;
    const double x = std::hypot(d.x(), d.y());
    inside += x >= small.x_min && x < small.x_max && -d.z() >= small.depth_min && -d.z() < small.depth_max;
  }
  EXPECT_EQ(n, inside);
}

TEST(ZModel, NoCellsAndBadOptions) {
  rt::ZFitOptions o = default_options();
  const rt::ZFit none = rt::fit_zmodel(std::vector<Vec3>{}, std::vector<Vec3>{}, o);
  EXPECT_EQ(none.cells, 0);
  EXPECT_TRUE(std::isnan(none.z));
  EXPECT_THROW(rt::fit_zmodel(std::vector<Vec3>(2), std::vector<Vec3>(1), o), rt::InputError);
  rt::ZFitOptions bad = o;
  bad.x_max = bad.x_min;
  EXPECT_THROW(rt::zmodel_cells({}, {}, bad), rt::InputError);
  bad = o;
  bad.z_min = 2;
  EXPECT_THROW(rt::zmodel_cells({}, {}, bad), rt::InputError);
  bad = o;
  bad.fit_h0 = true;
  bad.h0_min = bad.h0_max = 0;
  EXPECT_THROW(rt::fit_zmodel(std::vector<rt::ZCell>{}, bad), rt::InputError);
}

}  // namespace
