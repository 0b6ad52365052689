// Lander scenes (docs/scenes.md A): attitude and aim of the placement, and a
// short landing on a layer of glued grains observed with the outcome
// definitions (first contact, lift-off of the corners, ratios, ballistic travel).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "regolith_twin/scenes/landing/landing.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

// A box lander (0.29 x 0.275 x 0.195 m, 10 kg) over a rigid plate whose top
// face is at z = rim (a layer of glued grains lies out of the way: glued
// grains under a body damp each contact with the body's whole mass).
rt::Model lander_scene(double rim, double eps) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5),
                 rt::test::simple_material("lander", 2430, eps, eps, 0.5)};
  m.materials[1].structure = true;
  const double r = 0.01;
  const double mass = 4.0 / 3.0 * kPi * r * r * r * 2430;
  m.kn = rt::kn_rule(mass, 0.5, 0.01 * r);
  m.dt = rt::dt_rule(mass, m.kn, 30);
  for (int ix = -20; ix <= 20; ++ix)
    for (int iy = -20; iy <= 20; ++iy) rt::add_grain(m, r, 0, true);
  rt::BodyModel b;
  b.name = "lander";
  b.mass = 10;
  const Vec3 e(0.29, 0.275, 0.195);
  b.inertia = Vec3(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(), e.x() * e.x() + e.y() * e.y()) * (10.0 / 12);
  b.material = 1;
  rt::Shape box;
  box.type = rt::ShapeType::Box;
  box.size = e / 2;
  b.shapes = {box};
  m.bodies.push_back(b);
  // A rigid plate (fixed body) whose top face is the surface at z = rim.
  rt::BodyModel plate;
  plate.name = "plate";
  plate.fixed = true;
  plate.material = 1;
  rt::Shape slab;
  slab.type = rt::ShapeType::Box;
  slab.size = Vec3(0.5, 0.5, 0.05);
  plate.shapes = {slab};
  m.bodies.push_back(plate);
  m.body_kn = 1e6;
  rt::finalize_model(m);
  return m;
}

rt::State layer_state(const rt::Model& m, double rim) {
  rt::State s = rt::make_state(m);
  int k = 0;
  for (int ix = -20; ix <= 20; ++ix)
    for (int iy = -20; iy <= 20; ++iy) s.pos[k++] = Vec3(0.02 * ix, 0.02 * iy, rim - 0.3);  // far below: unused
  s.bodies[1].pos = Vec3(0, 0, rim - 0.05);
  return s;
}

// A flat landing under 1 g on the rigid plate of lander_scene.
rt::LandingSpec plate_spec(double rim, double angle_deg, double speed) {
  rt::LandingSpec sp;
  sp.lander = "lander";
  sp.rim = rim;
  sp.container_radius = 0.4;
  sp.attitude = rt::Attitude::Flat;
  sp.angle_deg = angle_deg;
  sp.speed = speed;
  sp.g = 9.81;
  return sp;
}

}  // namespace

TEST(Landing, PlacementFollowsAttitudeAngleAndAim) {
  const double rim = 0.3;
  rt::Model m = lander_scene(rim, 0.6);
  rt::State s = layer_state(m, rim);
  rt::LandingSpec sp;
  sp.lander = "lander";
  sp.rim = rim;
  sp.angle_deg = 30;
  sp.speed = 0.19;
  sp.clearance = 0.003;
  sp.aim = Vec3(0.05, -0.02, 0);
  for (rt::Attitude a : {rt::Attitude::BCF, rt::Attitude::FCF, rt::Attitude::Flat}) {
    sp.attitude = a;
    rt::place_lander(m, s, 0, sp);
    const auto corners = rt::lander_corners(m, s, 0);
    int low = 0;
    for (int c = 1; c < 8; ++c)
      if (corners[c].z() < corners[low].z()) low = c;
    EXPECT_NEAR(corners[low].z(), rim + sp.clearance, 1e-12) << "lowest corner at the clearance";
    const Vec3 v = s.bodies[0].vel;
    EXPECT_NEAR(v.norm(), 0.19, 1e-12);
    EXPECT_NEAR(std::acos(-v.z() / v.norm()) * 180 / kPi, 30, 1e-9) << "angle from the vertical";
    EXPECT_GT(v.x(), 0) << "heading 0 moves along +x";
    // The lowest corner travels to the aim point.
    const double t = (corners[low].z() - rim) / -v.z();
    const Vec3 hit = corners[low] + v * t;
    EXPECT_NEAR(hit.x(), sp.aim.x(), 1e-12);
    EXPECT_NEAR(hit.y(), sp.aim.y(), 1e-12);
    const Vec3 rel = corners[low] - s.bodies[0].pos;
    if (a == rt::Attitude::BCF) {
      EXPECT_LT(rel.x(), -0.05) << "back corner first: behind the centre of mass";
    }
    if (a == rt::Attitude::FCF) {
      EXPECT_GT(rel.x(), 0.05) << "front corner first: ahead of the centre of mass";
    }
    if (a == rt::Attitude::Flat) {
      int at_bottom = 0;
      for (const Vec3& c : corners) at_bottom += std::fabs(c.z() - corners[low].z()) < 1e-12;
      EXPECT_EQ(at_bottom, 4) << "flat: the bottom face is level";
    }
  }
}

TEST(Landing, PlacementBacksOffFromGrainsAboveTheTrimPlane) {
  // Trimming keeps centres below the rim, so grain tops stick out of it: a
  // lander placed at the clearance above the rim would start inside them.
  const double rim = 0.3;
  rt::Model m = lander_scene(rim, 0.6);
  rt::State s = layer_state(m, rim);
  for (int i = 0; i < m.n_grains; ++i) s.pos[i].z() = rim - 0.2 * m.grain_radius[i];  // tops above the rim
  rt::LandingSpec sp;
  sp.lander = "lander";
  sp.rim = rim;
  sp.speed = 0.19;
  sp.clearance = 0.002;
  for (double angle : {0.0, 30.0, 60.0}) {
    sp.angle_deg = angle;
    sp.attitude = rt::Attitude::BCF;
    rt::place_lander(m, s, 0, sp);
    const rt::BodyModel& bm = m.bodies[0];
    const rt::BodyState& bs = s.bodies[0];
    double closest = 1e300;
    for (int i = 0; i < m.n_grains; ++i)
      for (const rt::Shape& sh : bm.shapes)
        closest = std::min(closest, -rt::shape_gap(bm, sh, bs.q.conjugate() * (s.pos[i] - bs.pos),
                                                   m.grain_radius[i]).overlap);
    EXPECT_GE(closest, sp.clearance - 1e-9) << "angle " << angle;
    EXPECT_LT(closest, sp.clearance + 0.01) << "angle " << angle << ": not moved back further than needed";
    // Still on the approach line through the aim point.
    const auto corners = rt::lander_corners(m, s, 0);
    int low = 0;
    for (int c = 1; c < 8; ++c)
      if (corners[c].z() < corners[low].z()) low = c;
    const Vec3 v = bs.vel;
    const Vec3 hit = corners[low] + v * ((corners[low].z() - rim) / -v.z());
    EXPECT_NEAR(hit.x(), sp.aim.x(), 1e-9);
    EXPECT_NEAR(hit.y(), sp.aim.y(), 1e-9);
  }
}

TEST(Landing, BounceOnARigidPlateGivesAConsistentOutcome) {
  // Impact at 0.5 m/s, 20 degrees, under 1 g on a rigid plate: the lander
  // must touch, lift off with less energy, and the ballistic extrapolation
  // must match the kinematics of the lift-off state.
  const double rim = 0.3;
  rt::Model m = lander_scene(rim, 0.6);
  m.gravity = Vec3(0, 0, -9.81);
  rt::State s = layer_state(m, rim);
  rt::LandingSpec sp = plate_spec(rim, 20, 0.5);
  sp.clearance = 0.001;
  sp.after_liftoff = 0.01;
  sp.max_after_contact = 1.0;
  rt::place_lander(m, s, 0, sp);
  rt::LandingOptions opt;
  opt.progress_every = 0;
  if (const char* dir = std::getenv("LANDING_TEST_OUT")) opt.out_dir = dir;
  const rt::LandingOutcome o = rt::run_landing(m, s, 0, sp, opt);
  ASSERT_EQ(o.status, "ok") << o.message;
  ASSERT_TRUE(o.contact);
  ASSERT_TRUE(o.lifted_off) << o.ended_by;
  EXPECT_EQ(o.ended_by, "after_liftoff");
  EXPECT_NEAR(o.v_in, std::sqrt(0.25 + 2 * 9.81 * sp.clearance), 2e-3) << "speed at first contact";
  EXPECT_GT(o.speed_ratio, 0.05);
  EXPECT_LT(o.speed_ratio, 1.0);
  EXPECT_LE(o.energy_ratio, 1.0) << "a passive bounce cannot gain energy";
  EXPECT_GT(o.collision_duration, 0);
  // Ballistic flight: back down to max(h_liftoff, 0.155) under g, or to the
  // lift-off height when the apex stays below 0.155 m.
  const double vz = o.v_out * std::cos(o.angle_out_deg * kPi / 180);
  double ht = std::max(o.h_liftoff, 0.155);
  if (vz * vz < 2 * 9.81 * (ht - o.h_liftoff)) ht = o.h_liftoff;
  EXPECT_NEAR(o.travel_time, (vz + std::sqrt(vz * vz - 2 * 9.81 * (ht - o.h_liftoff))) / 9.81, 1e-9);
  EXPECT_GT(o.travel_time, 0);
  EXPECT_GT(o.second_impact_speed, 0);
  // Energy along the flight: v1^2 = v_out^2 + 2 g (h_liftoff - ht).
  EXPECT_NEAR(o.second_impact_speed * o.second_impact_speed, o.v_out * o.v_out + 2 * 9.81 * (o.h_liftoff - ht), 1e-9);
  RecordProperty("speed_ratio", rt::test::figure(o.speed_ratio));
}

TEST(Landing, LanderTrappedBelowTheTrimPlaneEndsTheRunEarly) {
  // The plate's top 0.25 m below the trim plane: a slow lander that lands on
  // it can never get every corner back above the trim plane. The run stops
  // once its kinetic energy has stayed below half the potential energy of a
  // lift-off for trapped_hold, long before max_after_contact, with V_out = 0;
  // with trapped_hold = 0 it runs to max_after_contact.
  const double rim = 0.3;
  rt::Model m = lander_scene(rim, 0.6);
  m.gravity = Vec3(0, 0, -9.81);
  rt::LandingSpec sp = plate_spec(rim, 0, 0.05);
  sp.max_after_contact = 0.6;
  rt::LandingOptions opt;
  opt.progress_every = 0;
  for (const double hold : {0.1, 0.0}) {
    rt::State s = layer_state(m, rim);
    s.bodies[1].pos.z() -= 0.25;  // plate top at the placement plane
    sp.rim = rim - 0.25;
    rt::place_lander(m, s, 0, sp);
    sp.rim = rim;  // ... and the surface reference 0.25 m higher
    sp.trapped_hold = hold;
    const rt::LandingOutcome o = rt::run_landing(m, s, 0, sp, opt);
    ASSERT_EQ(o.status, "ok") << o.message;
    ASSERT_TRUE(o.contact);
    EXPECT_FALSE(o.lifted_off);
    EXPECT_EQ(o.v_out, 0);
    if (hold > 0) {
      EXPECT_EQ(o.ended_by, "trapped");
      EXPECT_LT(o.t_end - o.t_contact, 0.3) << "stopped early";
    } else {
      EXPECT_EQ(o.ended_by, "max_after_contact");
      EXPECT_NEAR(o.t_end - o.t_contact, 0.6, 1e-3);
    }
  }
}

TEST(Landing, TheExpectedTimeLeftIsExactInFlightAndWithinTwiceOnAStraightRise) {
  // The tracker fed by hand: first contact at 0.1 m/s downwards, then the
  // lander (tilted 20 and 10 degrees, as a corner-first attitude) rising at
  // 0.02 m/s from 6 cm under the trim plane without turning, and no contact,
  // until the run ends 1 s after the clear lift-off. Before it the estimate
  // must lie within a factor of 2 of the time then left while the lowest
  // corner is at least 1 cm under (the promise of the progress line); in
  // flight it is exact; and it never exceeds the bound of max_after_contact.
  const double rim = 0.3, v = 0.02, dt = 0.01;
  const rt::Model m = lander_scene(rim, 0.6);
  rt::LandingSpec sp = plate_spec(rim, 0, 0.1);
  sp.g = 0;
  sp.after_liftoff = 1.0;
  sp.max_after_contact = 60;
  rt::LandingTracker tr(m.bodies[0], sp, Vec3::Zero());
  rt::BodyState bs;
  bs.q = rt::Quat(Eigen::AngleAxisd(20 * kPi / 180, Vec3::UnitY()) * Eigen::AngleAxisd(10 * kPi / 180, Vec3::UnitX()));
  bs.pos = Vec3(0, 0, rim);
  bs.pos.z() += -0.06 - tr.lowest_corner(bs);  // lowest corner 6 cm under the plane
  bs.vel = Vec3(0, 0, -0.1);
  rt::BodyContacts touch;
  touch.total = touch.bed = 1;
  ASSERT_FALSE(tr.update(0, bs, touch));
  const double t_end = 0.06 / v + sp.after_liftoff;  // the clear lift-off, then 1 s
  bs.vel = Vec3(0, 0, v);
  std::vector<double> ratios;
  double t = 0;
  for (int k = 1; !tr.ended(); ++k) {
    t = k * dt;
    bs.pos.z() += v * dt;
    if (tr.update(t, bs, rt::BodyContacts())) break;  // the run's end: checked after the loop
    const double e = tr.expected_time_left(t, bs), left = t_end - t;
    ASSERT_GE(e, 0) << t;
    EXPECT_LE(e, 60 - t) << t;
    if (tr.outcome().lifted_off_clear) {
      EXPECT_NEAR(e, tr.outcome().t_liftoff_clear + sp.after_liftoff - t, 1e-12) << t;
    } else if (tr.lowest_corner(bs) < -0.01) {
      ratios.push_back(e / left);
    }
  }
  ASSERT_GT(ratios.size(), 100u);
  for (double q : ratios) {
    EXPECT_GT(q, 0.5);
    EXPECT_LT(q, 2.0);
  }
  EXPECT_NEAR(t, t_end, 2 * dt) << "the run's end";
}
