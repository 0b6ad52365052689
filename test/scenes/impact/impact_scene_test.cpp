// The bucket-impact scene kind (docs/scenes.md C.1): the force-law fit
// recovers f0 and 1/d1 from a sphere decelerated by exactly that law; the
// sphere is placed on a settled, cut bed so that it reaches the surface at
// the impact speed; a short impact stops the sphere inside the bed with its
// durations in order; bad input is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/model.hpp"
#include "regolith_twin/scenes/impact/impact_scene.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
const char* kBucket = "test/scenes/impact/small_bucket.yaml";

TEST(ImpactTracker, FitRecoversTheForceLaw) {
  // A 1 kg sphere entering at 1 m/s under m a = -m g + f0 + m v^2 / d1,
  // f0 = 30 N, 1/d1 = 20 1/m (v < 0 downward), integrated by hand.
  rt::Model m;
  m.bodies.resize(1);
  m.bodies[0].mass = 1.0;
  rt::State s;
  s.bodies.resize(1);
  const double g = 9.81, f0 = 30, inv_d1 = 20, dt = 1e-6, r = 0.05;
  s.bodies[0].pos = Vec3(0, 0, r);  // bottom at the surface z = 0
  s.bodies[0].vel = Vec3(0, 0, -1.0);
  rt::ImpactSpec sp;
  rt::ImpactTracker t(0, r, 0.0, 0.0, g, sp);
  t.start(m, s);
  bool stopped = false;
  for (long k = 0; k < 2000000 && !stopped; ++k) {
    const double v = s.bodies[0].vel.z();
    const double force = f0 + v * v * inv_d1;  // the bed's push, N (m = 1)
    s.bodies[0].force = Vec3(0, 0, v < 0 ? force : 0.0);
    s.bodies[0].vel.z() += (force - g) * dt;
    s.bodies[0].pos.z() += s.bodies[0].vel.z() * dt;
    s.time += dt;
    if (s.bodies[0].vel.z() >= 0) {  // stopped: held there
      s.bodies[0].vel.setZero();
      s.bodies[0].force = Vec3(0, 0, g);
    }
    stopped = t.after_step(m, s);
  }
  EXPECT_TRUE(stopped);
  t.finish(m, s);
  EXPECT_NEAR(t.f0(), f0, 1e-3 * f0);
  EXPECT_NEAR(t.inv_d1(), inv_d1, 1e-3 * inv_d1);
  EXPECT_GT(t.fit_samples(), 50);
  // Stopping depth: (d1/2) ln(1 + v0^2 / ((f0/m - g) d1)) for this law.
  const double d1 = 1 / inv_d1, c = f0 - g;
  EXPECT_NEAR(t.stopping_depth(), 0.5 * d1 * std::log(1 + 1.0 / (c * d1)), 1e-5);
  EXPECT_FALSE(t.bounced());
  EXPECT_GT(t.duration_1mm(), t.duration_1cm());
}

// The sphere's bottom follows a prescribed path z(t) (the tracker reads the body state only).
rt::ImpactTracker follow(const std::vector<std::pair<double, double>>& path, double dt) {
  rt::Model m;
  m.bodies.resize(1);
  m.bodies[0].mass = 1.0;
  rt::State s;
  s.bodies.resize(1);
  const double r = 0.05;
  rt::ImpactSpec sp;
  sp.rest_time = 10;  // never ends by itself
  rt::ImpactTracker t(0, r, 0.0, 0.0, 9.81, sp);
  s.bodies[0].pos = Vec3(0, 0, r + path.front().second);
  t.start(m, s);
  // Piecewise linear between the given (t, bottom) points.
  for (size_t k = 1; k < path.size(); ++k) {
    const double t0 = path[k - 1].first, t1 = path[k].first, z0 = path[k - 1].second, z1 = path[k].second;
    const double v = (z1 - z0) / (t1 - t0);
    for (double tt = t0 + dt; tt <= t1 + 1e-12; tt += dt) {
      s.time = tt;
      s.bodies[0].pos.z() = r + z0 + v * (tt - t0);
      s.bodies[0].vel = Vec3(0, 0, v);
      s.bodies[0].force = Vec3(0, 0, 1.0);  // in contact throughout
      t.after_step(m, s);
    }
  }
  return t;
}

TEST(ImpactTracker, BounceIsAReboundAfterTheDeepestPoint) {
  // docs/scenes.md C.1: a rise of the bottom by more than 0.1 mm after its
  // deepest point, or an upward speed above 1 cm/s.
  const double dt = 1e-5;
  // Down 10 mm, then a recoil of 50 um at 0.5 mm/s: no bounce by either definition.
  rt::ImpactTracker a = follow({{0, 0}, {0.01, -0.01}, {0.11, -0.00995}}, dt);
  EXPECT_FALSE(a.bounced());
  EXPECT_FALSE(a.bounced_1mm_s());
  EXPECT_NEAR(a.stopping_depth(), 0.01, 1e-12);
  EXPECT_NEAR(a.rebound(), 5e-5, 1e-9);
  // A recoil of 50 um at 2 mm/s: the variant's bounce (above 1 mm/s), not the published one.
  rt::ImpactTracker b = follow({{0, 0}, {0.01, -0.01}, {0.035, -0.00995}}, dt);
  EXPECT_FALSE(b.bounced());
  EXPECT_TRUE(b.bounced_1mm_s());
  // A slow rise of 0.2 mm (2 mm/s): a bounce.
  rt::ImpactTracker c = follow({{0, 0}, {0.01, -0.01}, {0.11, -0.0098}}, dt);
  EXPECT_TRUE(c.bounced());
  // A rise of 0.2 mm, then deeper than before: still a bounce, the stopping depth the lowest point.
  rt::ImpactTracker d = follow({{0, 0}, {0.01, -0.01}, {0.11, -0.0098}, {0.12, -0.012}, {0.22, -0.01195}}, dt);
  EXPECT_TRUE(d.bounced());
  EXPECT_NEAR(d.rebound(), 2e-4, 1e-9);
  EXPECT_NEAR(d.stopping_depth(), 0.012, 1e-12);
  // A fast flick upward of 10 um at 2 cm/s: a bounce by its speed.
  rt::ImpactTracker e = follow({{0, 0}, {0.01, -0.01}, {0.0105, -0.00999}}, dt);
  EXPECT_TRUE(e.bounced());
}

rt::SceneOptions quiet_options() {
  rt::SceneOptions o;
  o.cache_dir = ::testing::TempDir() + "/impact_cache";
  o.quiet = true;
  return o;
}

TEST(ImpactScene, ASphereIntoASettledBed) {
  std::unique_ptr<rt::Scene> base = rt::load_scene(kBucket, {}, quiet_options());
  ASSERT_EQ(base->kind(), "impact");
  auto& sc = static_cast<rt::ImpactScene&>(*base);
  const rt::Model& m0 = sc.sc.model;
  // The cut bed: beads were removed, every centre left is at or below the cut plane, the surface near it.
  EXPECT_LT(m0.n_grains, 500);
  EXPECT_GT(m0.n_grains, 250);
  for (int i = 0; i < m0.n_grains; ++i) ASSERT_LE(sc.start.pos[i].z(), 0.045 + 1e-12);
  // From the cache, the same cut bed: grains and positions.
  {
    std::unique_ptr<rt::Scene> again = rt::load_scene(kBucket, {}, quiet_options());
    ASSERT_EQ(again->sc.model.n_grains, m0.n_grains);
    for (int i = 0; i < m0.n_grains; ++i) {
      ASSERT_EQ(again->sc.model.grain_radius[i], m0.grain_radius[i]);
      ASSERT_EQ(again->start.pos[i], sc.start.pos[i]);
    }
  }
  // The nominal surface: the cut's centre plane plus a bead radius; the mean top of the highest beads near it.
  EXPECT_DOUBLE_EQ(sc.surface, 0.045 + 0.005);
  EXPECT_GT(sc.mean_top, 0.035);
  EXPECT_LT(sc.mean_top, 0.051);
  // Packing: the beads' volume over the container's area times the nominal surface height.
  double vol = 0;
  for (int i = 0; i < m0.n_grains; ++i) vol += 4.0 / 3.0 * M_PI * std::pow(m0.grain_radius[i], 3);
  EXPECT_NEAR(sc.packing, vol / (M_PI * 0.05 * 0.05 * 0.05), 1e-12);
  EXPECT_GT(sc.packing, 0.40);
  EXPECT_LT(sc.packing, 0.66);
  // Placed on the axis, bottom `gap` above its first touch of a bead, reaching it at 0.5 m/s in free fall.
  const rt::BodyState& b = sc.start.bodies[sc.body];
  EXPECT_GE(sc.first_touch, sc.mean_top);
  EXPECT_LT(sc.first_touch, sc.surface + 1e-9);
  EXPECT_NEAR(b.pos.z() - sc.radius - sc.first_touch, sc.spec.gap, 1e-12);
  // First touch: lowered by `gap`, the sphere touches one bead (curvature included) and overlaps none.
  double clearance = 1e9;
  for (int i = 0; i < m0.n_grains; ++i) {
    const rt::Vec3 c(0, 0, sc.first_touch + sc.radius);
    clearance = std::min(clearance, (sc.start.pos[i] - c).norm() - sc.radius - m0.grain_radius[i]);
  }
  EXPECT_NEAR(clearance, 0.0, 1e-12);
  const double v2 = b.vel.squaredNorm() + 2 * 9.81 * sc.spec.gap;
  EXPECT_NEAR(std::sqrt(v2), 0.5, 1e-12);
  // The impact.
  rt::Model m = m0;
  rt::State s = sc.start;
  rt::test::SceneRunOutcome ran = rt::test::run_scene(sc, m, s);
  const rt::RunReport& rep = ran.report;
  auto& sr = ran.run;
  ASSERT_EQ(rep.status, "ok") << rep.message << " at t = " << rep.sim_time;
  const auto& t = static_cast<rt::ImpactRun&>(*sr).tracker();
  EXPECT_GT(t.contact_time(), 0);
  EXPECT_GT(t.stopping_depth(), 0.0);  // inside the bed ...
  EXPECT_LT(t.stopping_depth(), 0.045);  // ... above the bottom
  EXPECT_GT(t.duration_1cm(), 0);
  EXPECT_GE(t.duration_1mm(), t.duration_1cm());
  EXPECT_EQ(t.bounced_1mm_s(), t.max_upward_speed() > 1e-3);
  EXPECT_NEAR(t.stopping_depth() - t.stopping_depth_mean_top(), sc.surface - sc.mean_top, 1e-12);
}

TEST(ImpactScene, CutByTopsAndAimedOffAxis) {
  // trim_tops: every bead's top at or below the cut, which is the nominal surface;
  // the sphere falls along the vertical through its aim point.
  std::unique_ptr<rt::Scene> base = rt::load_scene(
      kBucket, {"stages.1.trim_above=0.05", "stages.1.trim_tops=true", "impact.aim=[0.01,-0.005]"}, quiet_options());
  auto& sc = static_cast<rt::ImpactScene&>(*base);
  for (int i = 0; i < sc.sc.model.n_grains; ++i)
    ASSERT_LE(sc.start.pos[i].z() + sc.sc.model.grain_radius[i], 0.05 + 1e-12);
  EXPECT_DOUBLE_EQ(sc.surface, 0.05);
  const rt::BodyState& b = sc.start.bodies[sc.body];
  EXPECT_DOUBLE_EQ(b.pos.x(), 0.01);
  EXPECT_DOUBLE_EQ(b.pos.y(), -0.005);
  double clearance = 1e9;
  for (int i = 0; i < sc.sc.model.n_grains; ++i) {
    const rt::Vec3 c(0.01, -0.005, sc.first_touch + sc.radius);
    clearance = std::min(clearance, (sc.start.pos[i] - c).norm() - sc.radius - sc.sc.model.grain_radius[i]);
  }
  EXPECT_NEAR(clearance, 0.0, 1e-12);
}

TEST(ImpactScene, BadInputIsRefused) {
  auto refused = [](const std::vector<std::string>& set, const std::string& what) {
    try {
      rt::load_scene(kBucket, set, quiet_options());
      ADD_FAILURE() << "accepted: " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused({"impact.impactor=ball"}, "impact.impactor");
  refused({"impact.speed=0"}, "impact.speed");
  refused({"impact.spin=1"}, "spin");
  refused({"impact.aim=[0.04,0]"}, "impact.aim");
  refused({"impact.aim=[0.01]"}, "impact.aim");
  refused({"stages.0.trim_tops=true"}, "trim_tops");
}

}  // namespace
