// rt::Twin, the ROS-free running twin under the node: stepping it to the end
// of a landing gives exactly the outcome of run_scene (the CLI path) from the
// same prepared scene, and reset and checkpoints restore states exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <unistd.h>

#include "regolith_twin/run/twin.hpp"
#include "regolith_twin/scenes/landing/landing_scene.hpp"

namespace {

const char* kFile = "test/ros/plate_landing.yaml";  // tests run in the source root

rt::TwinOptions options() {
  rt::TwinOptions o;
  o.file = kFile;
  o.scene.quiet = true;
  o.scene.cache_dir = "/tmp/regolith_twin_twin_test_cache_" + std::to_string(::getpid());
  return o;
}

}  // namespace

TEST(Twin, SteppedLandingEqualsRunLanding) {
  rt::Twin twin(options());
  ASSERT_EQ(twin.kind(), "landing");
  long guard = 0;
  while (!twin.ended() && ++guard < 100000) twin.step();
  ASSERT_TRUE(twin.ended());
  const auto& run = dynamic_cast<const rt::LandingRun&>(twin.run());
  const rt::LandingOutcome a = run.outcome(twin.report(), true);

  std::unique_ptr<rt::Scene> scene = rt::load_scene(kFile, {}, options().scene);
  rt::Model m = scene->sc.model;
  rt::State s = scene->start;
  std::unique_ptr<rt::SceneRun> sr;
  rt::SceneRunOptions ro;
  ro.progress_every = 0;
  const rt::RunReport rep = rt::run_scene(*scene, m, s, ro, &sr);
  const rt::LandingOutcome b = dynamic_cast<const rt::LandingRun&>(*sr).outcome(rep, true);
  EXPECT_TRUE(b.contact && b.lifted_off) << "the test landing must touch down and lift off";
  EXPECT_EQ(a.ended_by, b.ended_by);
  EXPECT_EQ(a.t_contact, b.t_contact);
  EXPECT_EQ(a.t_liftoff, b.t_liftoff);
  EXPECT_EQ(a.t_end, b.t_end);
  EXPECT_EQ(a.speed_ratio, b.speed_ratio);
  EXPECT_EQ(a.energy_ratio, b.energy_ratio);
  EXPECT_EQ(a.max_penetration, b.max_penetration);
  EXPECT_EQ(a.travel_distance, b.travel_distance);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_STREQ(run.phase(twin.ended()), "ended");
  EXPECT_EQ(a.far_field_rms, b.far_field_rms);
  EXPECT_EQ(a.ejected_grains, b.ejected_grains);
}

TEST(Twin, ResetAndCheckpointsRestoreExactly) {
  rt::Twin twin(options());
  const int b = static_cast<const rt::LandingScene&>(twin.scene()).lander;
  const rt::Vec3 p0 = twin.state().bodies[b].pos;
  for (int k = 0; k < 150; ++k) twin.step();
  const std::string path = "/tmp/regolith_twin_twin_test_" + std::to_string(::getpid()) + ".ckpt";
  twin.save(path);
  for (int k = 0; k < 200; ++k) twin.step();
  const rt::BodyState first = twin.state().bodies[b];
  twin.load(path);
  for (int k = 0; k < 200; ++k) twin.step();
  EXPECT_EQ(twin.state().bodies[b].pos, first.pos);
  EXPECT_EQ(twin.state().bodies[b].ang_mom, first.ang_mom);
  twin.reset();
  EXPECT_EQ(twin.state().bodies[b].pos, p0);
  EXPECT_EQ(twin.state().time, 0.0);
  std::remove(path.c_str());
}

TEST(Twin, ANonFiniteBodyStateIsRefusedAndChangesNothing) {
  rt::Twin twin(options());
  const int b = static_cast<const rt::LandingScene&>(twin.scene()).lander;
  for (int k = 0; k < 20; ++k) twin.step();
  const rt::BodyState before = twin.state().bodies[b];
  const double nan = std::nan(""), inf = HUGE_VAL;
  const rt::Vec3 p = before.pos, z = rt::Vec3::Zero();
  const rt::Quat q = rt::Quat::Identity();
  struct Case {
    rt::Vec3 pos, vel, omega;
    rt::Quat q;
  };
  // fn must throw an InputError whose message holds `text`.
  const auto refused = [](const auto& fn, const std::string& text, const std::string& what) {
    try {
      fn();
      ADD_FAILURE() << what << " was accepted";
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  for (const Case& c : {Case{rt::Vec3(nan, 0, 0), z, z, q}, Case{p, rt::Vec3(0, inf, 0), z, q},
                        Case{p, z, rt::Vec3(0, 0, nan), q}, Case{p, z, z, rt::Quat(nan, 0, 0, 0)},
                        Case{p, z, z, rt::Quat(0, 0, 0, 0)}}) {
    refused([&] { twin.set_body_state(b, c.pos, c.q, c.vel, c.omega); }, "must be finite", "a non-finite body state");
    EXPECT_EQ(twin.state().bodies[b].pos, before.pos);
    EXPECT_EQ(twin.state().bodies[b].vel, before.vel);
  }
  // Finite but beyond the state bounds (1e6 m, m/s, rad/s), and a push
  // beyond 1e6 m/s^2 or rad/s^2: refused with the bounds, nothing changed.
  for (const Case& c : {Case{rt::Vec3(0, 0, 1e300), z, z, q}, Case{p, rt::Vec3(2e6, 0, 0), z, q},
                        Case{p, z, rt::Vec3(0, -2e6, 0), q}}) {
    refused([&] { twin.set_body_state(b, c.pos, c.q, c.vel, c.omega); }, "within 1e6 m",
            "a body state beyond the bounds");
    EXPECT_EQ(twin.state().bodies[b].pos, before.pos);
  }
  const double m = twin.model().bodies[b].mass, i_min = twin.model().bodies[b].inertia.minCoeff();
  for (const auto& [f, t] : {std::pair(rt::Vec3(0, 0, 1e300), z), std::pair(rt::Vec3(0, 0, 1.01e6 * m), z),
                             std::pair(z, rt::Vec3(1.01e6 * i_min, 0, 0)), std::pair(rt::Vec3(nan, 0, 0), z)}) {
    refused([&] { twin.apply_wrench(b, f, t, twin.state().time + 1); }, "allowed up to 1e6",
            "a push beyond the bounds");
  }
  EXPECT_NO_THROW(twin.apply_wrench(b, rt::Vec3(0, 0, 0.99e6 * m), z, twin.state().time + 1e-9));
  EXPECT_NO_THROW(twin.apply_wrench(b, z, z, twin.state().time));
  twin.step();  // and the twin steps on
  EXPECT_TRUE(twin.state().bodies[b].pos.allFinite());
}
