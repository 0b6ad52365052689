// rt::Twin, the ROS-free running twin under the node: stepping it to the end
// of a landing gives exactly the outcome of run_landing (the CLI path) from
// the same prepared scene, and reset and checkpoints restore states exactly.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <unistd.h>

#include "regolith_twin/observe/twin.hpp"

namespace {

const char* kFile = "test/ros/plate_landing.yaml";  // tests run in the source root

rt::TwinOptions options() {
  rt::TwinOptions o;
  o.file = kFile;
  o.landing.quiet = true;
  o.landing.cache_dir = "/tmp/regolith_twin_twin_test_cache_" + std::to_string(::getpid());
  return o;
}

}  // namespace

TEST(Twin, SteppedLandingEqualsRunLanding) {
  rt::Twin twin(options());
  ASSERT_TRUE(twin.is_landing());
  long guard = 0;
  while (!twin.ended() && ++guard < 100000) twin.step();
  ASSERT_TRUE(twin.ended());
  const rt::LandingOutcome a = twin.outcome();

  rt::LandingSetupOptions so = options().landing;
  rt::LandingScene ls = rt::prepare_landing(kFile, {}, so);
  rt::State s = ls.start;
  const rt::LandingOutcome b = rt::run_landing(ls.sc.model, s, ls.lander, ls.run_spec, rt::LandingOptions{"", 0});
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
  EXPECT_STREQ(twin.phase(), "ended");
}

TEST(Twin, ResetAndCheckpointsRestoreExactly) {
  rt::Twin twin(options());
  const int b = twin.lander();
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
