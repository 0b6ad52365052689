// Scene kinds and their registry. A scene file is a scenario (materials,
// walls, bodies, grains, stages) plus at most one block naming its kind
// (`landing:` ...); a file without one is a plain scenario whose stages are
// the run. A kind reads and validates its own block (errors name file, key and
// range), prepares its scene on the scenario (bed relaxed and cached,
// bodies placed), and for each run contributes its observers and writes its
// outputs. The ROS node adds a kind's topics through the ROS registry
// (ros/scene_topics.hpp). Adding a kind: docs/architecture.md.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/run/run.hpp"

namespace YAML {
class Node;
}

namespace rt {

struct SceneOptions {
  std::string cache_dir;   // relaxed beds (empty: default_cache_dir())
  std::string relax_out;   // output folder of a bed relaxation (empty: none written)
  bool quiet = false;      // no progress lines while preparing
  std::string relaxed_bed; // a relaxed bed to start from instead of relaxing or the cache (a checkpoint of
                           // the same grains, e.g. a cache file of a run at another time step)
  long max_steps = kDefaultMaxSteps;  // of a bed relaxation (RunOptions::max_steps)
};

class JsonObject;

// A prepared scene's start state: time, step and ticks from zero, the lists
// rebuilt and the forces recomputed at the first step.
void restart_at_zero(State& s);

// One run of a prepared scene: its observers, and its outputs written from them.
// The run's sleep figures (docs/model.md §16) as j["sleep"], when sleeping was on.
void add_sleep_summary(JsonObject& j, const RunReport& rep);
// "free_flight": {"free_grains_max"} when free flight was on (docs/model.md §18).
void add_free_flight_summary(JsonObject& j, const RunReport& rep);
// The stiffness schedule's figures (docs/model.md §17) as j's "schedule", when it was on.
void add_schedule_summary(JsonObject& j, const RunReport& rep);

class SceneRun {
 public:
  explicit SceneRun(std::string kind = "") : kind_(std::move(kind)) {}
  virtual ~SceneRun() = default;
  // Its measures, in the order of their series columns, and its fixes, in
  // the order they act (after the run's own).
  virtual std::vector<Observer*> observers() = 0;
  virtual std::vector<Fix*> fixes() { return {}; }
  // Both added to the run.
  void attach(Run& run);
  // summary.json of the run (status and message from the report). By
  // default: the kind, status, run figures and every observer's summary().
  virtual void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                             int threads) const;
  // The kind's other files (summary.json and series.csv aside), written at the end of run_scene.
  virtual void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {}
  // Names of the files a run writes, for the "results are in" lines: {label, file name}.
  virtual std::vector<std::pair<std::string, std::string>> files() const {
    return {{"summary", "summary.json"}, {"time series", "series.csv"}};
  }
  // Every file of files() removed from dir (created if missing): a run
  // killed before its end leaves no earlier run's outputs beside its own
  // partial ones (docs/files.md, outputs). run_scene calls it before the first step.
  void remove_earlier_outputs(const std::string& dir) const;
  // One line on the outcome, for the command line and the node's log.
  virtual std::string result_line(const Model& m, const State& s, const RunReport& rep) const = 0;

 protected:
  // The "run" block (grains, steps, simulated and wall time, dt, k_n,
  // threads) and the "observers" block (every measure's and fix's summary()) of summary.json.
  void add_run_and_observers(JsonObject& j, const Model& m, const RunReport& rep, int threads) const;
  // The head of a kind's summary.json: kind, scenario, file, status, and the message of a run that stopped.
  JsonObject summary_head(const std::string& scenario, const std::string& file, const RunReport& rep) const;

 private:
  std::string kind_;
};

// A scene made ready to run: the scenario as the run starts it, its start
// state and plan; begin() makes the observers of one run.
class Scene {
 public:
  virtual ~Scene() = default;
  virtual std::string kind() const = 0;
  Scenario sc;               // model, groups and settings at the start of the run
  State start;               // start state of the run
  RunPlan plan;              // stages of the run
  double sample_every = 0.01;  // s between series rows
  // Grains above this height are not bed: contacts with them do not count as
  // bed contacts (a lander's touches by ejecta), m.
  virtual double bed_top() const;
  // Observers and outputs of one run (whose model and state start as
  // sc.model and start); the caller adds the observers to the run.
  virtual std::unique_ptr<SceneRun> begin(Run& run) const = 0;
};

class SceneKind {
 public:
  virtual ~SceneKind() = default;
  // Name of the kind, and the top-level YAML block that selects it.
  virtual std::string name() const = 0;
  // Prepare the scene from the document (overrides applied), read from `file`.
  // Throws InputError for bad input, BlowUpError if a preparation run fails.
  virtual std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                         const SceneOptions& opt) const = 0;
};

// The registry: the built-in kinds and any added at run time (tests add
// their own).
void register_scene_kind(std::shared_ptr<const SceneKind> kind);

// The kinds the package is built with. Declared here, for the registry,
// and defined one layer up, by the kinds themselves: one line each in
// src/scenes/registry.cpp (their ROS topics: src/ros/scenes/registry.cpp).
// The run layer names no kind, so no include points up a layer.
std::vector<std::shared_ptr<const SceneKind>> builtin_scene_kinds();
std::vector<std::string> scene_kind_names();

// The kind a document asks for: the registered kind whose block it has, the
// plain scenario if none. Two kind blocks are refused, naming both.
const SceneKind& scene_kind_of(const YAML::Node& root, const std::string& file);

// Read a scene file with overrides ("dotted.key=yaml-value") and prepare it.
std::unique_ptr<Scene> load_scene(const std::string& file, const std::vector<std::string>& overrides,
                                  const SceneOptions& opt = {});

struct SceneRunOptions {
  std::string out_dir;          // empty: nothing written
  double progress_every = 2.0;  // wall seconds between progress lines (<= 0: none)
  bool stage_snapshots = false; // out_dir/<stage>.bed after every stage
  int threads = 0;              // recorded in the summary
  long max_steps = kDefaultMaxSteps;  // RunOptions::max_steps
};

// Run a prepared scene from state s (initially scene.start) to its end on
// model m (initially scene.sc.model), writing series.csv, summary.json and
// the kind's files into out_dir. `run` (if given) receives the scene run, for
// callers that read its observers afterwards.
RunReport run_scene(const Scene& scene, Model& m, State& s, const SceneRunOptions& opt,
                    std::unique_ptr<SceneRun>* run = nullptr);

// A kind's container keys checked against the geometry they describe
// (docs/scenes.md, "Input ranges"): `block`.rim (skipped when NaN) at least a
// grain diameter above the floor (the highest upward plane wall), and
// `block`.container_radius wider than a grain diameter, within the scene's
// vertical cylinder wall if it has one, and wider than `body`'s bounding
// sphere (skipped when body < 0). Throws InputError naming the keys.
void check_container(const Model& m, const std::string& file, const std::string& block, double rim,
                     double container_radius, int body);

// $REGOLITH_CACHE, else ~/.cache/regolith_twin.
std::string default_cache_dir();

}  // namespace rt
