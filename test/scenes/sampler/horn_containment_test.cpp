// The horn holds what is fired inside it (docs/scenes.md B.1): 500 gravel
// grains placed at random in cylinders 1-3 of the shipped URDF and fired at
// 50 m/s in random directions (no gravity, the shot's contact law and step)
// leave the horn only through its bottom aperture or its open top, never
// through a wall: no grain centre is ever found beyond the outer wall surface
// between the two openings. Their total momentum changes by the horn's
// impulse alone (p(t) - p(0) = sum of dt F_horn over the leapfrog's half
// kicks), to rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"
#include "horn_alone.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
constexpr double kPi = 3.14159265358979323846;
constexpr double kWall = 0.001;  // shell thickness of the shipped horn (scripts/make_horn.py), m

double uniform(uint64_t& state) {
  state = state * 6364136223846793005ULL + 1442695040888963407ULL;
  return double(state >> 11) * (1.0 / 9007199254740992.0);
}

TEST(HornContainment, GrainsLeaveOnlyThroughTheOpenings) {
  rt::Scenario sc = rt::test::horn_alone(0.0025, Vec3(0, 0, 0.3));
  rt::Model& m = sc.model;
  rt::State& s = sc.initial;
  const rt::HornGeometry g = rt::HornGeometry::shipped();
  const double r = 0.0025, speed = 50;
  uint64_t rng = 2024;
  auto direction = [&] {
    const double cz = 2 * uniform(rng) - 1, az = 2 * kPi * uniform(rng), sz = std::sqrt(1 - cz * cz);
    return Vec3(sz * std::cos(az), sz * std::sin(az), cz);
  };
  s.vel[0] = speed * direction();
  // 499 more, not overlapping, centres at least 1 mm clear of the inner wall.
  int tries = 0;
  while (m.n_grains < 500) {
    ASSERT_LT(++tries, 100000);
    const double z = 0.02 + 0.58 * uniform(rng);
    const double rr = (g.inner_radius(z) - r - 0.001) * std::sqrt(uniform(rng)), az = 2 * kPi * uniform(rng);
    const Vec3 p(rr * std::cos(az), rr * std::sin(az), z);
    bool free = true;
    for (int j = 0; j < m.n_grains && free; ++j) free = (s.pos[j] - p).norm() > 2 * r + 1e-4;
    if (free) rt::add_grain(m, s, r, m.grain_material[0], p, speed * direction(), Vec3::Zero());
  }
  const int n = m.n_grains;
  std::vector<int> exit(n, 0);  // 0 inside, 1 bottom, 2 top
  int bottom = 0, top = 0, side = 0;
  double t_all = -1;
  const long steps = std::lround(0.25 / m.dt);
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (int i = 0; i < n; ++i) p += m.grain_mass[i] * s.vel[i];
    return p;
  };
  auto scale = [&] {
    double v = 0;
    for (int i = 0; i < n; ++i) v += m.grain_mass[i] * s.vel[i].norm() + 0.5 * m.dt * s.force[i].norm();
    return v;
  };
  rt::prime(m, s);
  s.forces_valid = true;
  const Vec3 p0 = momentum();
  Vec3 impulse = -0.5 * m.dt * s.bodies[0].force;
  double bound = scale();
  long k = 0;
  for (; k < steps && t_all < 0; ++k) {
    rt::step(m, s);
    impulse -= m.dt * s.bodies[0].force;  // the end of this step and the start of the next
    bound += scale();
    int out = 0;
    for (int i = 0; i < n; ++i) {
      const double z = g.axial(s.pos[i]), rad = g.radial(s.pos[i]);
      if (exit[i] == 0 && z >= 0 && z <= g.top() && rad > g.inner_radius(z) + kWall) {
        ++side;
        ADD_FAILURE() << "grain " << i << " crossed the wall at z = " << z << " m, " << rad << " m from the axis, t = "
                      << s.time << " s";
        exit[i] = 3;
      }
      if (exit[i] == 0 && z < -2 * r) exit[i] = 1, ++bottom;
      if (exit[i] == 0 && z > g.top() + 2 * r) exit[i] = 2, ++top;
      out += exit[i] != 0;
    }
    if (out == n) t_all = s.time;
  }
  impulse += 0.5 * m.dt * s.bodies[0].force;  // the last step's end counts once
  const double residual = (momentum() - p0 - impulse).norm();
  EXPECT_LT(residual, 4 * std::numeric_limits<double>::epsilon() * bound) << "momentum balance";
  EXPECT_GT(impulse.norm(), 1e6 * residual) << "the horn's impulse should matter";
  EXPECT_EQ(side, 0);
  EXPECT_GT(bottom, 50) << "the test should see grains leave through the bottom aperture";
  EXPECT_GT(top, 0) << "and some through the open top";
  RecordProperty("bottom", bottom);
  RecordProperty("top", top);
  RecordProperty("still_inside", n - bottom - top - side);
  RecordProperty("steps", static_cast<int>(k));
  RecordProperty("horn_impulse", rt::test::figure(impulse.norm()));
  RecordProperty("momentum_residual", rt::test::figure(residual));
}

}  // namespace
