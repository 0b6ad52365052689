// Grains held at rest (core/hold.hpp): policies combine, a grain is free only
// when none holds it, its inverse mass then comes back exactly as
// finalize_model gave it, a held grain stays where it is while its free
// partner bounces off it, and two held grains never interact.
#include <gtest/gtest.h>

#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/step.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

struct Two {
  rt::Model m;
  rt::State s;
};

// Two grains of 0.5 and 0.4 mm radius, centres 1 mm apart along x, no gravity.
Two two() {
  Two t;
  rt::test::grains_in_a_row(t.m, t.s, {5e-4, 4e-4}, 0.001);
  return t;
}

TEST(Hold, PoliciesCombineAndTheMassComesBackExactly) {
  Two t = two();
  const double im = t.m.grain_inv_mass[1], ii = t.m.grain_inv_inertia[1];
  ASSERT_GT(im, 0);
  t.s.vel[1] = Vec3(1, 2, 3);
  rt::hold_grain(t.m, t.s, 1, rt::kHoldGlued);
  rt::hold_grain(t.m, t.s, 1, rt::kHoldOutsideZone);
  EXPECT_TRUE(rt::held(t.m, 1));
  EXPECT_FALSE(rt::held(t.m, 0));
  EXPECT_EQ(t.m.grain_inv_mass[1], 0);
  EXPECT_EQ(t.m.grain_inv_inertia[1], 0);
  EXPECT_EQ(t.s.vel[1], Vec3::Zero());
  rt::release_grain(t.m, 1, rt::kHoldAnchored);  // a policy that does not hold it: nothing
  rt::release_grain(t.m, 1, rt::kHoldOutsideZone);
  EXPECT_TRUE(rt::held(t.m, 1));  // still glued
  EXPECT_EQ(t.m.grain_inv_mass[1], 0);
  rt::release_grain(t.m, 1, rt::kHoldGlued);
  EXPECT_FALSE(rt::held(t.m, 1));
  EXPECT_EQ(t.m.grain_inv_mass[1], im);  // bit for bit
  EXPECT_EQ(t.m.grain_inv_inertia[1], ii);
}

TEST(Hold, AHeldGrainStaysPutAndItsPartnerBouncesOff) {
  Two t = two();
  t.s.pos[1] = Vec3(0.0008, 0, 0.001);  // 0.1 mm overlap
  rt::hold_grain(t.m, t.s, 0, rt::kHoldAnchored);
  t.s.rebuild_requested = true;
  for (int k = 0; k < 20; ++k) rt::step(t.m, t.s);
  EXPECT_EQ(t.s.pos[0], Vec3(0, 0, 0.001));
  EXPECT_EQ(t.s.vel[0], Vec3::Zero());
  EXPECT_GT(t.s.vel[1].x(), 0);
  // Both held: the pair is not even listed, and nothing moves.
  Two u = two();
  u.s.pos[1] = Vec3(0.0008, 0, 0.001);
  rt::hold_grain(u.m, u.s, 0, rt::kHoldGlued);
  rt::hold_grain(u.m, u.s, 1, rt::kHoldOutsideZone);
  u.s.rebuild_requested = true;
  for (int k = 0; k < 5; ++k) rt::step(u.m, u.s);
  EXPECT_EQ(u.s.pairs.size(), 0u);
  EXPECT_EQ(u.s.pos[1], Vec3(0.0008, 0, 0.001));
}

}  // namespace
