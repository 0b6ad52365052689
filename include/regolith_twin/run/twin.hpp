// A running twin: one scene file (any kind) with its model, evolving state
// and the observers of its run, stepped one step at a time through the run
// loop (stages included), with the operations a front end needs (reset,
// checkpoints, setting a body's state, applying a wrench). ROS-free: the ROS
// node is a thin adapter over this class, and knows no scene kind.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/observers/body_contacts.hpp"
#include "regolith_twin/run/scene.hpp"

namespace rt {

struct TwinOptions {
  std::string file;                    // scene file
  std::vector<std::string> overrides;  // "dotted.key=yaml-value"
  SceneOptions scene;                  // bed cache and relaxation output
};

class Twin {
 public:
  // Throws InputError (bad file or value) or BlowUpError (bed relaxation).
  explicit Twin(const TwinOptions& opt);
  ~Twin();

  // Back to the start state of the scene.
  void reset();
  // One time step, with the run's stage actions and observers until the run
  // ends (plain steps after it). Throws BlowUpError; the state is then left as
  // the failed step had it.
  void step();

  const std::string& name() const { return scene_->sc.name; }
  const std::string& file() const { return file_; }
  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  int body_index(const std::string& name) const;  // -1 if there is none

  // The scene, its kind, and the current run (its observers).
  const Scene& scene() const { return *scene_; }
  std::string kind() const { return scene_->kind(); }
  const SceneRun& run() const { return *scene_run_; }
  // The run's report so far (steps counted from the start state).
  RunReport report() const;
  bool ended() const { return ended_; }  // the run reached its end (stages done, or an observer ended it)
  // One line on the outcome so far, and summary.json of the run (status and
  // message given: a front end that stopped on a blow-up says so).
  std::string result_line() const;
  void write_summary(const std::string& path, const std::string& status, const std::string& message,
                     int threads) const;
  // The scene kind's own files of the run so far into dir (the sampler's
  // collected.csv, ejecta.csv, ...; the landing's surface.csv), as the
  // command-line tools write them next to summary.json.
  void write_files(const std::string& dir) const;

  // Contacts of body b, with the bed top of this scene.
  BodyContacts contacts(int b) const;

  // Pose of the body's reference frame in the world, centre-of-mass velocity
  // and angular velocity (world). Contact lists are rebuilt at the next step.
  void set_body_state(int b, const Vec3& ref_pos, const Quat& ref_q, const Vec3& vel, const Vec3& omega);
  // Force and torque (world, at the centre of mass) until sim time `until`.
  void apply_wrench(int b, const Vec3& force, const Vec3& torque, double until);

  // The whole evolving state. A loaded state restarts the run's observers from it.
  void save(const std::string& path) const;
  void load(const std::string& path);
  // The same without the file: the checkpoint's bytes, and loading from
  // bytes read elsewhere (`source` names them in errors).
  std::string checkpoint_image() const;
  void load_image(const std::string& source, const std::string& data);

 private:
  void restart_run();
  std::string file_;
  long max_steps_ = kDefaultMaxSteps;  // of each run (TwinOptions::scene.max_steps)
  std::unique_ptr<Scene> scene_;
  Model model_;
  State state_;
  std::unique_ptr<Run> run_;
  std::unique_ptr<SceneRun> scene_run_;
  long step0_ = 0;
  bool ended_ = false;
  std::vector<double> wrench_until_;
};

}  // namespace rt
