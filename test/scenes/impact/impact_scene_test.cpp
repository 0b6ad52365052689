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
  rt::ImpactTracker t(0, r, 0.0, g, sp);
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
  EXPECT_GT(sc.surface, 0.035);
  EXPECT_LT(sc.surface, 0.051);
  EXPECT_GT(sc.packing, 0.45);
  EXPECT_LT(sc.packing, 0.66);
  // Placed on the axis, bottom `gap` above its first touch of a bead, reaching it at 0.5 m/s in free fall.
  const rt::BodyState& b = sc.start.bodies[sc.body];
  EXPECT_GE(sc.first_touch, sc.surface);
  EXPECT_LT(sc.first_touch, sc.surface + 0.01);
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
  rt::RunOptions ro;
  ro.progress_every = 0;
  rt::Run run(m, s, sc.plan, ro);
  auto sr = sc.begin(run);
  for (rt::Observer* o : sr->observers()) run.add_observer(o);
  const rt::RunReport rep = run.run();
  ASSERT_EQ(rep.status, "ok") << rep.message << " at t = " << rep.sim_time;
  const auto& t = static_cast<rt::ImpactRun&>(*sr).tracker();
  EXPECT_GT(t.contact_time(), 0);
  EXPECT_GT(t.stopping_depth(), 0.0);  // inside the bed ...
  EXPECT_LT(t.stopping_depth(), 0.045);  // ... above the bottom
  EXPECT_GT(t.duration_1cm(), 0);
  EXPECT_GE(t.duration_1mm(), t.duration_1cm());
  EXPECT_EQ(t.bounced(), t.max_upward_speed() > 1e-3);
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
}

}  // namespace
