// The run's own fixes (fix.hpp): what a stage of a plan asks for
// (docs/model.md §4 and §11; docs/scenes.md F) and the stiffness schedule
// (docs/model.md §17). Run adds them ahead of any scene's fixes.
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/run/fix.hpp"
#include "regolith_twin/run/run.hpp"

namespace rt {

// At a stage's start: grains above the trim height go, k_n and Δt follow the
// stage's stiffness scale (the elastic energy this adds to live contacts is
// measured and may stop the run), and walls are taken away.
class StageEdits : public Fix {
 public:
  StageEdits(RunPlan& plan, bool verbose) : plan_(plan), verbose_(verbose) {}
  void stage_start(const Stage& st, Model& m, State& s, StageReport& rep) override;

 private:
  RunPlan& plan_;
  bool verbose_;
};

// A stage's gravity: set at its start, or moved there over gravity_ramp
// seconds (geometric in magnitude, linear in direction).
class StageGravity : public Fix {
 public:
  void stage_start(const Stage& st, Model& m, State& s, StageReport& rep) override;
  void before_step(const Stage& st, Model& m, State& s) override;

 private:
  Vec3 from_ = Vec3::Zero();
  double t0_ = 0;
};

// Bed preparation after every step: quick-min (each grain keeps only its
// velocity along its net force), springs released, velocities quenched.
class StageDamping : public Fix {
 public:
  void stage_start(const Stage& st, Model& m, State& s, StageReport& rep) override;
  void after_step(const Stage& st, Model& m, State& s) override;

 private:
  double next_quench_ = 0;
};

// Groups a stage holds stay where the stage found them: put back, at rest,
// after every step.
class HeldGroups : public Fix {
 public:
  explicit HeldGroups(const std::vector<GrainGroup>& groups) : groups_(groups) {}
  void stage_start(const Stage& st, Model& m, State& s, StageReport& rep) override;
  void after_step(const Stage& st, Model& m, State& s) override;
  void grains_added(const Model& m, const State& s, int first) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  bool energy_input() const override { return !ids_.empty(); }
  // One flag per grain: held by the current stage.
  const std::vector<uint8_t>& held() const { return held_; }

 private:
  const std::vector<GrainGroup>& groups_;
  std::vector<uint8_t> held_;
  std::vector<int> ids_;
  std::vector<Vec3> pos_;
};

// The stiffness schedule (docs/model.md §17): k_n and Δt follow the fastest
// grain or body, raised at once, lowered once the target has stayed low for
// three durations of the longest contact.
class StiffnessSchedule : public Fix {
 public:
  StiffnessSchedule(const RunPlan& plan, bool verbose) : plan_(plan), verbose_(verbose) {}
  void start(Model& m, State& s) override;
  void end_step(Model& m, State& s, bool grains_added) override;
  bool energy_input() const override { return on_; }
  void report(const State& s, RunReport& rep) const override;
  std::string progress(const Model& m, const State& s) const override;

 private:
  void check(Model& m, State& s, bool grains_now);
  void set_scale(Model& m, State& s, double scale, bool account);
  const RunPlan& plan_;
  bool verbose_;
  bool on_ = false;
  double kn0_ = 0, body_kn0_ = 0, dt0_ = 0;  // the scene's, at the run's start
  double m_min_ = 0;  // smallest grain mass, kg
  long hold_ = 1;     // steps the target must stay low before k_n is lowered
  double vfast_ = 0;  // v_fast at the last check, m/s, and what set it (progress line)
  const char* why_ = "";
};

}  // namespace rt
