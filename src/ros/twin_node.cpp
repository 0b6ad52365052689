// The ROS adapter over rt::Twin (see twin_node.hpp and docs/ros.md).
#include "regolith_twin/ros/twin_node.hpp"
#include "regolith_twin/core/hold.hpp"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/BodyStates.h"
#include "regolith_twin/Contacts.h"
#include "regolith_twin/Status.h"
#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/data_file.hpp"

namespace rt_ros {
namespace {

using rt::Quat;
using rt::Vec3;

// Eigen <-> message conversions of tf2_eigen, under short names.
geometry_msgs::Point to_point(const Vec3& v) { return tf2::toMsg(v); }
geometry_msgs::Vector3 to_vector(const Vec3& v) {
  geometry_msgs::Vector3 out;
  return tf2::toMsg(v, out);
}
geometry_msgs::Quaternion to_quat(const Quat& q) { return tf2::toMsg(q); }
Vec3 from_vector(const geometry_msgs::Vector3& v) {
  Vec3 out;
  tf2::fromMsg(v, out);
  return out;
}

std::string frame_of(const rt::BodyModel& b, const std::string& link) {
  return b.name + "/" + (link.empty() ? std::string("base") : link);
}

double param_number(const ros::NodeHandle& pnh, const std::string& name, double def, double lo, double hi) {
  if (!pnh.hasParam(name)) return def;
  double v = 0;
  int iv = 0;
  if (!pnh.getParam(name, v)) {
    if (!pnh.getParam(name, iv))
      throw std::invalid_argument("parameter ~" + name + ": expected a number in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "]");
    v = iv;
  }
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument("parameter ~" + name + " = " + std::to_string(v) + ": allowed range [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

bool param_bool(const ros::NodeHandle& pnh, const std::string& name, bool def) {
  if (!pnh.hasParam(name)) return def;
  bool v = def;
  if (!pnh.getParam(name, v)) throw std::invalid_argument("parameter ~" + name + ": expected true or false");
  return v;
}

std::string param_text(const ros::NodeHandle& pnh, const std::string& name, const std::string& def) {
  if (!pnh.hasParam(name)) return def;
  std::string v;
  if (!pnh.getParam(name, v)) throw std::invalid_argument("parameter ~" + name + ": expected a string");
  return v;
}

}  // namespace

NodeParams read_params(const ros::NodeHandle& pnh) {
  NodeParams p;
  p.scenario_file = param_text(pnh, "scenario_file", "");
  if (p.scenario_file.empty())
    throw std::invalid_argument("parameter ~scenario_file is missing: give the scenario or landing YAML file");
  if (!std::ifstream(p.scenario_file).good())
    throw std::invalid_argument("parameter ~scenario_file: cannot read '" + p.scenario_file + "'");
  if (pnh.hasParam("set")) {
    XmlRpc::XmlRpcValue v;
    pnh.getParam("set", v);
    if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
      const std::string s = v;
      if (!s.empty()) p.overrides.push_back(s);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeArray) {
      for (int i = 0; i < v.size(); ++i) {
        if (v[i].getType() != XmlRpc::XmlRpcValue::TypeString)
          throw std::invalid_argument("parameter ~set: expected a list of \"dotted.key=value\" strings");
        p.overrides.push_back(static_cast<std::string>(v[i]));
      }
    } else {
      throw std::invalid_argument("parameter ~set: expected a list of \"dotted.key=value\" strings");
    }
  }
  p.realtime_factor = param_number(pnh, "realtime_factor", 0, -1e9, 1e9);
  p.clock_rate = param_number(pnh, "clock_rate", 100, 1e-3, 1e6);
  p.status_rate = param_number(pnh, "status_rate", 10, 1e-3, 1e3);
  p.body_state_rate = param_number(pnh, "body_state_rate", 0, 0, 1e9);
  p.contacts_rate = param_number(pnh, "contacts_rate", 100, 0, 1e9);
  p.particles_rate = param_number(pnh, "particles_rate", 5, 1e-3, 1e3);
  p.markers_rate = param_number(pnh, "markers_rate", 1, 1e-3, 1e3);
  const std::string vc = param_text(pnh, "visual_clock", "wall");
  if (vc != "wall" && vc != "sim") throw std::invalid_argument("parameter ~visual_clock = '" + vc + "': allowed wall or sim");
  p.visual_sim_clock = vc == "sim";
  p.max_contact_points = int(param_number(pnh, "max_contact_points", 32, 0, 10000));
  p.out_dir = param_text(pnh, "out_dir", "");
  p.cache_dir = param_text(pnh, "cache_dir", "");
  p.start_paused = param_bool(pnh, "start_paused", false);
  p.shutdown_at_end = param_bool(pnh, "shutdown_at_end", false);
  p.wait_for_recorder = param_bool(pnh, "wait_for_recorder", false);
  p.threads = int(param_number(pnh, "threads", 0, 0, 256));
  p.max_step_wall = param_number(pnh, "max_step_wall", 600, 1e-3, 1e7);
  p.checkpoint_dir = param_text(pnh, "checkpoint_dir", "");
  p.io_timeout = param_number(pnh, "io_timeout", 30, 1e-3, 1e5);
  p.max_steps = long(param_number(pnh, "max_steps", 0, 0, 1e15));
  return p;
}

std::string checkpoint_dir(const NodeParams& p) {
  if (!p.checkpoint_dir.empty()) return p.checkpoint_dir;
  if (!p.out_dir.empty()) return p.out_dir + "/checkpoints";
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  return (ros_home ? std::string(ros_home) : std::string(home ? home : ".") + "/.ros") + "/regolith_twin/checkpoints";
}

TwinNode::TwinNode(ros::NodeHandle nh, ros::NodeHandle pnh, const NodeParams& p) : nh_(nh), pnh_(pnh), p_(p) {
#ifdef _OPENMP
  if (p_.threads > 0) omp_set_num_threads(p_.threads);
#endif
  // The output folder is taken (and checked) before the scene is prepared, not at the run's end.
  if (!p_.out_dir.empty()) out_folder_ = std::make_unique<rt::OutputFolder>(p_.out_dir);
  rt::TwinOptions to;
  to.file = p_.scenario_file;
  to.overrides = p_.overrides;
  to.scene.cache_dir = p_.cache_dir;
  to.scene.quiet = false;
  // An interactive twin steps on request, is paused and cancelled from
  // outside, and may run an endless scene: no limit unless one is asked for.
  to.scene.max_steps = p_.max_steps > 0 ? p_.max_steps : std::numeric_limits<long>::max();
  checkpoint_dir_ = checkpoint_dir(p_);
  twin_ = std::make_unique<rt::Twin>(to);
  paused_ = p_.start_paused || p_.wait_for_recorder;
  waiting_for_recorder_ = p_.wait_for_recorder && !p_.start_paused;

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  // A deep queue: body states go out every step, and a recorder must not lose one.
  body_pub_ = pnh_.advertise<regolith_twin::BodyStates>("body_states", 20000);
  contacts_pub_ = pnh_.advertise<regolith_twin::Contacts>("contacts", 10);
  status_pub_ = pnh_.advertise<regolith_twin::Status>("status", 10);
  particles_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("particles", 2);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 2, true);
  contact_markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("contact_markers", 10);
  diag_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);

  services_.push_back(pnh_.advertiseService("pause", &TwinNode::on_pause, this));
  services_.push_back(pnh_.advertiseService("unpause", &TwinNode::on_unpause, this));
  services_.push_back(pnh_.advertiseService("reset", &TwinNode::on_reset, this));
  services_.push_back(pnh_.advertiseService("step", &TwinNode::on_step, this));
  {
    ros::NodeHandle io(pnh_);
    io.setCallbackQueue(&io_queue_);
    services_.push_back(io.advertiseService("save_checkpoint", &TwinNode::on_save, this));
    services_.push_back(io.advertiseService("load_checkpoint", &TwinNode::on_load, this));
  }
  services_.push_back(pnh_.advertiseService("set_body_state", &TwinNode::on_set_body_state, this));
  services_.push_back(pnh_.advertiseService("apply_body_wrench", &TwinNode::on_apply_wrench, this));

  // robot_description of every URDF body, in the body's namespace.
  for (const rt::BodyModel& b : twin_->model().bodies) {
    if (b.urdf_file.empty()) continue;
    std::ifstream f(b.urdf_file);
    std::stringstream ss;
    ss << f.rdbuf();
    nh_.setParam(b.name + "/robot_description", ss.str());
  }
  topics_ = make_scene_topics(twin_->kind(), pnh_, *twin_);
  start_wall_ = WallClock::now();
  publish_static();
}

TwinNode::~TwinNode() { stop(); }

void TwinNode::start() {
  if (running_) return;
  running_ = true;
  reset_pacing();
  {
    std::lock_guard<std::mutex> lk(mu_);
    after_step(true);
  }
  thread_ = std::thread([this] { loop(); });
  io_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &io_queue_);
  io_spinner_->start();
}

void TwinNode::stop() {
  if (io_spinner_) io_spinner_->stop();
  running_ = false;
  cv_.notify_all();
  step_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

double TwinNode::sim_time() {
  std::lock_guard<std::mutex> lk(mu_);
  return twin_->state().time;
}
double TwinNode::dt() {
  std::lock_guard<std::mutex> lk(mu_);
  return twin_->model().dt;
}
bool TwinNode::paused() {
  std::lock_guard<std::mutex> lk(mu_);
  return paused_;
}
bool TwinNode::ended() {
  std::lock_guard<std::mutex> lk(mu_);
  return twin_->ended();
}

void TwinNode::reset_pacing() {
  pace_wall0_ = WallClock::now();
  pace_sim0_ = twin_->state().time;
}

void TwinNode::loop() {
#ifdef _OPENMP
  if (p_.threads > 0) omp_set_num_threads(p_.threads);  // per thread: this one steps the engine
#endif
  while (running_ && ros::ok()) {
    std::unique_lock<std::mutex> lk(mu_);
    if (waiting_for_recorder_ && paused_) {
      // A recorder is connected once both publishers count a subscriber; the
      // second of grace lets it open its bag on the paused node's status
      // messages, so that it has every step from the first.
      if (body_pub_.getNumSubscribers() > 0 && status_pub_.getNumSubscribers() > 0) {
        if (!recorder_seen_set_) {
          recorder_seen_set_ = true;
          recorder_seen_ = WallClock::now();
          ROS_INFO("twin_node: recorder connected; starting in 1 s");
        } else if (WallClock::now() - recorder_seen_ >= std::chrono::seconds(1)) {
          waiting_for_recorder_ = false;
          paused_ = false;
          reset_pacing();
        }
      }
    }
    if ((paused_ || failed_) && pending_steps_ == 0) {
      cv_.wait_for(lk, std::chrono::milliseconds(50));
      // A paused twin keeps /clock and status alive (wall-time throttled).
      const auto now = WallClock::now();
      if (now - last_clock_wall_ >= std::chrono::milliseconds(100)) publish_clock();
      if (std::chrono::duration<double>(now - last_status_wall_).count() >= 1.0 / p_.status_rate) publish_status();
      reset_pacing();
      continue;
    }
    try {
      twin_->step();
    } catch (const rt::BlowUpError& e) {
      failed_ = true;
      paused_ = true;
      failure_ = e.what();
      pending_steps_ = 0;
      pending_until_ = -1;
      step_cv_.notify_all();
      ROS_ERROR("twin_node: %s (the run is stopped; reset or load a checkpoint to go on)", e.what());
      publish_diagnostics(diagnostic_msgs::DiagnosticStatus::ERROR, failure_);
      // The failed step's state is not published: the topics keep the last
      // sound values (docs/ros.md); /clock and ~status say where it stopped.
      publish_clock();
      publish_status();
      on_end();
      continue;
    }
    if (pending_steps_ > 0) {
      if (pending_until_ >= 0) {  // a span of simulated time: done once the next step would pass its end
        if (twin_->state().time >= pending_until_ - 0.5 * twin_->model().dt) pending_steps_ = 0;
      } else {
        --pending_steps_;
      }
      if (pending_steps_ == 0) {
        pending_until_ = -1;
        step_cv_.notify_all();
      }
    }
    after_step(false);
    if (twin_->ended() && !end_handled_) on_end();
    lk.unlock();
    if (p_.realtime_factor > 0 && pending_steps_ == 0) {
      const double ahead = (twin_->state().time - pace_sim0_) / p_.realtime_factor -
                           std::chrono::duration<double>(WallClock::now() - pace_wall0_).count();
      if (ahead > 0) std::this_thread::sleep_for(std::chrono::duration<double>(std::min(ahead, 0.1)));
    }
  }
}

void TwinNode::on_end() {
  end_handled_ = true;
  ROS_INFO("twin_node: run ended%s: %s", failed_ ? " (blow-up)" : "", twin_->result_line().c_str());
  if (!p_.out_dir.empty()) {
    int threads = 0;
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    try {
      twin_->write_files(p_.out_dir);
      twin_->write_summary(p_.out_dir + "/summary.json", failed_ ? "blow_up" : "ok", failure_, threads);
      ROS_INFO("twin_node: summary and the scene's files written to %s", p_.out_dir.c_str());
    } catch (const std::exception& e) {
      ROS_ERROR("twin_node: cannot write the run's files to %s: %s", p_.out_dir.c_str(), e.what());
    }
  }
  if (!failed_) {
    topics_->on_end(*twin_);
    // The final grains, whatever the particle rate (a recording ends with the run's last state).
    if (particles_pub_.getNumSubscribers() > 0) publish_particles();
  }
  paused_ = true;  // stays up for inspection; unpause steps on past the run end
  if (p_.shutdown_at_end) ros::requestShutdown();
}

// Publications after a step, each on its own clock (called with mu_ held).
void TwinNode::after_step(bool force) {
  const double t = twin_->state().time;
  const auto now = WallClock::now();
  const bool clock_due = force || t - last_clock_sim_ >= 1.0 / p_.clock_rate - 1e-12 ||
                         now - last_clock_wall_ >= std::chrono::milliseconds(100);
  if (clock_due) {
    publish_clock();
    publish_tf();
  }
  if (force || p_.body_state_rate <= 0 || t - last_body_sim_ >= 1.0 / p_.body_state_rate - 1e-12) {
    last_body_sim_ = t;
    publish_body_states();
  }
  if ((contacts_pub_.getNumSubscribers() > 0 || contact_markers_pub_.getNumSubscribers() > 0) &&
      (force || p_.contacts_rate <= 0 || t - last_contacts_sim_ >= 1.0 / p_.contacts_rate - 1e-12)) {
    last_contacts_sim_ = t;
    publish_contacts();
  }
  topics_->after_step(*twin_, clock_due, force);
  if (force || std::chrono::duration<double>(now - last_status_wall_).count() >= 1.0 / p_.status_rate)
    publish_status();
  const double vis_now = p_.visual_sim_clock ? t : std::chrono::duration<double>(now - start_wall_).count();
  if (particles_pub_.getNumSubscribers() > 0 && (force || vis_now - last_particles_ >= 1.0 / p_.particles_rate - 1e-12)) {
    last_particles_ = vis_now;
    publish_particles();
  }
  if (force || vis_now - last_markers_ >= 1.0 / p_.markers_rate - 1e-12) {
    last_markers_ = vis_now;
    if (markers_pub_.getNumSubscribers() > 0 || force) publish_markers();
  }
  if (std::chrono::duration<double>(now - last_diag_wall_).count() >= 1.0) {
    const rt::StepStats& st = twin_->state().stats;
    const double limit = twin_->model().guards.max_overlap_ratio;
    if (failed_)
      publish_diagnostics(diagnostic_msgs::DiagnosticStatus::ERROR, failure_);
    else if (st.max_overlap_ratio > 0.5 * limit)
      publish_diagnostics(diagnostic_msgs::DiagnosticStatus::WARN, "overlap above half the guard limit");
    else
      publish_diagnostics(diagnostic_msgs::DiagnosticStatus::OK, "running");
  }
}

void TwinNode::publish_clock() {
  rosgraph_msgs::Clock c;
  c.clock = stamp(twin_->state().time);
  clock_pub_.publish(c);
  last_clock_sim_ = twin_->state().time;
  last_clock_wall_ = WallClock::now();
}

void TwinNode::publish_tf() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  std::vector<geometry_msgs::TransformStamped> out;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const rt::BodyModel& bm = m.bodies[b];
    const rt::BodyState& bs = s.bodies[b];
    const Quat q = rt::reference_rotation(bm, bs.q);
    const Vec3 p = rt::reference_position(bm, bs.pos, bs.q);
    geometry_msgs::TransformStamped tr;
    tr.header.stamp = stamp(s.time);
    tr.header.frame_id = "world";
    tr.child_frame_id = frame_of(bm, bm.ref_frame);
    tr.transform.translation = to_vector(p);
    tr.transform.rotation = to_quat(q);
    out.push_back(tr);
  }
  if (!out.empty()) tf_.sendTransform(out);
}

void TwinNode::publish_static() {
  std::vector<geometry_msgs::TransformStamped> out;
  const rt::Model& m = twin_->model();
  for (const rt::BodyModel& bm : m.bodies)
    for (const rt::BodyFrame& f : bm.frames) {
      if (f.parent.empty()) continue;
      geometry_msgs::TransformStamped tr;
      tr.header.stamp = stamp(twin_->state().time);
      tr.header.frame_id = frame_of(bm, f.parent);
      tr.child_frame_id = frame_of(bm, f.name);
      tr.transform.translation = to_vector(f.pos);
      tr.transform.rotation = to_quat(f.rot);
      out.push_back(tr);
    }
  // A gravity frame when g is tilted: its -z axis along gravity.
  const Vec3 g = m.gravity;
  if (g.norm() > 0 && std::fabs(g.normalized().z() + 1) > 1e-12) {
    geometry_msgs::TransformStamped tr;
    tr.header.stamp = stamp(twin_->state().time);
    tr.header.frame_id = "world";
    tr.child_frame_id = "gravity";
    tr.transform.rotation = to_quat(Quat::FromTwoVectors(Vec3(0, 0, -1), g.normalized()));
    out.push_back(tr);
  }
  if (!out.empty()) static_tf_.sendTransform(out);
}

void TwinNode::publish_body_states() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  regolith_twin::BodyStates msg;
  msg.header.stamp = stamp(s.time);
  msg.header.frame_id = "world";
  msg.step = s.step;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const rt::BodyModel& bm = m.bodies[b];
    const rt::BodyState& bs = s.bodies[b];
    regolith_twin::BodyState o;
    o.name = bm.name;
    o.pose.position = to_point(rt::reference_position(bm, bs.pos, bs.q));
    o.pose.orientation = to_quat(rt::reference_rotation(bm, bs.q));
    o.center_of_mass = to_point(bs.pos);
    o.twist.linear = to_vector(bs.vel);
    o.twist.angular = to_vector(bs.omega);
    o.wrench.force = to_vector(bs.force);
    o.wrench.torque = to_vector(bs.torque);
    const rt::BodyContacts c = twin_->contacts(int(b));
    o.contacts = uint32_t(c.total);
    o.bed_contacts = uint32_t(c.bed);
    msg.bodies.push_back(o);
  }
  body_pub_.publish(msg);
}

void TwinNode::publish_contacts() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  regolith_twin::Contacts msg;
  msg.header.stamp = stamp(s.time);
  msg.header.frame_id = "world";
  struct Pt {
    double depth;
    Vec3 point, normal;
  };
  std::vector<Pt> pts;
  // One pair's message: its wrench, its point count and its deepest points.
  auto pack = [&](const std::string& body, const std::string& other, const Vec3& f, const Vec3& tq) {
    regolith_twin::BodyContact bc;
    bc.body = body;
    bc.other = other;
    bc.wrench.force = to_vector(f);
    bc.wrench.torque = to_vector(tq);
    bc.count = uint32_t(pts.size());
    const size_t keep = std::min(pts.size(), size_t(p_.max_contact_points));
    std::partial_sort(pts.begin(), pts.begin() + keep, pts.end(),
                      [](const Pt& x, const Pt& y) { return x.depth > y.depth; });
    for (size_t k = 0; k < keep; ++k) {
      bc.points.push_back(to_point(pts[k].point));
      bc.normals.push_back(to_vector(pts[k].normal));
      bc.depths.push_back(pts[k].depth);
    }
    return bc;
  };
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const rt::BodyModel& bm = m.bodies[b];
    const rt::BodyState& bs = s.bodies[b];
    // Grains: the body's contact wrench less its body–body part.
    Vec3 f = bs.force, tq = bs.torque;
    for (const rt::BodyPointContact& c : s.body_points) {
      if (c.a == int(b)) {
        f -= c.force_a;
        tq -= (c.point - bs.pos).cross(c.force_a);
      } else if (c.b == int(b)) {
        f += c.force_a;
        tq += (c.point - bs.pos).cross(c.force_a);
      }
    }
    pts.clear();
    const rt::BodyGrainList& bl = s.body_grains;
    for (int k = 0; k < bl.size(); ++k) {
      if (!bl.touching[k] || bl.body[k] != int(b)) continue;
      const Vec3 p = bs.q.conjugate() * (s.pos[bl.grain[k]] - bs.pos);
      const rt::ShapeGap g = rt::shape_gap(bm, bm.shapes[bl.shape[k]], p, m.grain_radius[bl.grain[k]]);
      pts.push_back({std::max(0.0, g.overlap), bs.pos + bs.q * g.point, bs.q * g.n});
    }
    if (!pts.empty()) msg.contacts.push_back(pack(bm.name, "grains", f, tq));
  }
  // Body pairs.
  for (size_t a = 0; a < m.bodies.size(); ++a)
    for (size_t b = a + 1; b < m.bodies.size(); ++b) {
      Vec3 f = Vec3::Zero(), tq = Vec3::Zero();
      const Vec3 ca = s.bodies[a].pos;
      pts.clear();
      for (const rt::BodyPointContact& c : s.body_points) {
        if (!((c.a == int(a) && c.b == int(b)) || (c.a == int(b) && c.b == int(a)))) continue;
        const double sign = c.a == int(a) ? 1.0 : -1.0;  // force on a
        f += sign * c.force_a;
        tq += (c.point - ca).cross(sign * c.force_a);
        pts.push_back({c.overlap, c.point, -sign * c.normal});  // into a
      }
      if (!pts.empty()) msg.contacts.push_back(pack(m.bodies[a].name, m.bodies[b].name, f, tq));
    }
  contacts_pub_.publish(msg);
  if (contact_markers_pub_.getNumSubscribers() == 0) return;
  // One arrow per pair at the mean listed point, along the force on the body
  // (length saturating: 0.3 m * |F| / (|F| + 0.01 N)).
  visualization_msgs::MarkerArray arr;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  arr.markers.push_back(clear);
  int id = 0;
  for (const auto& bc : msg.contacts) {
    if (bc.points.empty()) continue;
    Vec3 c = Vec3::Zero();
    for (const auto& p : bc.points) c += Vec3(p.x, p.y, p.z);
    c /= double(bc.points.size());
    const Vec3 f = from_vector(bc.wrench.force);
    const double n = f.norm();
    if (!(n > 0)) continue;
    visualization_msgs::Marker mk;
    mk.header = msg.header;
    mk.ns = "contact_wrench";
    mk.id = id++;
    mk.type = visualization_msgs::Marker::ARROW;
    mk.action = visualization_msgs::Marker::ADD;
    mk.pose.orientation.w = 1;
    mk.points.push_back(to_point(c));
    mk.points.push_back(to_point(c + f / n * (0.3 * n / (n + 0.01))));
    mk.scale.x = 0.01;
    mk.scale.y = 0.02;
    mk.scale.z = 0.03;
    mk.color.r = 1.0f;
    mk.color.g = 0.2f;
    mk.color.b = 0.2f;
    mk.color.a = 1.0f;
    arr.markers.push_back(mk);
  }
  contact_markers_pub_.publish(arr);
}

void TwinNode::publish_status() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  const auto now = WallClock::now();
  const double wall = std::chrono::duration<double>(now - last_status_wall_).count();
  regolith_twin::Status msg;
  msg.header.stamp = stamp(s.time);
  msg.sim_time = s.time;
  msg.step = s.step;
  msg.dt = m.dt;
  if (wall > 0 && wall < 1e6) {
    msg.realtime_factor = (s.time - status_sim0_) / wall;
    msg.steps_per_second = double(s.step - status_step0_) / wall;
  }
  msg.paused = paused_;
  msg.grains = uint32_t(m.n_grains);
  uint32_t frozen = 0;
  for (int i = 0; i < m.n_grains; ++i) frozen += held(m, i);
  msg.frozen_grains = frozen;
  msg.active_grains = uint32_t(m.n_grains) - frozen;
  if (!failed_) {
    status_overlap_ = s.stats.max_overlap_ratio;
    status_ke_ = rt::kinetic_energy(m, s);
  }
  msg.max_overlap_ratio = status_overlap_;
  msg.kinetic_energy = status_ke_;
  status_pub_.publish(msg);
  last_status_wall_ = now;
  status_sim0_ = s.time;
  status_step0_ = s.step;
}

void TwinNode::publish_particles() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = stamp(s.time);
  cloud.header.frame_id = "world";
  sensor_msgs::PointCloud2Modifier mod(cloud);
  mod.setPointCloud2Fields(6, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z",
                           1, sensor_msgs::PointField::FLOAT32, "radius", 1, sensor_msgs::PointField::FLOAT32, "speed",
                           1, sensor_msgs::PointField::FLOAT32, "id", 1, sensor_msgs::PointField::UINT32);
  mod.resize(size_t(m.n_grains));
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z"), r(cloud, "radius"),
      v(cloud, "speed");
  sensor_msgs::PointCloud2Iterator<uint32_t> id(cloud, "id");
  for (int i = 0; i < m.n_grains; ++i, ++x, ++y, ++z, ++r, ++v, ++id) {
    *x = float(s.pos[i].x());
    *y = float(s.pos[i].y());
    *z = float(s.pos[i].z());
    *r = float(m.grain_radius[i]);
    *v = float(s.vel[i].norm());
    *id = uint32_t(i);
  }
  particles_pub_.publish(cloud);
}

void TwinNode::publish_markers() {
  const rt::Model& m = twin_->model();
  const rt::State& s = twin_->state();
  visualization_msgs::MarkerArray arr;
  int id = 0;
  auto base = [&](const std::string& ns, int type) {
    visualization_msgs::Marker mk;
    mk.header.stamp = stamp(s.time);
    mk.header.frame_id = "world";
    mk.ns = ns;
    mk.id = id++;
    mk.type = type;
    mk.action = visualization_msgs::Marker::ADD;
    mk.pose.orientation.w = 1;
    mk.color.a = 1;
    return mk;
  };
  // Walls: cylinders as translucent tubes, planes as thin squares.
  for (const rt::Wall& w : m.walls) {
    if (w.type == rt::WallType::Cylinder) {
      auto mk = base("walls", visualization_msgs::Marker::CYLINDER);
      const double len = w.length > 0 ? w.length : 0.5;
      mk.pose.position = to_point(w.origin + w.axis * (0.5 * len));
      mk.pose.orientation = to_quat(Quat::FromTwoVectors(Vec3::UnitZ(), w.axis));
      mk.scale.x = mk.scale.y = 2 * w.radius;
      mk.scale.z = len;
      mk.color.r = mk.color.g = mk.color.b = 0.6f;
      mk.color.a = 0.15f;
      arr.markers.push_back(mk);
    } else if (w.type == rt::WallType::Plane) {
      auto mk = base("walls", visualization_msgs::Marker::CUBE);
      mk.pose.position = to_point(w.origin);
      mk.pose.orientation = to_quat(Quat::FromTwoVectors(Vec3::UnitZ(), w.axis));
      mk.scale.x = mk.scale.y = 2.0;
      mk.scale.z = 0.001;
      mk.color.r = mk.color.g = mk.color.b = 0.4f;
      mk.color.a = 0.3f;
      arr.markers.push_back(mk);
    }
  }
  // Bodies: one marker per shape.
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const rt::BodyModel& bm = m.bodies[b];
    const rt::BodyState& bs = s.bodies[b];
    for (const rt::Shape& sh : bm.shapes) {
      int type = visualization_msgs::Marker::CUBE;
      Vec3 scale = 2 * sh.size;
      if (sh.type == rt::ShapeType::Sphere || sh.type == rt::ShapeType::Ellipsoid) type = visualization_msgs::Marker::SPHERE;
      if (sh.type == rt::ShapeType::Cylinder) type = visualization_msgs::Marker::CYLINDER;
      if (sh.type == rt::ShapeType::Mesh) continue;
      auto mk = base("bodies/" + bm.name, type);
      mk.pose.position = to_point(bs.pos + bs.q * sh.pos);
      mk.pose.orientation = to_quat(bs.q * sh.rot);
      mk.scale.x = scale.x();
      mk.scale.y = scale.y();
      mk.scale.z = scale.z();
      mk.color.r = bm.fixed ? 0.5f : 0.9f;
      mk.color.g = bm.fixed ? 0.45f : 0.75f;
      mk.color.b = bm.fixed ? 0.4f : 0.2f;
      arr.markers.push_back(mk);
    }
  }
  // Grains: SPHERE_LISTs, one per radius bin (a list has one scale), at most 8.
  if (m.n_grains > 0) {
    const auto [lo_it, hi_it] = std::minmax_element(m.grain_radius.begin(), m.grain_radius.end());
    const double lo = *lo_it, hi = *hi_it;
    const int bins = hi > lo * (1 + 1e-6) ? 8 : 1;
    std::vector<visualization_msgs::Marker> lists;
    for (int k = 0; k < bins; ++k) {
      auto mk = base("grains", visualization_msgs::Marker::SPHERE_LIST);
      const double r = bins == 1 ? lo : lo + (hi - lo) * (k + 0.5) / bins;
      mk.scale.x = mk.scale.y = mk.scale.z = 2 * r;
      mk.color.r = 0.55f;
      mk.color.g = 0.5f;
      mk.color.b = 0.45f;
      lists.push_back(mk);
    }
    for (int i = 0; i < m.n_grains; ++i) {
      const int k = bins == 1 ? 0 : std::min(bins - 1, int((m.grain_radius[i] - lo) / (hi - lo) * bins));
      lists[k].points.push_back(to_point(s.pos[i]));
    }
    for (auto& mk : lists)
      if (!mk.points.empty()) arr.markers.push_back(mk);
  }
  // The scene kind's own markers.
  topics_->markers(*twin_, base, arr);
  markers_pub_.publish(arr);
}

void TwinNode::publish_diagnostics(int level, const std::string& message) {
  diagnostic_msgs::DiagnosticArray arr;
  arr.header.stamp = stamp(twin_->state().time);
  diagnostic_msgs::DiagnosticStatus st;
  st.level = static_cast<decltype(st.level)>(level);
  st.name = "regolith_twin: guards";
  st.hardware_id = twin_->name();
  st.message = message;
  auto kv = [&](const std::string& k, double v) {
    diagnostic_msgs::KeyValue x;
    x.key = k;
    x.value = std::to_string(v);
    st.values.push_back(x);
  };
  const rt::StepStats& s = twin_->state().stats;
  kv("max_overlap_ratio", s.max_overlap_ratio);
  kv("overlap_limit", twin_->model().guards.max_overlap_ratio);
  kv("dt", twin_->model().dt);
  kv("sim_time", twin_->state().time);
  arr.status.push_back(st);
  diag_pub_.publish(arr);
  last_diag_wall_ = WallClock::now();
}

// --- services -------------------------------------------------------------------

bool TwinNode::on_pause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lk(mu_);
  paused_ = true;
  res.success = true;
  res.message = "paused at t = " + std::to_string(twin_->state().time) + " s";
  if (pending_steps_ > 0) {  // a ~step in progress stops here and answers that it was cancelled
    pending_steps_ = 0;
    pending_until_ = -1;
    step_cancelled_ = true;
    step_cv_.notify_all();
    res.message += "; the ~step request in progress was cancelled";
  }
  return true;
}

bool TwinNode::on_unpause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lk(mu_);
  if (failed_) {
    res.success = false;
    res.message = "the run stopped on a blow-up (" + failure_ + "); reset or load a checkpoint first";
    return true;
  }
  paused_ = false;
  reset_pacing();
  cv_.notify_all();
  res.success = true;
  res.message = "running";
  return true;
}

bool TwinNode::on_reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lk(mu_);
  twin_->reset();
  failed_ = false;
  failure_.clear();
  end_handled_ = false;
  last_clock_sim_ = last_body_sim_ = last_contacts_sim_ = -1e300;
  reset_pacing();
  after_step(true);
  res.success = true;
  res.message = "reset to t = " + std::to_string(twin_->state().time) + " s";
  return true;
}

bool TwinNode::on_step(regolith_twin::Step::Request& req, regolith_twin::Step::Response& res) {
  std::unique_lock<std::mutex> lk(mu_);
  const bool by_time = req.duration != 0;
  if (by_time && req.steps != 0) {
    res.success = false;
    res.message = "give steps or duration, not both";
  } else if (by_time && !(req.duration > 0 && req.duration <= 1e6)) {
    res.success = false;
    res.message = "duration = " + std::to_string(req.duration) + " s: allowed range (0, 1e6]";
  } else if (!by_time && (req.steps <= 0 || req.steps > 100000000)) {
    res.success = false;
    res.message = "steps = " + std::to_string(req.steps) + ": allowed range [1, 100000000]";
  } else if (!paused_) {
    res.success = false;
    res.message = "refused while running: call ~pause first";
  } else if (failed_) {
    res.success = false;
    res.message = "the run stopped on a blow-up (" + failure_ + "); reset or load a checkpoint first";
  } else if (pending_steps_ > 0) {
    res.success = false;
    res.message = "another step request is in progress";
  } else {
    pending_steps_ = by_time ? 1 : req.steps;  // by time: one pending until the span is done
    pending_until_ = by_time ? twin_->state().time + req.duration : -1;
    step_cancelled_ = false;
    cv_.notify_all();
    // Bounded: ~pause cancels it, and so does ~max_step_wall seconds of wall time.
    const bool done = step_cv_.wait_for(lk, std::chrono::duration<double>(p_.max_step_wall),
                                        [&] { return pending_steps_ == 0 || !running_; });
    if (!done) {
      pending_steps_ = 0;
      pending_until_ = -1;
      res.success = false;
      res.message = "stopped after " + std::to_string(p_.max_step_wall) +
                    " s of wall time (~max_step_wall); ask for fewer steps or raise ~max_step_wall";
    } else if (step_cancelled_) {
      res.success = false;
      res.message = "cancelled by ~pause";
    } else {
      res.success = !failed_ && running_;
      res.message = failed_ ? failure_ : (running_ ? "ok" : "node stopping");
    }
    step_cancelled_ = false;
  }
  res.sim_time = twin_->state().time;
  return true;
}

// Checkpoints: the state is copied to bytes (save) or made from bytes (load)
// under the simulation lock; the file is written or read outside it, so a
// slow or blocking path never stops /clock or the other services.
bool TwinNode::on_save(regolith_twin::Checkpoint::Request& req, regolith_twin::Checkpoint::Response& res) {
  try {
    const std::string path = rt::path_inside(checkpoint_dir_, req.path, "checkpoint");
    rt::check_regular_target(path, "a checkpoint");
    std::string image;
    double t = 0;
    {
      std::lock_guard<std::mutex> lk(mu_);
      if (failed_)
        throw std::runtime_error("the run stopped on a blow-up (" + failure_ +
                                 "): its state is not saved; reset or load a checkpoint first");
      image = twin_->checkpoint_image();
      t = twin_->state().time;
    }
    rt::write_checkpoint_file(path, image);
    res.success = true;
    res.message = "saved t = " + std::to_string(t) + " s to " + path;
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool TwinNode::on_load(regolith_twin::Checkpoint::Request& req, regolith_twin::Checkpoint::Response& res) {
  try {
    const std::string path = rt::path_inside(checkpoint_dir_, req.path, "checkpoint");
    const std::string data = rt::read_file_bounded(path, rt::kMaxCheckpointBytes, "checkpoint", p_.io_timeout);
    std::lock_guard<std::mutex> lk(mu_);
    twin_->load_image(path, data);
    failed_ = false;
    failure_.clear();
    end_handled_ = false;
    last_clock_sim_ = last_body_sim_ = last_contacts_sim_ = -1e300;
    reset_pacing();
    after_step(true);
    res.success = true;
    res.message = "loaded t = " + std::to_string(twin_->state().time) + " s from " + path;
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool TwinNode::on_set_body_state(regolith_twin::SetBodyState::Request& req, regolith_twin::SetBodyState::Response& res) {
  std::lock_guard<std::mutex> lk(mu_);
  const int b = twin_->body_index(req.body);
  const auto& o = req.pose.orientation;
  if (b < 0) {
    res.success = false;
    res.message = "no body named '" + req.body + "'";
  } else if (twin_->model().bodies[b].fixed) {
    res.success = false;
    res.message = "body '" + req.body + "' is fixed";
  } else if (failed_) {
    res.success = false;
    res.message = "the run stopped on a blow-up (" + failure_ + "); reset or load a checkpoint first";
  } else {
    const auto& p = req.pose.position;
    try {
      twin_->set_body_state(b, Vec3(p.x, p.y, p.z), Quat(o.w, o.x, o.y, o.z), from_vector(req.twist.linear),
                            from_vector(req.twist.angular));
      publish_body_states();
      res.success = true;
      res.message = "ok";
    } catch (const rt::InputError& e) {  // a non-finite pose or twist, a zero quaternion: the state is left as it was
      res.success = false;
      res.message = e.what();
    }
  }
  return true;
}

bool TwinNode::on_apply_wrench(regolith_twin::ApplyBodyWrench::Request& req,
                               regolith_twin::ApplyBodyWrench::Response& res) {
  std::lock_guard<std::mutex> lk(mu_);
  const int b = twin_->body_index(req.body);
  if (b < 0) {
    res.success = false;
    res.message = "no body named '" + req.body + "'";
  } else if (!(req.duration > 0) || !std::isfinite(req.duration)) {
    res.success = false;
    res.message = "duration = " + std::to_string(req.duration) + ": must be > 0 s";
  } else if (twin_->model().bodies[b].fixed) {
    res.success = false;
    res.message = "body '" + req.body + "' is fixed";
  } else {
    try {  // a non-finite wrench or one beyond the acceleration bounds is refused with its numbers
      twin_->apply_wrench(b, from_vector(req.wrench.force), from_vector(req.wrench.torque),
                          twin_->state().time + req.duration);
      res.success = true;
      res.message = "ok";
    } catch (const rt::InputError& e) {
      res.success = false;
      res.message = e.what();
    }
  }
  return true;
}

}  // namespace rt_ros
