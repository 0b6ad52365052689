#include <gtest/gtest.h>

#include "test_support.hpp"

TEST(Smoke, TwoGrainsCollide) {
  rt::Model m;
  m.materials.push_back(rt::test::simple_material("g", 2500, 0.5, 0.5, 0.5));
  m.gravity.setZero();
  rt::add_grain(m, 0.005, 0);
  rt::add_grain(m, 0.005, 0);
  m.kn = 1e4;
  m.dt = 1e-6;
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = rt::Vec3(0, 0, 0);
  s.pos[1] = rt::Vec3(0.0101, 0, 0);
  s.vel[0] = rt::Vec3(0.1, 0, 0);
  s.vel[1] = rt::Vec3(-0.1, 0, 0);
  for (int k = 0; k < 20000; ++k) rt::step(m, s);
  EXPECT_LT(s.vel[0].x(), 0);
  EXPECT_NEAR(s.vel[0].x(), -0.05, 0.005);
}
