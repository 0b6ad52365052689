// Scene kinds from the registry: a kind added from outside the package (the
// toy drop of test/support/toy_drop.hpp) is chosen by its block, runs its
// stages through the one run loop with its own observers and summary, both
// from the command-line path (run_scene) and stepped by rt::Twin, with the
// same result; two kind blocks in one file are refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include "regolith_twin/run/twin.hpp"
#include "toy_drop.hpp"

namespace {

std::string tmp(const std::string& name) { return "/tmp/regolith_scene_kind_" + std::to_string(::getpid()) + name; }

std::string read(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct Registered {
  Registered() { rt::register_scene_kind(std::make_shared<toy::DropKind>()); }
};
const Registered registered;

}  // namespace

TEST(SceneKinds, ToyKindRunsThroughTheRunLoopAndTwinAlike) {
  const std::string file = tmp("_drop.yaml");
  toy::write_drop_file(file);
  rt::SceneOptions so;
  so.quiet = true;
  std::unique_ptr<rt::Scene> scene = rt::load_scene(file, {}, so);
  ASSERT_EQ(scene->kind(), "drop");

  // Command-line path: files written, the kind's columns in the series.
  rt::Model m = scene->sc.model;
  rt::State s = scene->start;
  rt::SceneRunOptions ro;
  ro.out_dir = tmp("_out");
  ro.progress_every = 0;
  std::unique_ptr<rt::SceneRun> sr;
  const rt::RunReport rep = rt::run_scene(*scene, m, s, ro, &sr);
  ASSERT_EQ(rep.status, "ok");
  ASSERT_EQ(rep.stages.size(), 2u);
  EXPECT_EQ(rep.stages[0].name, "settle");
  EXPECT_NEAR(s.time, 0.45, m.dt);  // each of the two stages ends within half a step of its duration
  const auto& run = dynamic_cast<const toy::DropRun&>(*sr);
  // The ball has fallen onto the bed: no grain is left above the plane, and
  // the ball was above it while held.
  EXPECT_EQ(run.above().grains(), 0);
  const std::string series = read(ro.out_dir + "/series.csv");
  EXPECT_EQ(series.substr(0, series.find('\n')), "t,above_count,above_mass");
  EXPECT_NE(series.find("\n0,1,"), std::string::npos) << "the held ball counts at t = 0";
  const std::string summary = read(ro.out_dir + "/summary.json");
  EXPECT_NE(summary.find("\"kind\": \"drop\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"above_count\": 0"), std::string::npos) << summary;

  // The twin steps the same stages and ends where the run ended.
  rt::TwinOptions to;
  to.file = file;
  to.scene = so;
  rt::Twin twin(to);
  EXPECT_EQ(twin.kind(), "drop");
  long n = 0;
  while (!twin.ended() && ++n < 1000000) twin.step();
  ASSERT_TRUE(twin.ended());
  EXPECT_EQ(twin.state().step, s.step);
  for (int i = 0; i < m.n_grains; ++i) ASSERT_EQ(twin.state().pos[i], s.pos[i]) << i;
  EXPECT_EQ(twin.result_line(), "drop: 0 grains above the plane");
}

TEST(SceneKinds, BadBlocksAndTwoKindsAreRefused) {
  const std::string file = tmp("_bad.yaml");
  toy::write_drop_file(file);
  EXPECT_THROW(rt::load_scene(file, {"drop.plane=-1"}, {}), rt::InputError);
  try {
    rt::load_scene(file, {"landing.lander=ball"}, {});
    FAIL() << "two kind blocks were accepted";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at most one scene kind"), std::string::npos) << e.what();
  }
}

TEST(SceneKinds, PlainScenarioIsTheDefaultKind) {
  rt::SceneOptions so;
  so.quiet = true;
  std::unique_ptr<rt::Scene> scene = rt::load_scene("test/ros/tiny_box.yaml", {}, so);
  EXPECT_EQ(scene->kind(), "scenario");
  const auto names = rt::scene_kind_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "landing"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "drop"), names.end());
}
