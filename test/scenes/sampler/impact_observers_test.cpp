// Impact measurements of the sampler shot (docs/scenes.md B.4) against hand
// values: the impact clock's step for a projectile closing a known gap on a
// grain (either index order, after a removal renumbered it), a wall and a
// body; ejection angles, speeds, launch positions, histogram, mean and median
// of grains given known velocities; the wave profile and slope of a speed
// field made from a known power law (with faster grains outside the cone and
// behind the projectile, and a quiet bin in the range); and Z-model fits of a
// field made from the model with a known Z, slow grains left out.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <unistd.h>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;

rt::Material grain_material() {
  rt::Material g = rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5);
  return g;
}

std::string temp_path() {
  char path[] = "/tmp/impact_observers_XXXXXX";
  const int fd = mkstemp(path);
  if (fd >= 0) close(fd);
  return path;
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(f, l);) out.push_back(l);
  return out;
}

// --- a projectile closing a gap --------------------------------------------------

// Free flight at speed v (no gravity) over a gap of 10.5 v dt: the first
// overlap is at step 11.
constexpr double kV = 2.0, kDt = 1e-6, kGap = 10.5 * kV * kDt;
constexpr double kRP = 4e-3, kRB = 2.5e-3;

struct Shot {
  rt::Model m;
  rt::State s;
};

// Grains: `far` grains far away first, then the target and the projectile
// in the given order; the projectile falls on the target along -z.
Shot grain_shot(bool projectile_first, int far) {
  Shot k;
  k.m.materials.push_back(grain_material());
  k.m.gravity.setZero();
  for (int q = 0; q < far; ++q) rt::add_grain(k.m, kRB, 0);
  const int a = rt::add_grain(k.m, projectile_first ? kRP : kRB, 0);
  const int b = rt::add_grain(k.m, projectile_first ? kRB : kRP, 0);
  k.m.kn = 1e5;
  k.m.dt = kDt;
  rt::finalize_model(k.m);
  k.s = rt::make_state(k.m);
  for (int q = 0; q < far; ++q) k.s.pos[q] = Vec3(1 + 0.1 * q, 0, 0);
  const int p = projectile_first ? a : b, t = projectile_first ? b : a;
  k.s.pos[t] = Vec3::Zero();
  k.s.pos[p] = Vec3(0, 0, kRB + kRP + kGap);
  k.s.vel[p] = Vec3(0, 0, -kV);
  return k;
}

// Steps until the clock sees the impact; returns the step.
long run_to_impact(Shot& k, rt::ImpactClock& c) {
  for (int n = 0; n < 40 && !c.hit(); ++n) {
    rt::step(k.m, k.s);
    c.after_step(k.m, k.s);
  }
  return c.impact_step();
}

}  // namespace

TEST(ImpactClock, FirstGrainContactWhicheverIndexHoldsTheRow) {
  for (bool first : {true, false}) {
    Shot k = grain_shot(first, 0);
    const int p = first ? 0 : 1;
    rt::ImpactClock c(p);
    rt::prime(k.m, k.s);
    c.start(k.m, k.s);
    EXPECT_FALSE(c.hit());
    EXPECT_TRUE(std::isnan(c.t_impact()));
    EXPECT_EQ(run_to_impact(k, c), 11) << "projectile first: " << first;
    EXPECT_NEAR(c.t_impact(), 11 * kDt, 1e-15);
    // The velocity at the end of that step: the first half of the contact's kick slowed it a little.
    EXPECT_GT(c.impact_velocity().z(), -kV);
    EXPECT_LT(c.impact_velocity().z(), -0.99 * kV);
    EXPECT_NEAR(c.impact_position().z(), kRB + kRP + kGap - 11 * kV * kDt, 1e-12);
    EXPECT_NEAR(c.after(k.s), 0.0, 0.0);
    rt::step(k.m, k.s);
    c.after_step(k.m, k.s);
    EXPECT_EQ(c.impact_step(), 11);  // kept
    EXPECT_NEAR(c.after(k.s), kDt, 1e-15);
  }
}

TEST(ImpactClock, FollowsTheProjectileThroughARemoval) {
  Shot k = grain_shot(false, 3);  // far grains 0-2, target 3, projectile 4
  rt::ImpactClock c(4);
  rt::prime(k.m, k.s);
  c.start(k.m, k.s);
  for (int n = 0; n < 5; ++n) {
    rt::step(k.m, k.s);
    c.after_step(k.m, k.s);
  }
  std::vector<uint8_t> drop(k.m.n_grains, 0);
  drop[0] = drop[2] = 1;
  std::vector<int> old_to_new;
  ASSERT_EQ(rt::remove_grains(k.m, k.s, drop, &old_to_new), 2);
  c.grains_removed(old_to_new);
  EXPECT_EQ(c.projectile(), 2);
  EXPECT_FALSE(c.hit());
  EXPECT_EQ(run_to_impact(k, c), 11);
}

TEST(ImpactClock, WallAndBodyContactsCount) {
  // A plane wall under the projectile.
  {
    Shot k;
    k.m.materials.push_back(grain_material());
    k.m.gravity.setZero();
    k.m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 0));
    rt::add_grain(k.m, kRP, 0);
    k.m.kn = 1e5;
    k.m.dt = kDt;
    rt::finalize_model(k.m);
    k.s = rt::make_state(k.m);
    k.s.pos[0] = Vec3(0, 0, kRP + kGap);
    k.s.vel[0] = Vec3(0, 0, -kV);
    rt::ImpactClock c(0);
    rt::prime(k.m, k.s);
    c.start(k.m, k.s);
    EXPECT_EQ(run_to_impact(k, c), 11);
  }
  // A fixed sphere body under the projectile.
  {
    Shot k;
    k.m.materials.push_back(grain_material());
    k.m.gravity.setZero();
    rt::BodyModel b;
    b.name = "rock";
    b.mass = 1;
    b.inertia = Vec3::Constant(1e-3);
    b.fixed = true;
    rt::Shape sh;
    sh.type = rt::ShapeType::Sphere;
    sh.size = Vec3::Constant(0.01);
    b.shapes.push_back(sh);
    k.m.bodies.push_back(b);
    rt::add_grain(k.m, kRP, 0);
    k.m.kn = 1e5;
    k.m.dt = kDt;
    rt::finalize_model(k.m);
    k.s = rt::make_state(k.m);
    k.s.bodies[0].pos = Vec3::Zero();
    k.s.pos[0] = Vec3(0, 0, 0.01 + kRP + kGap);
    k.s.vel[0] = Vec3(0, 0, -kV);
    rt::ImpactClock c(0);
    rt::prime(k.m, k.s);
    c.start(k.m, k.s);
    EXPECT_EQ(run_to_impact(k, c), 11);
    rt::JsonObject j;
    c.summary(j);
    EXPECT_NE(j.dump().find("\"impact\": true"), std::string::npos);
  }
}

namespace {

// --- synthetic states ----------------------------------------------------------------

// Bed grains at given positions (radius r each, at rest, no gravity) and the
// projectile last, touching a plane wall far above (z = 10, grains below it):
// one step makes the clock see the impact (t_impact = dt, step 1) and leaves
// the bed where it was.
struct Synthetic {
  rt::Model m;
  rt::State s;
  int p = 0;
};

Synthetic synthetic(const std::vector<Vec3>& bed, double r) {
  Synthetic y;
  y.m.materials.push_back(grain_material());
  y.m.gravity.setZero();
  y.m.walls.push_back(rt::make_plane(Vec3(0, 0, 10), -Vec3::UnitZ(), 0));
  for (size_t q = 0; q < bed.size(); ++q) rt::add_grain(y.m, r, 0);
  y.p = rt::add_grain(y.m, kRP, 0);
  y.m.kn = 1e5;
  y.m.dt = kDt;
  rt::finalize_model(y.m);
  y.s = rt::make_state(y.m);
  for (size_t q = 0; q < bed.size(); ++q) y.s.pos[q] = bed[q];
  y.s.pos[y.p] = Vec3(5, 5, 10 - kRP + 1e-6);
  rt::prime(y.m, y.s);
  return y;
}

// One step, then every observer (the clock first) sees it.
void impact_step(Synthetic& y, const std::vector<rt::Observer*>& obs) {
  rt::step(y.m, y.s);
  for (rt::Observer* o : obs) o->after_step(y.m, y.s);
}

void at(Synthetic& y, long step, double after_impact, const std::vector<rt::Observer*>& obs) {
  y.s.step = step;
  y.s.ticks = double(step);
  y.s.time = kDt + after_impact;
  for (rt::Observer* o : obs) o->after_step(y.m, y.s);
}

Vec3 launch_velocity(double speed, double angle_deg, double azimuth) {
  return speed * Vec3(std::cos(angle_deg * kDeg) * std::cos(azimuth), std::cos(angle_deg * kDeg) * std::sin(azimuth),
                      std::sin(angle_deg * kDeg));
}

}  // namespace

// Ten bed grains 1 cm below h_s = 0; grain 5 starts above it and never
// counts. Launches are recorded only on sampled steps (every 5 from the
// impact step), once per grain, with the velocity's angle from the
// horizontal; a removal between two samples renumbers the flags.
TEST(EjectionAngles, AnglesSpeedsAndPositionsOfKnownLaunches) {
  const double r = 1e-3, R = 0.15, g = 1.19e-4;
  const Vec3 axis(0.01, 0.02, 0);
  std::vector<Vec3> bed;
  for (int q = 0; q < 10; ++q) bed.push_back(Vec3(0.01 * q, 0, -0.01));
  bed[5].z() = 0.002;
  Synthetic y = synthetic(bed, r);
  rt::ImpactClock c(y.p);
  rt::EjectionAngles ej(&c, 0.0, axis, R, g, 5);
  const std::vector<rt::Observer*> obs{&c, &ej};
  for (rt::Observer* o : obs) o->start(y.m, y.s);
  impact_step(y, obs);
  ASSERT_TRUE(c.hit());
  ASSERT_EQ(c.impact_step(), 1);
  EXPECT_EQ(ej.count(), 0);

  // Grain 0 rises at 33 deg, 0.03 m from the axis; step 3 is not sampled.
  y.s.pos[0] = axis + Vec3(0.03, 0, 0.001);
  y.s.vel[0] = launch_velocity(2.0, 33, 0.7);
  y.s.pos[1] = axis + Vec3(0, -0.06, 0.0005);
  y.s.vel[1] = launch_velocity(0.5, 10, 2.0);
  at(y, 3, 2e-6, obs);
  EXPECT_EQ(ej.count(), 0);
  at(y, 6, 5e-6, obs);
  ASSERT_EQ(ej.count(), 2);
  const rt::EjectaLaunch& l0 = ej.launches()[0];
  EXPECT_EQ(l0.grain, 0);
  EXPECT_NEAR(l0.t, 5e-6, 1e-15);
  EXPECT_NEAR(l0.angle_deg, 33, 1e-9);
  EXPECT_NEAR(l0.speed, 2.0, 1e-12);
  EXPECT_NEAR(l0.r, 0.03, 1e-12);
  EXPECT_NEAR(ej.launches()[1].angle_deg, 10, 1e-9);
  EXPECT_NEAR(ej.launches()[1].r, 0.06, 1e-12);

  // Grain 2 leaves the run: grains 3.. move down by one, the projectile too.
  std::vector<uint8_t> drop(y.m.n_grains, 0);
  drop[2] = 1;
  std::vector<int> old_to_new;
  ASSERT_EQ(rt::remove_grains(y.m, y.s, drop, &old_to_new), 1);
  for (rt::Observer* o : obs) o->grains_removed(old_to_new);
  ASSERT_EQ(c.projectile(), 9);
  // Old grains 3, 4, 6, 7 (now 2, 3, 5, 6) rise at 45, 80, 90 and -20 deg;
  // old grain 5 (now 4) is still above, grains 0 and 1 too.
  const double angles[] = {45, 80, 90, -20};
  const int now[] = {2, 3, 5, 6};
  for (int q = 0; q < 4; ++q) {
    y.s.pos[now[q]].z() = 0.001;
    y.s.vel[now[q]] = launch_velocity(1.0, angles[q], 0.3 * q);
  }
  at(y, 7, 6e-6, obs);  // not sampled
  EXPECT_EQ(ej.count(), 2);
  at(y, 11, 1e-5, obs);
  ASSERT_EQ(ej.count(), 6);
  EXPECT_EQ(ej.launches()[2].grain, 2);
  EXPECT_NEAR(ej.launches()[2].t, 1e-5, 1e-15);
  EXPECT_NEAR(ej.launches()[4].angle_deg, 90, 1e-9);
  EXPECT_NEAR(ej.launches()[5].angle_deg, -20, 1e-9);
  EXPECT_NEAR(ej.mean_angle_deg(), (33 + 10 + 45 + 80 + 90 - 20) / 6.0, 1e-9);
  EXPECT_NEAR(ej.median_angle_deg(), (33 + 45) / 2.0, 1e-9);
  std::vector<long> h(15, 0);
  h[1] = h[5] = h[7] = h[13] = h[14] = 1;
  EXPECT_EQ(ej.histogram(), h);
  EXPECT_EQ(ej.outside(), 1);
  const double vol = 6 * 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(ej.volume(), vol, 1e-20);
  std::vector<double> row;
  ej.row(y.m, y.s, row);
  ASSERT_EQ(row.size(), 2u);
  EXPECT_EQ(row[0], 6.0);
  EXPECT_NEAR(row[1], vol, 1e-20);
  at(y, 16, 1.5e-5, obs);
  EXPECT_EQ(ej.count(), 6);

  const std::string path = temp_path();
  ej.write_csv(path);
  const std::vector<std::string> lines = lines_of(path);
  std::remove(path.c_str());
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[0], "t,x_launch,r_launch_over_R,speed,speed_over_sqrt_gR,angle");
  double t, x, xr, v, vr, a;
  ASSERT_EQ(std::sscanf(lines[1].c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", &t, &x, &xr, &v, &vr, &a), 6);
  EXPECT_NEAR(xr, 0.2, 1e-9);
  EXPECT_NEAR(vr, 2.0 / std::sqrt(g * R), 1e-6);
  EXPECT_NEAR(a, 33, 1e-7);
}

// Grains on rays from the impact point at the middle distances of 2.5 mm
// bins: 30 deg from the downward vertical (speed A d^-n) and straight down
// (half that); grains 70 deg from the vertical (outside the 60 deg cone) at
// 100 m/s; bins 0-2 (behind the projectile, whose far side is at 7 mm) at
// 50 m/s; bin 9 and bins 13-15 below the noise floor (10 x 1e-5 m/s). The fit
// uses bins 3-8 and 10-12 and returns -n.
TEST(WaveAttenuation, MaxSpeedProfileAndPowerLawSlope) {
  const double bin = 2.5e-3;
  const Vec3 impact(0.02, -0.01, 0.0);
  const int bins = 16;
  std::vector<Vec3> bed;
  const Vec3 ray30(std::sin(30 * kDeg), 0, -std::cos(30 * kDeg)), down(0, 0, -1),
      ray70(0, std::sin(70 * kDeg), -std::cos(70 * kDeg));
  for (int k = 0; k < bins; ++k) {
    const double d = (k + 0.5) * bin;
    bed.push_back(impact + d * ray30);
    bed.push_back(impact + d * down);
    bed.push_back(impact + d * ray70);
  }
  bed.push_back(impact + Vec3(0, 0, 0.01));  // above the surface
  Synthetic y = synthetic(bed, 2e-4);
  rt::ImpactClock c(y.p);
  rt::WaveOptions o;
  o.impact = impact;
  o.times = {3e-5, 1e-5};  // sorted by the observer
  o.rest_rms = 1e-5;
  rt::WaveAttenuation wave(&c, o);
  const std::vector<rt::Observer*> obs{&c, &wave};
  for (rt::Observer* q : obs) q->start(y.m, y.s);
  impact_step(y, obs);
  ASSERT_TRUE(c.hit());
  y.s.pos[y.p] = impact + Vec3(0, 0, -3e-3);  // far side 7 mm from the impact point

  auto field = [&](double A, double n) {
    for (int k = 0; k < bins; ++k) {
      const double d = (k + 0.5) * bin;
      double v = k < 3 ? 50 : A * std::pow(d, -n);
      if (k == 9 || k >= 13) v = 5e-5;
      y.s.vel[3 * k] = v * Vec3(0.6, 0, -0.8);
      y.s.vel[3 * k + 1] = 0.5 * v * Vec3(0, 0, -1);
      y.s.vel[3 * k + 2] = Vec3(100, 0, 0);
    }
    y.s.vel[3 * bins] = Vec3(0, 0, 200);
  };
  field(1e-3, 1.7);
  at(y, 5, 0.99e-5, obs);
  EXPECT_TRUE(wave.profiles().empty());
  at(y, 6, 1.01e-5, obs);
  ASSERT_EQ(wave.profiles().size(), 1u);
  field(2e-4, 2.5);
  at(y, 20, 3e-5, obs);
  ASSERT_EQ(wave.profiles().size(), 2u);
  at(y, 30, 5e-5, obs);
  EXPECT_EQ(wave.profiles().size(), 2u);

  const double ns[] = {1.7, 2.5}, As[] = {1e-3, 2e-4};
  for (int q = 0; q < 2; ++q) {
    const rt::WaveProfile& w = wave.profiles()[q];
    EXPECT_NEAR(w.t, q ? 3e-5 : 1e-5, 1e-18);
    EXPECT_NEAR(w.t_actual, q ? 3e-5 : 1.01e-5, 1e-15);
    EXPECT_NEAR(w.contact, 7e-3, 1e-12);
    EXPECT_NEAR(w.floor, 1e-4, 1e-18);
    ASSERT_EQ(w.max_speed.size(), size_t(bins));
    for (int k = 0; k < bins; ++k) EXPECT_EQ(w.grains[k], 2) << k;
    EXPECT_EQ(w.max_speed[0], 50.0);
    EXPECT_NEAR(w.max_speed[4], As[q] * std::pow(4.5 * bin, -ns[q]), 1e-12 * w.max_speed[4]);
    EXPECT_EQ(w.first_bin, 3);
    EXPECT_EQ(w.last_bin, 12);
    EXPECT_FALSE(w.front_found);  // an exact power law: no precursor, the front is the last bin above the floor
    EXPECT_EQ(w.front_bin, 12);
    EXPECT_TRUE(w.precursor.empty());
    EXPECT_EQ(w.used, (std::vector<int>{3, 4, 5, 6, 7, 8, 10, 11, 12}));
    EXPECT_NEAR(w.slope, -ns[q], 1e-10);
    EXPECT_NEAR(w.intercept, std::log(As[q]), 1e-9);
  }
  const std::string path = temp_path();
  wave.write_csv(path);
  const std::vector<std::string> lines = lines_of(path);
  std::remove(path.c_str());
  ASSERT_EQ(lines.size(), 1u + 2 * bins);
  EXPECT_EQ(lines[0], "t,bin,distance_from,distance_to,distance_mid,max_speed,grains,in_fit,precursor");
  EXPECT_EQ(lines[4].substr(lines[4].size() - 4), ",1,0");   // bin 3
  EXPECT_EQ(lines[10].substr(lines[10].size() - 4), ",0,0");  // bin 9
}

// One grain at the centre of every 2.5 mm cell of the default region (4-10 cm
// from the axis, 0-6.5 cm deep), each at its own azimuth, moving along the
// Z-model direction of a known Z; a slow grain opposite each moving the other
// way. The rest RMS speed (1e-5 m/s) is measured at start(), so grains at
// 5e-5 m/s are below the threshold of 1e-4 m/s. The fits recover Z (and
// H₀ = 0) with no misfit.
TEST(ZModelSampler, RecoversZOfASyntheticField) {
  rt::ZFitOptions base;
  base.impact = Vec3(0.01, -0.02, 0.05);
  const int nx = 24, nd = 26;
  std::vector<Vec3> bed;
  for (int j = 0; j < nd; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = base.x_min + (i + 0.5) * base.cell, depth = (j + 0.5) * base.cell, phi = 0.37 * (j * nx + i);
      bed.push_back(base.impact + Vec3(x * std::cos(phi), x * std::sin(phi), -depth));
      bed.push_back(base.impact + Vec3(-x * std::cos(phi), -x * std::sin(phi), -depth));
    }
  Synthetic y = synthetic(bed, 3e-4);
  for (size_t q = 0; q < bed.size(); ++q) y.s.vel[q] = Vec3(0, 1e-5, 0);
  rt::ImpactClock c(y.p);
  rt::ZModelSampler zs(&c, base, -1, {45e-6, 1.25e-3});
  const std::vector<rt::Observer*> obs{&c, &zs};
  for (rt::Observer* q : obs) q->start(y.m, y.s);
  EXPECT_NEAR(zs.rest_rms(), 1e-5, 1e-16);
  for (size_t q = 0; q < bed.size(); ++q) y.s.vel[q].setZero();
  impact_step(y, obs);
  ASSERT_TRUE(c.hit());

  auto field = [&](double Z) {
    for (size_t q = 0; q < bed.size(); q += 2) {
      const Vec3 u = rt::zmodel_direction(Z, y.s.pos[q], base.impact, 0.0);
      y.s.vel[q] = 0.05 * u;
      y.s.vel[q + 1] = -5e-5 * rt::zmodel_direction(Z, y.s.pos[q + 1], base.impact, 0.0);
    }
  };
  field(3.0);
  at(y, 10, 40e-6, obs);
  EXPECT_TRUE(zs.samples().empty());
  at(y, 11, 46e-6, obs);
  ASSERT_EQ(zs.samples().size(), 1u);
  field(2.5);
  at(y, 100, 1.3e-3, obs);
  ASSERT_EQ(zs.samples().size(), 2u);

  const double Zs[] = {3.0, 2.5};
  for (int q = 0; q < 2; ++q) {
    const rt::ZSample& z = zs.samples()[q];
    EXPECT_NEAR(z.speed_min, 1e-4, 1e-15);
    EXPECT_NEAR(z.fixed_h0.z, Zs[q], 1e-4);
    EXPECT_EQ(z.fixed_h0.cells, nx * nd);
    EXPECT_EQ(z.fixed_h0.grains, nx * nd);
    EXPECT_LT(z.fixed_h0.misfit_rms_deg, 1e-3);
    EXPECT_EQ(z.fixed_h0.h0, 0.0);
    EXPECT_NEAR(z.fitted_h0.z, Zs[q], 1e-3);
    EXPECT_NEAR(z.fitted_h0.h0, 0.0, 1e-5);
    EXPECT_NEAR(z.surface.z, Zs[q], 1e-4);
    EXPECT_EQ(z.surface.cells, nx);
  }
  EXPECT_NEAR(zs.samples()[1].t_actual, 1.3e-3, 1e-15);
  const std::string path = temp_path();
  zs.write_csv(path);
  const std::vector<std::string> lines = lines_of(path);
  std::remove(path.c_str());
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[0], "t,variant,z,h0,misfit_mean_deg,misfit_sd_deg,misfit_rms_deg,cells,grains,speed_min");
  EXPECT_NE(lines[2].find(",fitted_h0,"), std::string::npos);
  EXPECT_NE(lines[6].find(",surface,2.5"), std::string::npos) << lines[6];
}
