// Relaxed beds (docs/scenes.md F): a bed is relaxed once and cached; a run
// can start from a given relaxed bed instead (--relaxed-bed), e.g. one
// relaxed at another time step, exactly as it was saved; a file of other
// grains, or not a checkpoint, is refused with its path.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "regolith_twin/core/types.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/io/scenario.hpp"

namespace {

std::string bed_yaml(int count, const std::string& dt) {
  return R"(
name: small_bed
seed: 4
gravity: [0, 0, -9.81]
materials:
  grain: {preset: moderate}
  wall: {preset: moderate, structure: true}
contact: {model: linear, kn: rule, v_max: 1.0, x_max: 0.05, dt: )" +
         dt + R"(}
guards: {allow_under_resolved: true}
walls:
  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}
grains:
  - name: bed
    material: grain
    radius: {mean: 0.005, sigma: 0.1, cut: 1.0}
    fill: {shape: box, lo: [0, 0, 0], hi: [0.05, 0.05, 0.05], count: )" +
         std::to_string(count) + R"(}
stages:
  - {name: relax, duration: 0.02}
)";
}

TEST(RelaxedBed, StartsFromTheGivenBedAsSavedAndRefusesOthers) {
  const std::string dir = "/tmp/regolith_relaxed_bed_" + std::to_string(::getpid());
  rt::SceneOptions so;
  so.quiet = true;
  so.cache_dir = dir;
  rt::Scenario a = rt::parse_scenario_text(bed_yaml(40, "2e-5"));
  const rt::RelaxedBed relaxed = rt::relax_bed(a, a.initial, {}, so, "test");
  ASSERT_FALSE(relaxed.from_cache);
  // The same grains at another time step: its own key would relax again;
  // given the bed, it starts from it unchanged.
  rt::Scenario b = rt::parse_scenario_text(bed_yaml(40, "1e-5"));
  rt::SceneOptions given = so;
  given.relaxed_bed = relaxed.cache;
  const rt::RelaxedBed reused = rt::relax_bed(b, b.initial, {}, given, "test");
  EXPECT_TRUE(reused.from_cache);
  EXPECT_EQ(reused.cache, relaxed.cache);
  EXPECT_EQ(reused.state.pos, relaxed.state.pos);
  EXPECT_EQ(reused.state.vel, relaxed.state.vel);
  // Other grains, or not a checkpoint: refused with the file named.
  rt::Scenario c = rt::parse_scenario_text(bed_yaml(41, "2e-5"));
  try {
    rt::relax_bed(c, c.initial, {}, given, "test");
    ADD_FAILURE() << "a bed of 40 grains was accepted for 41";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(relaxed.cache), std::string::npos) << e.what();
  }
  const std::string text = dir + "/not_a_bed.txt";
  std::FILE* f = std::fopen(text.c_str(), "w");
  std::fputs("grains: 40\n", f);
  std::fclose(f);
  given.relaxed_bed = text;
  EXPECT_THROW(rt::relax_bed(b, b.initial, {}, given, "test"), rt::InputError);
  std::remove(text.c_str());
  std::remove(relaxed.cache.c_str());
}

}  // namespace
