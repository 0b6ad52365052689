// The one run loop: stages -> step -> measures and fixes -> outputs. Every
// tool runs through it: regolith_sim and regolith_land, the bed relaxation of
// a scene, the sweep (through regolith_land) and the ROS node (through
// rt::Twin, which advances it one step at a time).
//
// A run works on a model and a state it does not own, following a plan of
// stages (a scenario's `stages:`, or one open-ended stage that a measure
// ends, as a landing's). What reads the run is a measure (observer.hpp: series
// columns, a summary, an end condition); what acts on it is a fix (fix.hpp,
// called at named points of the step: before it, after it, when grains join,
// after the measures, at its end). The run's own fixes carry out the stages
// (stage_fixes.hpp: trim, stiffness, gravity, damping, held groups) and the
// stiffness schedule; a scene adds its own (the landing's active zone, the
// sampler's second projectile, the plume's erosion planes, the incline's tilt
// and glue). advance() reads as the step does: a short table of contents.
// Measures may take grains out of the run (grains that left the scene): the
// run removes them after the step, keeping every other contact's springs, and
// renumbers the groups and every fix's and measure's data. A numerical blow-up
// ends run() with status "blow_up" and keeps what was written. See docs/architecture.md.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/run/fix.hpp"
#include "regolith_twin/run/observer.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/scenario.hpp"

namespace rt {

class StageEdits;
class StageGravity;
class StageDamping;
class HeldGroups;
class StiffnessSchedule;

// The stages of a run and what they refer to (groups, the scene stiffness).
struct RunPlan {
  std::string name;                   // progress-line label
  std::vector<Stage> stages;
  std::vector<GrainGroup> groups;     // kept current when a stage trims grains
  double scene_kn = 0, scene_dt = 0, scene_body_kn = 0;  // what stiffness_scale scales
  // A scenario's stages.
  static RunPlan of(const Scenario& sc);
  // One stage without a time limit: an observer ends the run.
  static RunPlan open_ended(const std::string& name, const std::string& stage = "run");
};

// Steps a run may take unless raised (--max-steps, the node's ~max_steps):
// ten times the longest shipped run, so a time step or duration that would
// run for days is refused at the start instead of found out later.
constexpr long kDefaultMaxSteps = 100000000;

struct RunOptions {
  std::string out_dir;          // series.csv (and stage snapshots) written here; empty: nothing written
  double sample_every = 0.01;   // s of simulated time between series rows
  double progress_every = 2.0;  // wall seconds between progress lines (<= 0: none)
  bool stage_snapshots = false; // write out_dir/<stage>.bed (compact snapshot) after every stage
  long max_steps = kDefaultMaxSteps;  // stages whose durations need more are refused at the start
                                      // (InputError); a run past it stops with status step_limit
};

struct StageReport {
  std::string name;
  double t_end = 0;         // simulated time at the end of the stage, s
  std::string reason;       // "duration", "criteria" or "observer"
  int grains_removed = 0;   // by the stage's trim
  double stiffness_injection = 0;  // elastic energy added by the stage's change of k_n, J
  double kinetic_at_switch = 0;    // grains' and bodies' kinetic energy then, J
};

struct RunReport {
  std::string status = "ok";  // ok | blow_up | step_limit
  std::string message;        // diagnostic when not ok
  long steps = 0;             // taken by this run
  long rebuilds = 0;          // neighbour-list rebuilds in this run (grain lists; body lists apart)
  long body_rebuilds = 0;
  double sim_time = 0;        // s at the end
  double wall_seconds = 0;
  double max_overlap_ratio = 0;
  bool ended_by_observer = false;
  std::vector<StageReport> stages;
  // Sleeping (docs/model.md §16), when on: grains asleep at the end, mean
  // awake grains per step of this run, transitions, what was discarded.
  bool sleep = false;
  long sleeping_at_end = 0;
  double mean_awake = 0;
  long fell_asleep = 0, woke = 0;
  double discarded_energy = 0, discarded_max_speed = 0;
  // Stiffness schedule (docs/model.md §17), when on: the scene's Δt and the
  // schedule's state at the end (factors reached, changes, energy injected).
  bool schedule = false;
  double dt_scene = 0;
  ScheduleState sched;
  // Free flight (docs/model.md §18), when on: most grains with a reach at a build.
  bool free_flight = false;
  long free_grains_max = 0;
};

class Run {
 public:
  // m and s must outlive the run; observers are added before the first step.
  Run(Model& m, State& s, RunPlan plan, const RunOptions& opt = {});
  ~Run();
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  // Measures and fixes are not owned. The measures' order is the order of
  // their series columns (the fixes' columns follow); fixes act in the order
  // added, after the run's own.
  void add_observer(Observer* o);
  void add_fix(Fix* f);

  // One step, with the stage transitions before it and the observers after
  // it. Returns false (and steps nothing) once the run has ended. Throws BlowUpError.
  bool advance();
  // Stage transitions only: true once every stage is done or an observer ended the run.
  bool ended();

  // To the end: advance() until the run ends, a blow-up caught into the
  // report; then the observers' finish() and the final series row.
  RunReport run();
  // The observers' finish() (run() calls it; a stepping front end calls it at the end).
  void finish();
  // The state was edited from outside (a body's pose or velocity set): the
  // energy-growth guard takes a new reference (docs/model.md §13).
  void state_edited() { energy_watch_.reset(); }

  const RunReport& report() const { return rep_; }
  Model& model() { return m_; }
  State& state() { return s_; }
  const Model& model() const { return m_; }
  const State& state() const { return s_; }
  const std::vector<GrainGroup>& groups() const { return plan_.groups; }
  const RunPlan& plan() const { return plan_; }
  int stage_index() const { return int(k_); }
  // Grains held in place by the current stage (one flag per grain).
  const std::vector<uint8_t>& held() const;

 private:
  bool settle();  // stage transitions up to the next step; false at the end
  void start();   // the first call: fixes prepared, forces primed, measures and fixes started, series opened
  void add_grains();      // grains the fixes add, announced to every fix and measure
  bool measure();         // the measures' after_step: true if one ends the run
  void remove_leaving();  // grains the measures take out, renumbered everywhere
  bool criteria_met();    // the stage's end criteria, when a check is due
  void begin_stage();
  void end_stage(const char* reason);
  void sample();
  void progress();
  void watch_energy();  // energy-growth guard of passive scenes (docs/model.md §13)

  Model& m_;
  State& s_;
  RunPlan plan_;
  RunOptions opt_;
  std::vector<Observer*> obs_;
  std::unique_ptr<StageEdits> edits_;
  std::unique_ptr<StageGravity> gravity_;
  std::unique_ptr<StageDamping> damping_;
  std::unique_ptr<HeldGroups> held_;
  std::unique_ptr<StiffnessSchedule> schedule_;
  std::vector<Fix*> fixes_;  // the run's own, then the scene's
  RunReport rep_;
  CsvSeries series_;
  bool started_ = false, in_stage_ = false, ended_ = false, finished_ = false;
  size_t k_ = 0;                      // current stage
  double t_stage_end_ = 0, next_sample_ = 0, next_check_ = 0;
  double t_start_ = 0, stage_t0_ = 0;  // simulated time at the run's and at the stage's start
  // The progress line's rate (simulated s per wall s; < 0: not yet measured in this stage), its
  // window (wall s) and the simulated time of the last progress line.
  double rate_ = -1, rate_t_ = 0;
  static constexpr double kRateWindow = 60;
  long step0_ = 0;
  long rebuilds0_ = 0, body_rebuilds0_ = 0;
  double awake0_ = 0;  // SleepState::awake_grain_steps at the start
  std::vector<uint8_t> drop_;
  std::vector<int> old_to_new_;
  StageReport sr_;
  EnergyWatch energy_watch_;
  bool energy_input_ = false;  // energy was put in since the last check (field, wrench, a fix)
  std::chrono::steady_clock::time_point t0_, last_progress_;
};

// RMS and largest speed of the free grains not flagged in `skip`.
struct GrainSpeeds {
  double rms = 0, max = 0;
};
GrainSpeeds grain_speeds(const Model& m, const State& s, const std::vector<uint8_t>& skip);

// "m:ss" or "h:mm:ss".
std::string clock_text(double seconds);

}  // namespace rt
