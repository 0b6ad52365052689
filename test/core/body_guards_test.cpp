// Guards on rigid bodies (docs/model.md §13): a body whose state becomes
// non-finite stops the step with its name, a body that would drift through a
// thin plate in one step (tunnelling) is stopped before it passes, and a body
// pressed into the plate deeper than the plate's half thickness is
// stopped, while the same body slow enough to be resolved bounces off the plate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/step.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

// A 2 cm cube falling at `speed` onto a fixed plate 1 mm thick (top face at
// z = 0), no gravity, no grains. The plate's half thickness (0.5 mm) is the
// body step limit.
struct PlateScene {
  rt::Model m;
  rt::State s;
};

PlateScene plate_scene(double speed, double dt, double ratio, double body_kn = 0) {
  PlateScene p;
  rt::Material mat = rt::test::simple_material("structure", 2000, 0.5, 0.5, 0.5);
  mat.structure = true;
  p.m.materials.push_back(mat);
  p.m.bodies.push_back(rt::test::box_body("plate", Vec3(0.1, 0.1, 5e-4), 2000, true, 0));
  p.m.bodies.push_back(rt::test::box_body("cube", Vec3(0.01, 0.01, 0.01), 2000, false, 0));
  p.m.kn = 1e6;
  p.m.body_kn = body_kn;
  p.m.dt = dt;
  p.m.gravity = Vec3::Zero();
  p.m.guards.max_body_step_ratio = ratio;
  rt::finalize_model(p.m);
  p.s = rt::make_state(p.m);
  p.s.bodies[0].pos = Vec3(0, 0, -5e-4);
  p.s.bodies[1].pos = Vec3(0, 0, 0.012);  // 2 mm above the plate
  rt::set_body_velocity(p.m.bodies[1], p.s.bodies[1], Vec3(0, 0, -speed), Vec3::Zero());
  return p;
}

// Steps until the cube is 5 cm past the plate or has come back up; returns
// the cube's final z velocity.
// (k_n = 1e6 N/m: 40 steps per contact at 1 m/s, 0.13 mm overlap.)
double drop(PlateScene& p, int max_steps) {
  for (int k = 0; k < max_steps; ++k) {
    rt::step(p.m, p.s);
    const double z = p.s.bodies[1].pos.z();
    if (z < -0.05 || (z > 0.012 && p.s.bodies[1].vel.z() > 0)) break;
  }
  return p.s.bodies[1].vel.z();
}

}  // namespace

TEST(BodyGuards, TheStepLimitIsThePlatesHalfThickness) {
  PlateScene p = plate_scene(1, 1e-5, 1);
  EXPECT_DOUBLE_EQ(p.m.body_step_limit, 5e-4);
}

TEST(BodyGuards, ACubeResolvedInTimeBouncesOffTheThinPlate) {
  // 1 m/s at dt = 1e-5 s: 10 µm per step, 2 % of the limit.
  PlateScene p = plate_scene(1, 1e-5, 1);
  EXPECT_GT(drop(p, 20000), 0.1);
  EXPECT_GT(p.s.bodies[1].pos.z(), 0.0);
}

TEST(BodyGuards, ACubeFastEnoughToPassThePlateInOneStepIsStopped) {
  // 200 m/s at dt = 1e-5 s: 2 mm per step, four times the plate's half thickness.
  {
    PlateScene p = plate_scene(200, 1e-5, 0);  // guards off: it passes through the plate
    p.m.guards.max_body_overlap_ratio = 0;
    drop(p, 1000);
    EXPECT_LT(p.s.bodies[1].pos.z(), -0.05);
  }
  PlateScene p = plate_scene(200, 1e-5, 1);
  try {
    drop(p, 1000);
    ADD_FAILURE() << "a cube moving 2 mm per step through a 1 mm plate ran on";
  } catch (const rt::BlowUpError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("body 'cube'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("at step 0"), std::string::npos) << msg;  // refused before its first step completes
    EXPECT_NE(msg.find("reduce dt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("guards.max_body_step_ratio"), std::string::npos) << msg;
  }
}

TEST(BodyGuards, ANonFiniteBodyStateStopsTheStepNamingTheBody) {
  for (int what = 0; what < 3; ++what) {
    PlateScene p = plate_scene(1, 1e-5, 1);
    rt::BodyState& c = p.s.bodies[1];
    if (what == 0) c.pos.x() = std::nan("");
    if (what == 1) c.vel.y() = HUGE_VAL;
    if (what == 2) c.ang_mom.z() = std::nan("");
    try {
      rt::step(p.m, p.s);
      ADD_FAILURE() << "case " << what << ": a non-finite body state ran on";
    } catch (const rt::BlowUpError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("body 'cube'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("NaN or infinite"), std::string::npos) << msg;
    }
  }
}

// Body–body stiffness 1e3 N/m: the 16 g cube at 1 m/s would sink v sqrt(m/k)
// = 4 mm into the 1 mm plate. Off, the run goes on with the cube deeper in
// the plate than the plate's half thickness; on, it stops there.
TEST(BodyGuards, ABodyPressedDeepIntoAnotherIsStopped) {
  {
    PlateScene p = plate_scene(1, 1e-5, 1, 1e3);
    p.m.guards.max_body_overlap_ratio = 0;
    double deepest = 0;
    for (int k = 0; k < 3000; ++k) {
      rt::step(p.m, p.s);
      deepest = std::max(deepest, p.s.stats.max_body_overlap_ratio);
    }
    EXPECT_GT(deepest, 1.0);
  }
  PlateScene p = plate_scene(1, 1e-5, 1, 1e3);
  try {
    for (int k = 0; k < 3000; ++k) rt::step(p.m, p.s);
    ADD_FAILURE() << "a cube sinking through the plate ran on";
  } catch (const rt::BlowUpError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bodies 'plate' and 'cube'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("guards.max_body_overlap_ratio"), std::string::npos) << msg;
    EXPECT_NE(msg.find("raise body_kn"), std::string::npos) << msg;
  }
  // At k = 1e6 N/m (0.13 mm, a quarter of the half thickness) it bounces: ACubeResolvedInTimeBouncesOffTheThinPlate.
}
