// Guards on grains and on the scene's energy (docs/model.md §13): a grain
// that moves more than the list skin in one step, a grain touching more
// others than the scene's radii allow, and a passive scene whose total energy
// grows are stopped with a message naming the grain, the step and the key to
// change; each case is shown to run on silently with its guard off.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "regolith_twin/run/run.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

// Two equal grains of radius r on the x axis, centres at -/+ x0, moving
// towards each other at speed v each; no gravity, no walls.
struct Pair {
  rt::Model m;
  rt::State s;
};

Pair pair(double r, double x0, double v, double kn, double dt) {
  Pair p;
  p.m.materials.push_back(rt::test::simple_material("glass", 2500, 1.0, 1.0, 0.0));
  rt::add_grain(p.m, r, 0);
  rt::add_grain(p.m, r, 0);
  p.m.kn = kn;
  p.m.dt = dt;
  p.m.gravity = Vec3::Zero();
  rt::finalize_model(p.m);
  p.s = rt::make_state(p.m);
  p.s.pos[0] = Vec3(-x0, 0, 0);
  p.s.pos[1] = Vec3(x0, 0, 0);
  p.s.vel[0] = Vec3(v, 0, 0);
  p.s.vel[1] = Vec3(-v, 0, 0);
  return p;
}

std::string blow_up(const std::function<void()>& f) {
  try {
    f();
  } catch (const rt::BlowUpError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// 0.1 mm grains (skin 0.05 mm), 0.55 mm apart, at 100 m/s each with dt =
// 1e-5 s: each moves 1 mm per step, 20 times the skin, and they jump past
// each other without ever touching. The guard stops that at the first step;
// at 1 m/s and dt = 1e-6 s (1 µm per step) they bounce.
TEST(GrainGuards, AGrainMovingMoreThanTheSkinInOneStepIsStopped) {
  const double r = 1e-4, kn = 100;
  {
    Pair p = pair(r, 5.5e-4, 100, kn, 1e-5);
    p.m.guards.max_grain_step_ratio = 0;  // off: the collision is missed
    for (int k = 0; k < 3; ++k) rt::step(p.m, p.s);
    EXPECT_GT(p.s.pos[0].x(), 0.0);
    EXPECT_DOUBLE_EQ(p.s.vel[0].x(), 100.0);  // no contact force ever acted
  }
  Pair p = pair(r, 5.5e-4, 100, kn, 1e-5);
  const std::string msg = blow_up([&] { rt::step(p.m, p.s); });
  ASSERT_FALSE(msg.empty()) << "two grains crossing each other in one step ran on";
  EXPECT_NE(msg.find("at step 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("grain 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("guards.max_grain_step_ratio"), std::string::npos) << msg;
  EXPECT_NE(msg.find("reduce dt"), std::string::npos) << msg;

  Pair slow = pair(r, 1.05e-4, 1, kn, 1e-6);
  for (int k = 0; k < 1000; ++k) rt::step(slow.m, slow.s);  // contact: 23 steps
  EXPECT_NEAR(slow.s.vel[0].x(), -1.0, 0.02);  // bounced back (ε_n = 1)
}

// A pair released from a small overlap at rest, with dt beyond the
// leapfrog's stability limit (ω Δt = 2.5 > 2, ω² = k_n / m*): in one step the
// spring throws the grains apart with (ω Δt)² / 4 = 1.5625 times the energy it
// held. The run loop's energy guard (checked every step here) stops it; off,
// the grains fly apart with the extra energy and nothing else notices.
TEST(GrainGuards, EnergyGrowthInAPassiveSceneIsStopped) {
  const double r = 1e-3, kn = 1e3;
  const double m = 4.0 / 3.0 * kPi * r * r * r * 2500, mstar = 0.5 * m;
  const double dt = 2.5 / std::sqrt(kn / mstar);
  const double x0 = 1e-4 * r;  // overlap, far below the overlap guard
  auto run = [&](double growth) {
    Pair p = pair(r, r - 0.5 * x0, 0, kn, dt);
    p.m.guards.max_energy_growth = growth;
    p.m.guards.energy_check_every = 1;
    const double e0 = 0.5 * kn * x0 * x0;
    rt::RunOptions opt;
    opt.progress_every = 0;
    rt::Run run(p.m, p.s, rt::RunPlan::open_ended("pair"), opt);
    const std::string msg = blow_up([&] {
      for (int k = 0; k < 10; ++k) run.advance();
    });
    return std::make_pair(msg, rt::energy(p.m, p.s).kinetic() / e0);
  };
  const auto off = run(0);
  EXPECT_TRUE(off.first.empty()) << off.first;
  EXPECT_NEAR(off.second, 1.5625, 1e-6);  // the energy the unstable step created
  const auto on = run(0.1);
  ASSERT_FALSE(on.first.empty()) << "a step that created 56 % more energy ran on";
  EXPECT_NE(on.first.find("at step 1"), std::string::npos) << on.first;
  EXPECT_NE(on.first.find("fastest grain"), std::string::npos) << on.first;
  EXPECT_NE(on.first.find("guards.max_energy_growth"), std::string::npos) << on.first;
}

// The same pair at a resolved dt (30 steps per contact) in an elastic
// collision, and grains settling under gravity onto a floor, never trip the
// energy guard checked every step.
TEST(GrainGuards, ResolvedPassiveScenesDoNotTripTheEnergyGuard) {
  const double r = 1e-3, kn = 1e3;
  const double m = 4.0 / 3.0 * kPi * r * r * r * 2500;
  Pair p = pair(r, 1.2e-3, 0.01, kn, rt::dt_rule(m, kn, 30));
  p.m.guards.energy_check_every = 1;
  rt::RunOptions opt;
  opt.progress_every = 0;
  rt::Run run(p.m, p.s, rt::RunPlan::open_ended("pair"), opt);
  EXPECT_NO_THROW(for (int k = 0; k < 3000; ++k) run.advance());
  EXPECT_LT(p.s.vel[0].x(), 0.0);  // the collision happened

  rt::Model fm;
  rt::test::grain_and_wall_in_open_box(fm, 0.02);
  for (int i = 0; i < 27; ++i) rt::add_grain(fm, r, 0);
  fm.kn = rt::kn_rule(m, 1.0, 0.05 * r);
  fm.dt = rt::dt_rule(m, fm.kn, 30);
  fm.guards.energy_check_every = 1;
  rt::finalize_model(fm);
  rt::State fs = rt::make_state(fm);
  for (int i = 0; i < 27; ++i) fs.pos[i] = Vec3(0.004 + 0.0025 * (i % 3), 0.004 + 0.0025 * (i / 3 % 3), 0.005 + 0.0025 * (i / 9));
  rt::Run settle(fm, fs, rt::RunPlan::open_ended("settle"), opt);
  EXPECT_NO_THROW(for (int k = 0; k < 20000; ++k) settle.advance());
  EXPECT_LT(fs.pos[0].z(), 1.5 * r);  // landed on the floor
}

// Grain 0 with 14 neighbours on a sphere of radius 1.98 r around it (Fibonacci
// points; neighbours overlap each other by at most 0.4 r, allowed here by
// max_overlap_ratio 0.5). With at most 13 contacts per grain the step that
// counts them stops, naming grain 0; with the scene's bound (61 at this
// overlap limit) it runs on.
TEST(GrainGuards, TooManyContactsOnOneGrainAreStopped) {
  auto cluster = [](int limit) {
    Pair p;
    p.m.materials.push_back(rt::test::simple_material("glass", 2500, 0.5, 0.5, 0.5));
    const double r = 1e-3;
    for (int i = 0; i < 15; ++i) rt::add_grain(p.m, r, 0);
    p.m.kn = 1;  // soft: the cluster barely moves in one step
    p.m.dt = 1e-5;
    p.m.gravity = Vec3::Zero();
    p.m.guards.max_overlap_ratio = 0.5;
    p.m.guards.max_contacts_per_grain = limit;
    rt::finalize_model(p.m);
    p.s = rt::make_state(p.m);
    const double golden = kPi * (3 - std::sqrt(5.0));
    for (int k = 0; k < 14; ++k) {
      const double z = 1 - (k + 0.5) * 2 / 14, rho = std::sqrt(1 - z * z);
      p.s.pos[k + 1] = 1.98 * r * Vec3(rho * std::cos(golden * k), rho * std::sin(golden * k), z);
    }
    return p;
  };
  Pair p = cluster(13);
  const std::string msg = blow_up([&] {
    rt::step(p.m, p.s);  // lists built and forces known
    p.s.rebuild_requested = true;
    rt::step(p.m, p.s);  // the contacts are counted at a list build
  });
  ASSERT_FALSE(msg.empty()) << "a grain with 14 contacts ran on with a limit of 13";
  EXPECT_NE(msg.find("grain 0 touches 14"), std::string::npos) << msg;
  EXPECT_NE(msg.find("guards.max_contacts_per_grain"), std::string::npos) << msg;

  Pair q = cluster(0);
  EXPECT_EQ(rt::contacts_limit(q.m), 61);
  EXPECT_NO_THROW({
    rt::step(q.m, q.s);
    q.s.rebuild_requested = true;
    rt::step(q.m, q.s);
  });
  EXPECT_EQ(q.s.stats.max_contacts, 14);
  EXPECT_EQ(q.s.stats.max_contacts_grain, 0);
}
