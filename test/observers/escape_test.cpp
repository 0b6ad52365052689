// Grains that leave the scene: a grain fired up out of a box is taken out of
// the run after the step it crossed the top, logged with its time, face, mass
// and velocity; the run goes on with the others, their groups, held grains
// and the other observers' per-grain data renumbered, and every contact of
// the grains that stay keeps its springs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "regolith_twin/observers/ejecta.hpp"
#include "regolith_twin/observers/escape.hpp"
#include "regolith_twin/run/run.hpp"

namespace {

const char* kScene = R"(
name: escape
gravity: [0, 0, -9.81]
materials:
  grain: {preset: moderate}
  wall: {preset: moderate, structure: true}
contact: {model: linear, kn: rule, v_max: 3.0, x_max: 0.05, steps_per_contact: 20}
walls:
  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}
grains:
  - {name: left, material: grain, radius: 0.01, position: [-0.05, 0, 0.01]}
  - {name: shot, material: grain, radius: 0.01, position: [0, 0, 0.02], velocity: [0.1, 0, 3.0]}
  - {name: right, material: grain, radius: 0.01, position: [0.05, 0, 0.01]}
stages:
  - {name: fly, duration: 0.3, hold: [right]}
)";

}  // namespace

TEST(Escape, AGrainLeavingTheBoxIsTakenOutAndLogged) {
  rt::Scenario sc = rt::parse_scenario_text(kScene);
  rt::State s = sc.initial;
  rt::RunOptions opt;
  opt.progress_every = 0;
  rt::Run run(sc.model, s, rt::RunPlan::of(sc), opt);
  const std::string log = "/tmp/regolith_escape_" + std::to_string(::getpid()) + ".csv";
  rt::Escape escape(rt::Vec3(-1, -1, -1), rt::Vec3(1, 1, 0.3), 1, log);
  rt::Ejecta ejecta(0.1, 1);
  run.add_observer(&ejecta);
  run.add_observer(&escape);
  const double shot_mass = sc.model.grain_mass[1];
  // Up to the step the shot leaves: 0.3 m at 3 m/s under g, about 0.11 s.
  while (run.advance() && sc.model.n_grains == 3) {
    EXPECT_LE(s.pos[1].z(), 0.3 + 3.0 * sc.model.dt) << "taken out the step it crossed";
  }
  ASSERT_EQ(sc.model.n_grains, 2);
  ASSERT_EQ(escape.exits().size(), 1u);
  const rt::Escape::Exit& e = escape.exits()[0];
  EXPECT_EQ(e.face, rt::Escape::ZMax);
  EXPECT_EQ(e.mass, shot_mass);
  EXPECT_GT(e.pos.z(), 0.3);
  // Ballistic up to there: v_z^2 = v0^2 - 2 g (z - z0), which the leapfrog
  // keeps exactly under a constant force, up to one rounding of v0 per step.
  const double rounding = 4.0 * double(s.step) * 2.2e-16 * 3.0;
  EXPECT_NEAR(e.vel.z(), std::sqrt(9.0 - 2 * 9.81 * (e.pos.z() - 0.02)), rounding);
  EXPECT_DOUBLE_EQ(escape.mass_through(rt::Escape::ZMax), shot_mass);
  // The shot was ejecta (above 0.1 m) before it left; the flags followed the renumbering.
  EXPECT_EQ(ejecta.count(), 1);
  EXPECT_FALSE(ejecta.ejected(0));
  EXPECT_FALSE(ejecta.ejected(1));
  // Groups renumbered: 'right' is now grain 1 and still held.
  ASSERT_EQ(run.groups().size(), 3u);
  EXPECT_EQ(run.groups()[1].count, 0);
  EXPECT_EQ(run.groups()[2].first, 1);
  EXPECT_EQ(run.held(), (std::vector<uint8_t>{0, 1}));
  const rt::Vec3 right = s.pos[1];
  for (int k = 0; k < 50 && run.advance(); ++k) EXPECT_EQ(s.pos[1], right);
  while (run.advance()) {
  }
  run.finish();
  std::ifstream f(log);
  std::string header, line;
  std::getline(f, header);
  EXPECT_EQ(header, "t,face,mass,x,y,z,vx,vy,vz");
  ASSERT_TRUE(std::getline(f, line));
  EXPECT_NE(line.find(",z_max,"), std::string::npos) << line;
  std::remove(log.c_str());
}

// The wall spring of grain 0 after each step, before any removal.
class WallSpring : public rt::Observer {
 public:
  bool after_step(const rt::Model& m, const rt::State& s) override {
    for (int k = 0; k < s.wall_pairs.size(); ++k)
      if (s.wall_pairs.grain[k] == 0) spring = s.wall_pairs.spring_t[k];
    return false;
  }
  rt::Vec3 spring = rt::Vec3::Zero();
};

TEST(Escape, RemovalKeepsTheOtherContactsSprings) {
  // A grain sliding on the floor (its wall contact carries a tangential
  // spring) while another leaves: the sliding grain's spring is the same
  // after the removal as it was after the step, before it.
  rt::Scenario sc = rt::parse_scenario_text(kScene);
  rt::State s = sc.initial;
  s.vel[0] = rt::Vec3(0.01, 0, 0);
  rt::RunOptions opt;
  opt.progress_every = 0;
  rt::Run run(sc.model, s, rt::RunPlan::of(sc), opt);
  WallSpring before;
  rt::Escape escape(rt::Vec3(-1, -1, -1), rt::Vec3(1, 1, 0.05), 1);
  run.add_observer(&before);
  run.add_observer(&escape);
  while (run.advance() && sc.model.n_grains == 3) {
  }
  ASSERT_EQ(sc.model.n_grains, 2);
  ASSERT_GT(before.spring.norm(), 0) << "the sliding grain must carry a spring";
  bool found = false;
  for (int k = 0; k < s.wall_pairs.size(); ++k)
    if (s.wall_pairs.grain[k] == 0) {
      EXPECT_EQ(s.wall_pairs.spring_t[k], before.spring);
      found = true;
    }
  EXPECT_TRUE(found);
  // The next step carries it on through the list rebuild the removal asked for.
  const rt::Vec3 kept = before.spring;
  ASSERT_TRUE(run.advance());
  EXPECT_GT(before.spring.dot(kept), 0) << "not restarted from zero";
}
