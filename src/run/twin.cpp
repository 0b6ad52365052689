// A running twin (see twin.hpp).
#include "regolith_twin/run/twin.hpp"

#include <cmath>
#include <sstream>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {
std::string vec_text(const Vec3& v) {
  std::ostringstream os;
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}
}  // namespace

Twin::Twin(const TwinOptions& opt) : file_(opt.file), max_steps_(opt.scene.max_steps) {
  scene_ = load_scene(opt.file, opt.overrides, opt.scene);
  reset();
}

Twin::~Twin() = default;

void Twin::reset() {
  scene_run_.reset();
  run_.reset();
  model_ = scene_->sc.model;
  state_ = scene_->start;
  wrench_until_.clear();
  restart_run();
}

// A fresh run of the scene from the current state: observers prepared and
// started, forces primed, the first stage begun.
void Twin::restart_run() {
  scene_run_.reset();
  RunOptions ro;
  ro.progress_every = 0;
  ro.max_steps = max_steps_;
  run_ = std::make_unique<Run>(model_, state_, scene_->plan, ro);
  scene_run_ = scene_->begin(*run_);
  scene_run_->attach(*run_);
  step0_ = state_.step;
  ended_ = run_->ended();
  if (ended_) run_->finish();
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
  if (ended_) {
    rt::step(model_, state_);
    return;
  }
  run_->advance();
  if (run_->ended()) {
    ended_ = true;
    run_->finish();
  }
}

RunReport Twin::report() const {
  RunReport r = run_->report();
  r.steps = state_.step - step0_;
  r.sim_time = state_.time;
  return r;
}

std::string Twin::result_line() const { return scene_run_->result_line(model_, state_, report()); }

void Twin::write_summary(const std::string& path, const std::string& status, const std::string& message,
                         int threads) const {
  RunReport r = report();
  r.status = status;
  r.message = message;
  scene_run_->write_summary(path, model_, state_, r, threads);
}

void Twin::write_files(const std::string& dir) const { scene_run_->write_files(dir, model_, state_, report()); }

int Twin::body_index(const std::string& name) const {
  for (size_t b = 0; b < model_.bodies.size(); ++b)
    if (model_.bodies[b].name == name) return int(b);
  return -1;
}

BodyContacts Twin::contacts(int b) const { return body_contacts(state_, b, scene_->bed_top()); }

void Twin::set_body_state(int b, const Vec3& ref_pos, const Quat& ref_q, const Vec3& vel, const Vec3& omega) {
  const BodyModel& bm = model_.bodies.at(b);
  BodyState& bs = state_.bodies.at(b);
  const double qn = ref_q.norm();
  if (!ref_pos.allFinite() || !vel.allFinite() || !omega.allFinite() || !(qn > 1e-9) || !std::isfinite(qn))
    throw InputError("body '" + bm.name + "': the new state must be finite with a non-zero orientation (position " +
                     vec_text(ref_pos) + ", velocity " + vec_text(vel) + ", angular velocity " + vec_text(omega) + ")");
  // The bounds of a loaded state (docs/scenes.md, "Input ranges"): a step,
  // the neighbour grid and the published messages need values of a physical size.
  static_assert(kMaxCoordinate == 1e6 && kMaxStateSpeed == 1e6, "the message names these bounds");
  if (!(ref_pos.cwiseAbs().maxCoeff() <= kMaxCoordinate) || !(vel.cwiseAbs().maxCoeff() <= kMaxStateSpeed) ||
      !(omega.cwiseAbs().maxCoeff() <= kMaxStateSpeed))
    throw InputError("body '" + bm.name + "': position " + vec_text(ref_pos) + ", velocity " + vec_text(vel) +
                     ", angular velocity " + vec_text(omega) +
                     ": allowed components within 1e6 m, 1e6 m/s and 1e6 rad/s");
  const Quat q_ref = ref_q.normalized();
  bs.q = (q_ref * bm.ref_rot).normalized();
  bs.pos = ref_pos + q_ref * bm.ref_pos;
  bs.vel_mid = vel;
  bs.omega_mid = omega;
  set_body_velocity(bm, bs, vel, omega);
  state_.forces_valid = false;  // lists and forces for the new pose at the next step
  state_.rebuild_requested = true;
  if (run_) run_->state_edited();
}

void Twin::apply_wrench(int b, const Vec3& force, const Vec3& torque, double until) {
  const BodyModel& bm = model_.bodies.at(b);
  // A push must keep the body's accelerations physical: at most 1e6 m/s^2
  // and 1e6 rad/s^2 (the state bounds reached in one second).
  const double a = force.norm() / bm.mass, alpha = torque.norm() / bm.inertia.minCoeff();
  if (!force.allFinite() || !torque.allFinite() || !(a <= kMaxStateSpeed) || !(alpha <= kMaxStateSpeed))
    throw InputError("body '" + bm.name + "': force " + vec_text(force) + " N and torque " + vec_text(torque) +
                     " N m give accelerations of " + YamlReader::num_text(a) + " m/s^2 and " + YamlReader::num_text(alpha) +
                     " rad/s^2: allowed up to 1e6 each (|F| <= " + YamlReader::num_text(kMaxStateSpeed * bm.mass) +
                     " N, |torque| <= " + YamlReader::num_text(kMaxStateSpeed * bm.inertia.minCoeff()) + " N m)");
  if (!(until >= state_.time) || !(until <= kMaxStateTime))
    throw InputError("body '" + bm.name + "': the push would end at t = " + YamlReader::num_text(until) +
                     " s: allowed up to 1e9 s");
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

std::string Twin::checkpoint_image() const { return rt::checkpoint_image(model_, state_); }

void Twin::load(const std::string& path) { load_image(path, read_checkpoint_file(path)); }

void Twin::load_image(const std::string& source, const std::string& data) {
  State loaded = state_from_checkpoint(source, data, scene_->sc.model);
  scene_run_.reset();
  run_.reset();
  model_ = scene_->sc.model;
  state_ = std::move(loaded);
  wrench_until_.clear();
  restart_run();
}

}  // namespace rt
