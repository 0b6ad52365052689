// The one run loop: an observer ends the run after the step it says so; a
// fix acts at its hook points in the order of the step;
// stages run in order with their durations, hold, gravity ramp and speed
// criteria; series rows come before the step when due, plus a final row;
// a blow-up ends run() with its diagnostic, observers finished and the rows
// written so far kept.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "regolith_twin/run/run.hpp"

namespace {

const char* kPile = R"(
name: pile
gravity: [0, 0, -9.81]
materials:
  grain: {preset: moderate}
  wall: {preset: moderate, structure: true}
contact: {model: linear, kn: rule, v_max: 1.0, x_max: 0.05, steps_per_contact: 20}
walls:
  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}
  - {type: cylinder, base: [0, 0, 0], axis: [0, 0, 1], radius: 0.05, length: 0.3, inner: true, material: wall}
grains:
  - name: bed
    material: grain
    radius: {mean: 0.01, sigma: 0.0, cut: 1.0}
    fill: {shape: cylinder, center: [0, 0, 0], radius: 0.04, z: [0.0, 0.06], count: 12}
  - {name: probe, material: grain, radius: 0.01, position: [0, 0, 0.2]}
stages:
  - {name: hold, duration: 0.05, hold: [probe]}
  - {name: ramp, duration: 0.05, gravity: [0, 0, -1.0], gravity_ramp: 0.02}
  - {name: settle, duration: 5.0, until_rms_speed: 0.05, check_every: 0.01}
)";

// Counts steps and ends the run at step `end_at` (0: never).
class Counter : public rt::Observer {
 public:
  explicit Counter(long end_at) : end_at_(end_at) {}
  void start(const rt::Model& m, const rt::State& s) override { started = true; }
  bool after_step(const rt::Model& m, const rt::State& s) override { return ++steps == end_at_; }
  void columns(std::vector<std::string>& out) const override { out.push_back("steps"); }
  void row(const rt::Model& m, const rt::State& s, std::vector<double>& out) const override { out.push_back(steps); }
  void finish(const rt::Model& m, const rt::State& s) override { ++finished; }
  long steps = 0;
  int finished = 0;
  bool started = false;

 private:
  long end_at_;
};

// Writes what it sees into a shared log: the order of the hooks of a step.
class Log : public rt::Observer {
 public:
  explicit Log(std::vector<std::string>& log) : log_(log) {}
  void start(const rt::Model& m, const rt::State& s) override { log_.push_back("measure start"); }
  bool after_step(const rt::Model& m, const rt::State& s) override {
    log_.push_back("measure");
    return false;
  }
  void columns(std::vector<std::string>& out) const override { out.push_back("measured"); }

 private:
  std::vector<std::string>& log_;
};

// A fix that logs every hook and, after every step, puts grain 0 back where it started.
class PinFirst : public rt::Fix {
 public:
  explicit PinFirst(std::vector<std::string>& log) : log_(log) {}
  void prepare(rt::Model& m, rt::State& s) override {
    log_.push_back("prepare");
    p0_ = s.pos[0];
  }
  void start(rt::Model& m, rt::State& s) override { log_.push_back("fix start"); }
  void stage_start(const rt::Stage& st, rt::Model& m, rt::State& s, rt::StageReport& rep) override {
    log_.push_back("stage " + st.name);
  }
  void before_step(const rt::Stage& st, rt::Model& m, rt::State& s) override { log_.push_back("before"); }
  void after_step(const rt::Stage& st, rt::Model& m, rt::State& s) override {
    log_.push_back("after");
    s.pos[0] = p0_;
    s.vel[0].setZero();
  }
  void add_grains(rt::Model& m, rt::State& s) override { log_.push_back("add"); }
  void after_measures(rt::Model& m, rt::State& s) override { log_.push_back("after measures"); }
  void end_step(rt::Model& m, rt::State& s, bool added) override { log_.push_back("end"); }
  bool energy_input() const override { return true; }
  void finish(rt::Model& m, rt::State& s) override { log_.push_back("finish"); }
  void columns(std::vector<std::string>& out) const override { out.push_back("fixed"); }
  void row(const rt::Model& m, const rt::State& s, std::vector<double>& out) const override { out.push_back(1); }

 private:
  std::vector<std::string>& log_;
  rt::Vec3 p0_ = rt::Vec3::Zero();
};

// Series rows every 10 steps into a folder of this process, no progress lines.
rt::RunOptions writing(const std::string& tag, double dt) {
  rt::RunOptions opt;
  opt.out_dir = "/tmp/regolith_run_loop" + tag + "_" + std::to_string(::getpid());
  opt.sample_every = 10 * dt;
  opt.progress_every = 0;
  return opt;
}

int lines(const std::string& path) {
  std::ifstream f(path);
  std::string l;
  int n = 0;
  while (std::getline(f, l)) ++n;
  return n;
}

}  // namespace

TEST(RunLoop, AnObserverEndsTheRun) {
  rt::Scenario sc = rt::parse_scenario_text(kPile);
  rt::State s = sc.initial;
  const rt::RunOptions opt = writing("", sc.model.dt);
  rt::Run run(sc.model, s, rt::RunPlan::of(sc), opt);
  Counter c(25);
  run.add_observer(&c);
  const rt::RunReport rep = run.run();
  EXPECT_TRUE(c.started);
  EXPECT_EQ(c.finished, 1);
  EXPECT_EQ(rep.status, "ok");
  EXPECT_TRUE(rep.ended_by_observer);
  EXPECT_EQ(rep.steps, 25);
  EXPECT_EQ(s.step, 25);
  ASSERT_EQ(rep.stages.size(), 1u);
  EXPECT_EQ(rep.stages[0].reason, "observer");
  EXPECT_FALSE(run.advance()) << "an ended run takes no step";
  // Header, rows before steps 0, 10, 20, and the final row.
  EXPECT_EQ(lines(opt.out_dir + "/series.csv"), 1 + 3 + 1);
}

TEST(RunLoop, AFixActsAtItsHookPointsInTheOrderOfTheStep) {
  rt::Scenario sc = rt::parse_scenario_text(kPile);
  rt::State s = sc.initial;
  const rt::RunOptions opt = writing("_fix", sc.model.dt);
  rt::RunPlan plan = rt::RunPlan::of(sc);
  plan.stages.resize(1);
  plan.stages[0].duration = 2 * sc.model.dt;  // two steps
  rt::Run run(sc.model, s, plan, opt);
  std::vector<std::string> log;
  Log measure(log);
  PinFirst fix(log);
  run.add_observer(&measure);
  run.add_fix(&fix);
  const rt::Vec3 p0 = s.pos[0];
  const rt::RunReport rep = run.run();
  EXPECT_EQ(rep.steps, 2);
  EXPECT_EQ(s.pos[0], p0) << "the fix put grain 0 back after every step";
  EXPECT_NE(s.pos[1], sc.initial.pos[1]) << "the others fell";
  const std::vector<std::string> step = {"before", "after", "add", "measure", "after measures", "end"};
  std::vector<std::string> want = {"prepare", "measure start", "fix start", "stage hold"};
  for (int k = 0; k < 2; ++k) want.insert(want.end(), step.begin(), step.end());
  want.push_back("finish");
  EXPECT_EQ(log, want);
  std::ifstream f(opt.out_dir + "/series.csv");
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header, "t,measured,fixed") << "the fixes' columns follow the measures'";
}

TEST(RunLoop, StagesHoldRampAndStopOnCriteria) {
  rt::Scenario sc = rt::parse_scenario_text(kPile);
  rt::State s = sc.initial;
  rt::RunOptions opt;
  opt.progress_every = 0;
  rt::Run run(sc.model, s, rt::RunPlan::of(sc), opt);
  const int probe = sc.group("probe")->first;
  const rt::Vec3 p0 = s.pos[probe];
  bool ramped = false;
  while (run.advance()) {
    if (run.stage_index() == 0) EXPECT_EQ(s.pos[probe], p0) << "held in place";
    if (run.stage_index() == 1 && s.time > 0.05 + 0.02 + 2 * sc.model.dt) {
      EXPECT_EQ(sc.model.gravity, rt::Vec3(0, 0, -1.0)) << "at the target once the ramp is over";
      ramped = true;
    }
    if (run.stage_index() == 1 && s.time < 0.05 + 0.01) {
      const double g = -sc.model.gravity.z();
      EXPECT_GT(g, 1.0);
      EXPECT_LE(g, 9.81);
    }
  }
  EXPECT_TRUE(ramped);
  const rt::RunReport& rep = run.report();
  ASSERT_EQ(rep.stages.size(), 3u);
  EXPECT_EQ(rep.stages[0].reason, "duration");
  EXPECT_NEAR(rep.stages[0].t_end, 0.05, sc.model.dt);
  EXPECT_EQ(rep.stages[2].reason, "criteria");
  EXPECT_LT(rep.stages[2].t_end, 5.0);
  const rt::GrainSpeeds sp = rt::grain_speeds(sc.model, s, std::vector<uint8_t>(sc.model.n_grains, 0));
  EXPECT_LT(sp.rms, 0.05);
}

TEST(RunLoop, BlowUpKeepsWhatWasWritten) {
  rt::Scenario sc = rt::parse_scenario_text(kPile);
  sc.model.guards.max_overlap_ratio = 1e-6;  // the first real contact trips it
  rt::State s = sc.initial;
  const rt::RunOptions opt = writing("_blow", sc.model.dt);
  rt::Run run(sc.model, s, rt::RunPlan::of(sc), opt);
  Counter c(0);
  run.add_observer(&c);
  const rt::RunReport rep = run.run();
  EXPECT_EQ(rep.status, "blow_up");
  EXPECT_NE(rep.message.find("overlap"), std::string::npos) << rep.message;
  EXPECT_EQ(c.finished, 1);
  EXPECT_GE(lines(opt.out_dir + "/series.csv"), 2) << "the rows before the blow-up stay";
}
