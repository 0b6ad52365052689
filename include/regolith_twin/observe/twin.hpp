// A running twin: one scenario (or landing) file with its model, evolving
// state and observers, stepped one step at a time, with the operations a
// front end needs (reset, checkpoints, setting a body's state, applying a
// wrench). ROS-free: the ROS node is a thin adapter over this class.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/observe/landing.hpp"
#include "regolith_twin/observe/landing_scene.hpp"
#include "regolith_twin/scene/scenario.hpp"

namespace rt {

struct TwinOptions {
  std::string file;                    // scenario file; with a `landing:` block it is a landing
  std::vector<std::string> overrides;  // "dotted.key=yaml-value"
  LandingSetupOptions landing;         // bed cache and relaxation output of landings
};

class Twin {
 public:
  // Throws InputError (bad file or value) or BlowUpError (bed relaxation).
  explicit Twin(const TwinOptions& opt);
  ~Twin();

  // Back to the start state (relaxed bed, lander placed; the scenario's initial state otherwise).
  void reset();
  // One time step and the observers. Throws BlowUpError; the state is then
  // left as the failed step had it.
  void step();

  const std::string& name() const { return name_; }
  const std::string& file() const { return file_; }
  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  int body_index(const std::string& name) const;  // -1 if there is none

  // Lander scenes.
  bool is_landing() const { return landing_ != nullptr; }
  int lander() const { return is_landing() ? landing_->lander : -1; }
  bool ended() const { return ended_; }            // the landing reached its run end
  LandingOutcome outcome() const;                  // so far; the final one once ended
  const char* phase() const;                       // approach | collision | flight | ended ("" if no lander)
  double bed_top() const;                          // grains above this are not bed (lander scenes), m
  const LandingScene* landing_scene() const { return landing_.get(); }
  double lowest_corner() const;                    // of the lander, above the trim plane, m

  // Contacts of body b with the bed top of this scene.
  BodyContacts contacts(int b) const;

  // Pose of the body's reference frame in the world, centre-of-mass velocity
  // and angular velocity (world). Contact lists are rebuilt at the next step.
  void set_body_state(int b, const Vec3& ref_pos, const Quat& ref_q, const Vec3& vel, const Vec3& omega);
  // Force and torque (world, at the centre of mass) until sim time `until`.
  void apply_wrench(int b, const Vec3& force, const Vec3& torque, double until);

  // The whole evolving state. A loaded state restarts the landing observer from it.
  void save(const std::string& path) const;
  void load(const std::string& path);

 private:
  void restart_observer();
  std::string file_, name_;
  std::unique_ptr<LandingScene> landing_;
  Model start_model_, model_;
  State start_state_, state_;
  std::unique_ptr<LandingObserver> observer_;
  LandingOutcome final_;
  bool ended_ = false;
  std::vector<double> wrench_until_;
};

}  // namespace rt
