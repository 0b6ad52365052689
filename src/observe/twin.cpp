// A running twin (see twin.hpp).
#include "regolith_twin/observe/twin.hpp"

#include <yaml-cpp/yaml.h>

#include <limits>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/scene/checkpoint.hpp"

namespace rt {

Twin::Twin(const TwinOptions& opt) : file_(opt.file) {
  const YAML::Node root = load_document(opt.file, opt.overrides);
  if (root["landing"]) {
    landing_ = std::make_unique<LandingScene>(prepare_landing(opt.file, opt.overrides, opt.landing));
    start_model_ = landing_->sc.model;
    start_state_ = landing_->start;
    name_ = landing_->sc.name;
  } else {
    Scenario sc = parse_scenario(root, opt.file);
    start_model_ = sc.model;
    start_state_ = sc.initial;
    name_ = sc.name;
  }
  reset();
}

Twin::~Twin() = default;

void Twin::reset() {
  observer_.reset();
  model_ = start_model_;
  state_ = start_state_;
  wrench_until_.clear();
  restart_observer();
}

void Twin::restart_observer() {
  observer_.reset();
  ended_ = false;
  final_ = LandingOutcome();
  if (landing_) observer_ = std::make_unique<LandingObserver>(model_, state_, landing_->lander, landing_->run_spec);
  if (!state_.forces_valid) prime(model_, state_);
}

void Twin::step() {
  if (!wrench_until_.empty()) {
    bool any = false;
    for (size_t b = 0; b < wrench_until_.size(); ++b) {
      if (state_.time >= wrench_until_[b] - 0.5 * model_.dt) {
        state_.body_applied_force[b].setZero();
        state_.body_applied_torque[b].setZero();
      } else {
        any = true;
      }
    }
    if (!any) {
      wrench_until_.clear();
      state_.body_applied_force.clear();
      state_.body_applied_torque.clear();
    }
  }
  rt::step(model_, state_);
  if (observer_ && !ended_ && observer_->observe()) {
    ended_ = true;
    final_ = observer_->finish();
    final_.steps = state_.step - start_state_.step;
  }
}

int Twin::body_index(const std::string& name) const {
  for (size_t b = 0; b < model_.bodies.size(); ++b)
    if (model_.bodies[b].name == name) return int(b);
  return -1;
}

LandingOutcome Twin::outcome() const {
  if (ended_) return final_;
  return observer_ ? observer_->outcome() : LandingOutcome();
}

const char* Twin::phase() const {
  if (!observer_) return "";
  return ended_ ? "ended" : observer_->tracker().phase();
}

double Twin::bed_top() const {
  return observer_ ? observer_->bed_top() : std::numeric_limits<double>::infinity();
}

double Twin::lowest_corner() const {
  return observer_ ? observer_->tracker().lowest_corner(state_.bodies[landing_->lander]) : 0.0;
}

BodyContacts Twin::contacts(int b) const { return body_contacts(state_, b, bed_top()); }

void Twin::set_body_state(int b, const Vec3& ref_pos, const Quat& ref_q, const Vec3& vel, const Vec3& omega) {
  const BodyModel& bm = model_.bodies.at(b);
  BodyState& bs = state_.bodies.at(b);
  const Quat q_ref = ref_q.normalized();
  bs.q = (q_ref * bm.ref_rot).normalized();
  bs.pos = ref_pos + q_ref * bm.ref_pos;
  bs.vel_mid = vel;
  bs.omega_mid = omega;
  set_body_velocity(bm, bs, vel, omega);
  state_.forces_valid = false;  // lists and forces for the new pose at the next step
  state_.rebuild_requested = true;
}

void Twin::apply_wrench(int b, const Vec3& force, const Vec3& torque, double until) {
  const size_t n = model_.bodies.size();
  if (state_.body_applied_force.size() != n) {
    state_.body_applied_force.assign(n, Vec3::Zero());
    state_.body_applied_torque.assign(n, Vec3::Zero());
    wrench_until_.assign(n, 0.0);
  }
  state_.body_applied_force.at(b) = force;
  state_.body_applied_torque.at(b) = torque;
  wrench_until_.at(b) = until;
}

void Twin::save(const std::string& path) const { save_checkpoint(path, model_, state_); }

void Twin::load(const std::string& path) {
  State loaded = load_checkpoint(path, start_model_);
  observer_.reset();
  model_ = start_model_;
  state_ = std::move(loaded);
  wrench_until_.clear();
  restart_observer();
}

}  // namespace rt
