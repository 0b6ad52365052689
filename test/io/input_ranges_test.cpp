// Values a file can hold that make no physical sense, refused before any
// step or stopped with a diagnostic (docs/scenes.md E.3, docs/files.md); each
// case ran, crashed or blew up later before its check.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "regolith_twin/io/data_file.hpp"
#include "regolith_twin/run/scene.hpp"

namespace {

const char* kPlain = "test/fuzz/inputs/plain.yaml";  // 30 grains, a probe sphere; tests run in the source root

std::string refusal(const std::vector<std::string>& set, const char* file = kPlain) {
  try {
    rt::load_scene(file, set);
  } catch (const rt::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

std::string temp_dir(const char* tag) {
  std::string d = std::string("/tmp/regolith_ranges_") + tag + "_" + std::to_string(::getpid());
  ::mkdir(d.c_str(), 0755);
  return d;
}

TEST(InputRanges, AbsurdSizesAndCoordinatesAreRefusedNamingTheKey) {
  // A sphere of 1e300 m overflowed the cell index of the grain–body search.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bodies.0.shapes.0.radius=1e300", "bodies[0].shapes[0].radius"},
      {"bodies.0.shapes=[{type: box, size: [1e300, 1, 1]}]", "bodies[0].shapes[0].size[0]"},
      {"bodies.0.position=[0, 0, 1e300]", "bodies[0].position[2]"},
      {"bodies.0.mass=1e300", "bodies[0].mass"},
      {"gravity=[0, 0, -1e300]", "gravity[2]"},
      {"walls.1.radius=1e300", "walls[1].radius"},
      {"contact.skin=1e300", "contact.skin"},
      {"grains.0.radius.cut=0", "grains[0].radius.cut"},  // rejected every draw: ran for ever
      {"contact.v_max=1e-300", "contact.v_max"},          // k_n underflowed to 0, reported as "model: contact.kn"
      {"bodies.0.inertia=[3, 1, 1]", "bodies[0].inertia"},  // reported as bodies[0]
  };
  for (const auto& [set, key] : cases) {
    const std::string msg = refusal({set});
    EXPECT_NE(msg.find("key '" + key + "'"), std::string::npos) << set << ": " << msg;
  }
}

TEST(InputRanges, GrainsBehindAWallOrOnTopOfEachOtherAreRefused) {
  std::string msg = refusal({"grains.0.fill.center=[0.5, 0, 0]", "grains.0.fill.radius=0.02", "grains.0.fill.count=3"});
  EXPECT_NE(msg.find("key 'grains[0]'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("walls[1] ('side')"), std::string::npos) << msg;
  EXPECT_NE(msg.find("walls[1].radius"), std::string::npos) << msg;
  EXPECT_NE(msg.find("grains[0].fill.center"), std::string::npos) << msg;
  msg = refusal({"grains=[{name: a, material: grain, radius: 0.01, position: [0, 0, 0.05]}, "
                 "{name: b, material: grain, radius: 0.01, position: [0, 0, 0.051]}]",
                 "stages.0.hold=[a]"});
  EXPECT_NE(msg.find("start overlapping"), std::string::npos) << msg;
  EXPECT_NE(msg.find("grains[1].position"), std::string::npos) << msg;
}

TEST(InputRanges, ATrimBelowEveryGrainIsRefusedNamingItAndLeavesNoEarlierOutputs) {
  std::unique_ptr<rt::Scene> sc = rt::load_scene(kPlain, {"stages.1.trim_above=0.005"});  // above the floor, below every centre
  rt::Model m = sc->sc.model;
  rt::State s = sc->start;
  // An earlier run's final grains in the folder: a run stopped part-way
  // must not leave them beside its own partial series.
  const std::string dir = temp_dir("trim");
  std::ofstream(dir + "/final_grains.txt") << "an earlier run's grains\n";
  rt::SceneRunOptions o;
  o.out_dir = dir;
  try {
    rt::run_scene(*sc, m, s, o);
    FAIL() << "a trim of every grain ran";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'stages[1].trim_above' = 0.005 m removes every grain"), std::string::npos)
        << e.what();
  }
  EXPECT_NE(::access((dir + "/final_grains.txt").c_str(), F_OK), 0) << "the earlier run's final grains were left";
  EXPECT_EQ(::access((dir + "/series.csv").c_str(), F_OK), 0);
  for (const char* f : {"series.csv", "final_grains.txt"}) std::remove((dir + "/" + f).c_str());
  ::rmdir(dir.c_str());
}

TEST(InputRanges, TheStepLimitRefusesLongStagesAndStopsOpenEndedRuns) {
  std::unique_ptr<rt::Scene> sc = rt::load_scene(kPlain, {});
  rt::Model m = sc->sc.model;
  rt::State s = sc->start;
  rt::SceneRunOptions o;
  o.max_steps = 100;  // the two stages need about 4,000
  try {
    rt::run_scene(*sc, m, s, o);
    FAIL() << "ran past its step limit";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than the limit of 100"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--max-steps"), std::string::npos) << e.what();
  }
  // A landing ends by its own measure: the limit stops it, as a blow-up does.
  std::unique_ptr<rt::Scene> land = rt::load_scene("test/fuzz/inputs/landing.yaml", {});
  m = land->sc.model;
  s = land->start;
  o.max_steps = 50;
  const rt::RunReport rep = rt::run_scene(*land, m, s, o);
  EXPECT_EQ(rep.status, "step_limit");
  EXPECT_EQ(rep.steps, 50);
  EXPECT_NE(rep.message.find("limit of 50 steps"), std::string::npos) << rep.message;
}

TEST(InputRanges, OutputsAreNeverWrittenOverSpecialFiles) {
  // As root, /dev/full was replaced by a regular file (a rename over it).
  EXPECT_THROW(rt::check_regular_target("/dev/null", "a checkpoint"), rt::InputError);
  const std::string dir = temp_dir("fifo");
  const std::string fifo = dir + "/pipe.ckpt";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    rt::write_file_replacing(fifo, "bytes", "checkpoint", false);
    FAIL() << "wrote over a named pipe";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a named pipe, not a file"), std::string::npos) << e.what();
  }
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_NO_THROW(rt::check_regular_target(dir + "/absent.ckpt", "a checkpoint"));
  // Paths of the node's checkpoints stay in their directory.
  EXPECT_EQ(rt::path_inside(dir, "a.ckpt", "checkpoint"), dir + "/a.ckpt");
  EXPECT_THROW(rt::path_inside(dir, "../a.ckpt", "checkpoint"), rt::InputError);
  EXPECT_THROW(rt::path_inside(dir, "/etc/passwd", "checkpoint"), rt::InputError);
  const std::string link = dir + "/out";
  ASSERT_EQ(::symlink("/etc", link.c_str()), 0);
  EXPECT_THROW(rt::path_inside(dir, "out/passwd", "checkpoint"), rt::InputError);
  // A pipe nobody writes: the bounded read gives up.
  try {
    rt::read_file_bounded(fifo, 1000, "checkpoint", 0.2);
    FAIL() << "read from a pipe nobody writes";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("within 0.2 s"), std::string::npos) << e.what();
  }
  EXPECT_THROW(rt::read_file_bounded("/dev/zero", 1000, "checkpoint", 1), rt::InputError);
  std::remove(link.c_str());
  std::remove(fifo.c_str());
  ::rmdir(dir.c_str());
}

}  // namespace
