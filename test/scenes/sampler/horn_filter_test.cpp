// The horn's filter (docs/scenes.md B.1): four plates across the neck of
// cylinder 4 leave slots of 9.5 mm. Single grains are fired up at the filter
// of the shipped URDF from below, with the shot's contact law and step: a
// grain larger than 1 cm never gets its centre past the plates, from any
// start across the neck, at any speed and tilt tried; a 0.9 cm grain aimed
// along a slot passes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"
#include "horn_alone.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
constexpr double kPi = 3.14159265358979323846;

// The horn alone with one grain of radius r (the probe, placed per start).
rt::Scenario filter_scene(double r) { return rt::test::horn_alone(r, Vec3(0, 0, 0.5)); }

struct Shot {
  bool passed = false;   // centre above the plates' top by a radius
  double highest = -1;   // highest centre reached, axial m
  double widest = 0;     // largest distance from the axis, m
};

// Fire grain 0 from p0 with velocity v0 until it has passed the filter,
// come back 2 mm below its start, or 20 ms have gone by.
Shot fire(const rt::Scenario& sc, const rt::HornGeometry& g, const Vec3& p0, const Vec3& v0) {
  rt::Model m = sc.model;
  rt::State s = sc.initial;
  s.pos[0] = p0;
  s.vel[0] = v0;
  const double r = m.grain_radius[0];
  Shot out;
  const long steps = std::lround(0.02 / m.dt);
  for (long k = 0; k < steps; ++k) {
    rt::step(m, s);
    const double z = g.axial(s.pos[0]);
    out.highest = std::max(out.highest, z);
    out.widest = std::max(out.widest, g.radial(s.pos[0]));
    if (z > g.filter_top + r) {
      out.passed = true;
      break;
    }
    if (z < p0.z() - 0.002 && s.vel[0].z() < 0) break;
  }
  return out;
}

// Uniform in [0, 1), the same on every platform.
double uniform(uint64_t& state) {
  state = state * 6364136223846793005ULL + 1442695040888963407ULL;
  return double(state >> 11) * (1.0 / 9007199254740992.0);
}

class HornFilter : public ::testing::TestWithParam<double> {};

// Starts on a 2 mm grid over the neck below the plates, each fired at 2 or
// 4 m/s up to 20 degrees off the axis in a random direction.
TEST_P(HornFilter, GrainsOfOneCentimetreAndMoreNeverPass) {
  const double r = GetParam();
  const rt::Scenario sc = filter_scene(r);
  const rt::HornGeometry g = rt::HornGeometry::shipped();
  const double neck = g.inner_radius(0.5 * (g.filter_bottom + g.filter_top));
  const double z0 = g.filter_bottom - r - 0.001;
  ASSERT_NEAR(g.inner_radius(z0), neck, 1e-9) << "the starts lie in the straight neck";
  uint64_t rng = 17;
  int starts = 0, reached = 0;
  double highest = -1;
  for (double x = -neck; x <= neck; x += 0.002)
    for (double y = -neck; y <= neck; y += 0.002) {
      if (std::hypot(x, y) > neck - r - 2e-4) continue;
      const double speed = (starts % 2) ? 4.0 : 2.0;
      const double tilt = 20 * kPi / 180 * uniform(rng), az = 2 * kPi * uniform(rng);
      const Vec3 v = speed * Vec3(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az), std::cos(tilt));
      const Shot shot = fire(sc, g, Vec3(x, y, z0), v);
      ++starts;
      EXPECT_FALSE(shot.passed) << "a " << 2e3 * r << " mm grain passed the filter from (" << x << ", " << y << ")";
      EXPECT_LT(shot.widest, neck) << "the grain left through the neck wall";
      if (shot.highest > g.filter_bottom - r) ++reached;
      highest = std::max(highest, shot.highest);
    }
  EXPECT_GT(starts, 300);
  EXPECT_GT(reached, starts / 2) << "most grains should reach the plates";
  RecordProperty("starts", starts);
  RecordProperty("highest_centre_below_plate_top_mm", rt::test::figure(1e3 * (g.filter_top - highest)));
}

// 1.02 cm (just above the limit) and 1.2 cm.
INSTANTIATE_TEST_SUITE_P(Diameters, HornFilter, ::testing::Values(0.0051, 0.006));

TEST(HornFilterSlots, NineMillimetreGrainsPass) {
  const double r = 0.0045;
  const rt::Scenario sc = filter_scene(r);
  const rt::HornGeometry g = rt::HornGeometry::shipped();
  const double z0 = g.filter_bottom - r - 0.001;
  int passed = 0, fired = 0;
  // The three inner slots are centred at y = 0 and +-11.5 mm (slot 9.5 mm, plate 2 mm).
  for (double y : {-0.0115, 0.0, 0.0115})
    for (double x : {-0.010, -0.005, 0.0, 0.005, 0.010}) {
      const Shot shot = fire(sc, g, Vec3(x, y, z0), Vec3(0, 0, 2.0));
      ++fired;
      passed += shot.passed;
      EXPECT_TRUE(shot.passed) << "a 9 mm grain did not pass the slot at (" << x << ", " << y << ")";
    }
  EXPECT_EQ(passed, fired);
}

}  // namespace
