// The node's services, in process: a TwinNode on the short plate landing,
// driven through pause / step / reset / checkpoints / body state / wrench,
// with every answer checked against the engine (an rt::Twin of the same file
// stepped directly) or against the physics (a push changes the velocity by
// F t / M in free flight).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/ApplyBodyWrench.h"
#include "regolith_twin/BodyStates.h"
#include "regolith_twin/Checkpoint.h"
#include "regolith_twin/SetBodyState.h"
#include "regolith_twin/Step.h"
#include "regolith_twin/ros/twin_node.hpp"

namespace {

std::unique_ptr<rt_ros::TwinNode> g_node;
rt_ros::NodeParams g_params;

// The latest body_states message.
std::mutex g_mu;
regolith_twin::BodyStates g_last;
void on_states(const regolith_twin::BodyStates::ConstPtr& m) {
  std::lock_guard<std::mutex> lk(g_mu);
  g_last = *m;
}

// Waits until a body_states message of step `step` has arrived; returns it.
regolith_twin::BodyStates states_at(long step) {
  for (int k = 0; k < 500; ++k) {
    {
      std::lock_guard<std::mutex> lk(g_mu);
      if (g_last.step == step) return g_last;
    }
    ros::WallDuration(0.01).sleep();
  }
  ADD_FAILURE() << "no body_states message for step " << step;
  return {};
}

std::string srv(const std::string& name) { return ros::names::resolve("~" + name); }

bool trigger(const std::string& name, std::string* message = nullptr) {
  std_srvs::Trigger t;
  EXPECT_TRUE(ros::service::call(srv(name), t)) << name;
  if (message) *message = t.response.message;
  return t.response.success;
}

// ros::service::call asks the master for the service on every call, and two
// such lookups at once race inside roscpp (ThreadSanitizer reports it for a
// program that uses roscpp alone). Tests that call from two threads at once
// therefore open persistent clients first, one per thread: a persistent
// client looks the service up on its first call only.
template <class Service>
ros::ServiceClient persistent_client(const std::string& name) {
  ros::NodeHandle nh;
  return nh.serviceClient<Service>(srv(name), true);
}

regolith_twin::Step::Response step(long n) {
  regolith_twin::Step s;
  s.request.steps = n;
  EXPECT_TRUE(ros::service::call(srv("step"), s));
  return s.response;
}

regolith_twin::Step::Response step_for(double seconds, long steps = 0) {
  regolith_twin::Step s;
  s.request.duration = seconds;
  s.request.steps = steps;
  EXPECT_TRUE(ros::service::call(srv("step"), s));
  return s.response;
}

rt::Twin reference_twin() {
  rt::TwinOptions to;
  to.file = g_params.scenario_file;
  to.scene.quiet = true;
  return rt::Twin(to);
}

const regolith_twin::BodyState& body(const regolith_twin::BodyStates& m, const std::string& name) {
  for (const auto& b : m.bodies)
    if (b.name == name) return b;
  throw std::runtime_error("no body " + name);
}

}  // namespace

TEST(TwinNodeServices, StepAdvancesBySteps_AndBodiesMoveAsTheEngine) {
  ASSERT_TRUE(trigger("reset"));
  ASSERT_TRUE(trigger("pause"));
  const double t0 = g_node->sim_time(), dt = g_node->dt();
  const auto r = step(250);
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_NEAR(r.sim_time, t0 + 250 * dt, 1e-9 * dt);
  EXPECT_NEAR(g_node->sim_time(), t0 + 250 * dt, 1e-9 * dt);
  // The same 250 steps taken directly with the engine: identical centre of mass and velocity.
  rt::Twin ref = reference_twin();
  const long s0 = ref.state().step;
  for (int k = 0; k < 250; ++k) ref.step();
  const auto m = states_at(s0 + 250);
  const auto& b = body(m, "mascot");
  const rt::BodyState& e = ref.state().bodies[ref.body_index("mascot")];
  EXPECT_EQ(b.center_of_mass.x, e.pos.x());
  EXPECT_EQ(b.center_of_mass.y, e.pos.y());
  EXPECT_EQ(b.center_of_mass.z, e.pos.z());
  EXPECT_EQ(b.twist.linear.z, e.vel.z());
  EXPECT_EQ(b.twist.angular.x, e.omega.x());
  EXPECT_GT(b.contacts, 0u) << "250 steps reach the plate (first contact after about 100)";
}

TEST(TwinNodeServices, StepAdvancesByADuration) {
  ASSERT_TRUE(trigger("reset"));
  ASSERT_TRUE(trigger("pause"));
  const double t0 = g_node->sim_time(), dt = g_node->dt();
  // 37.4 steps' worth: the span ends at the step nearest its end (37 steps).
  const auto r = step_for(37.4 * dt);
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_NEAR(r.sim_time, t0 + 37 * dt, 1e-9 * dt);
  auto bad = step_for(-1.0);
  EXPECT_FALSE(bad.success);
  EXPECT_NE(bad.message.find("allowed range"), std::string::npos) << bad.message;
  bad = step_for(1e-3, 5);
  EXPECT_FALSE(bad.success);
  EXPECT_NE(bad.message.find("not both"), std::string::npos) << bad.message;
}

TEST(TwinNodeServices, StepIsRefusedWhileRunning_AndBadCountsAreRefused) {
  ASSERT_TRUE(trigger("pause"));
  ASSERT_TRUE(trigger("reset"));
  // Lift the lander 50 m: a fall of seconds of wall time, so the run cannot
  // end (and pause itself) before the refused request below arrives.
  regolith_twin::SetBodyState set;
  set.request.body = "mascot";
  {
    std::lock_guard<std::mutex> lk(g_mu);
    set.request.pose = body(g_last, "mascot").pose;
  }
  set.request.pose.position.z += 50;
  ASSERT_TRUE(ros::service::call(srv("set_body_state"), set));
  ASSERT_TRUE(set.response.success) << set.response.message;
  ASSERT_TRUE(trigger("unpause"));
  auto r = step(10);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("refused while running"), std::string::npos) << r.message;
  ASSERT_TRUE(trigger("pause"));
  r = step(-5);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("allowed range"), std::string::npos) << r.message;
  r = step(0);
  EXPECT_FALSE(r.success);
  r = step(3);  // the node still answers
  EXPECT_TRUE(r.success) << r.message;
}

TEST(TwinNodeServices, ResetRestoresTheStart) {
  ASSERT_TRUE(trigger("pause"));
  ASSERT_TRUE(trigger("reset"));
  rt::Twin ref = reference_twin();
  const double t_start = ref.state().time;
  EXPECT_EQ(g_node->sim_time(), t_start);
  ASSERT_TRUE(step(40).success);
  ASSERT_TRUE(trigger("reset"));
  EXPECT_EQ(g_node->sim_time(), t_start);
  const auto m = states_at(ref.state().step);
  const rt::BodyState& e = ref.state().bodies[ref.body_index("mascot")];
  EXPECT_EQ(body(m, "mascot").center_of_mass.z, e.pos.z());
  EXPECT_EQ(body(m, "mascot").twist.linear.x, e.vel.x());
}

TEST(TwinNodeServices, CheckpointContinuesBitIdentically) {
  ASSERT_TRUE(trigger("pause"));
  ASSERT_TRUE(trigger("reset"));
  const long s0 = reference_twin().state().step;
  ASSERT_TRUE(step(120).success);
  const std::string path = "/tmp/regolith_twin_services_test_" + std::to_string(::getpid()) + ".ckpt";
  regolith_twin::Checkpoint c;
  c.request.path = path;
  ASSERT_TRUE(ros::service::call(srv("save_checkpoint"), c));
  ASSERT_TRUE(c.response.success) << c.response.message;
  const double t1 = g_node->sim_time();
  const auto a = step(200);
  const regolith_twin::BodyStates first = states_at(s0 + 320);
  ASSERT_TRUE(ros::service::call(srv("load_checkpoint"), c));
  ASSERT_TRUE(c.response.success) << c.response.message;
  EXPECT_EQ(g_node->sim_time(), t1);
  {
    std::lock_guard<std::mutex> lk(g_mu);
    g_last.step = -1;  // wait for the repeated step below, not the first run's message
  }
  const auto b = step(200);
  EXPECT_EQ(a.sim_time, b.sim_time);
  const auto second = states_at(s0 + 320);
  EXPECT_EQ(body(first, "mascot").center_of_mass.x, body(second, "mascot").center_of_mass.x);
  EXPECT_EQ(body(first, "mascot").center_of_mass.z, body(second, "mascot").center_of_mass.z);
  EXPECT_EQ(body(first, "mascot").twist.angular.y, body(second, "mascot").twist.angular.y);
  std::remove(path.c_str());
}

TEST(TwinNodeServices, AppliedWrenchChangesVelocityByImpulse) {
  ASSERT_TRUE(trigger("pause"));
  ASSERT_TRUE(trigger("reset"));
  rt::Twin ref = reference_twin();
  const int b = ref.body_index("mascot");
  const double mass = ref.model().bodies[b].mass, dt = g_node->dt();
  const long s0 = ref.state().step;
  const auto before = body(states_at(s0), "mascot");
  // Lift the lander away from the plate first so that nothing touches it.
  regolith_twin::SetBodyState set;
  set.request.body = "mascot";
  set.request.pose = before.pose;
  set.request.pose.position.z += 0.5;
  set.request.twist.linear.x = 0.1;
  ASSERT_TRUE(ros::service::call(srv("set_body_state"), set));
  ASSERT_TRUE(set.response.success) << set.response.message;
  regolith_twin::ApplyBodyWrench w;
  w.request.body = "mascot";
  w.request.wrench.force.z = 3.0 * mass;  // 3 m/s^2 upwards
  w.request.duration = 20 * dt;
  ASSERT_TRUE(ros::service::call(srv("apply_body_wrench"), w));
  ASSERT_TRUE(w.response.success) << w.response.message;
  ASSERT_TRUE(step(40).success);
  const auto after = body(states_at(s0 + 40), "mascot");
  EXPECT_EQ(after.contacts, 0u);
  // 20 steps pushed at 3 m/s^2 up, 40 steps of gravity.
  const double g = -ref.model().gravity.z();
  EXPECT_NEAR(after.twist.linear.z, 3.0 * 20 * dt - g * 40 * dt, 1e-9);
  EXPECT_NEAR(after.twist.linear.x, 0.1, 1e-12);
}

TEST(TwinNodeServices, BadRequestsGetErrors_AndTheNodeGoesOn) {
  ASSERT_TRUE(trigger("pause"));
  regolith_twin::SetBodyState set;
  set.request.body = "no_such_body";
  set.request.pose.orientation.w = 1;
  ASSERT_TRUE(ros::service::call(srv("set_body_state"), set));
  EXPECT_FALSE(set.response.success);
  EXPECT_NE(set.response.message.find("no_such_body"), std::string::npos);
  set.request.body = "mascot";
  set.request.pose.orientation.w = 0;  // not a rotation
  ASSERT_TRUE(ros::service::call(srv("set_body_state"), set));
  EXPECT_FALSE(set.response.success);
  set.request.body = "plate";
  set.request.pose.orientation.w = 1;
  ASSERT_TRUE(ros::service::call(srv("set_body_state"), set));
  EXPECT_FALSE(set.response.success) << "a fixed body cannot be moved";
  regolith_twin::Checkpoint c;
  c.request.path = "/nonexistent/folder/state.ckpt";
  ASSERT_TRUE(ros::service::call(srv("load_checkpoint"), c));
  EXPECT_FALSE(c.response.success);
  ASSERT_TRUE(ros::service::call(srv("save_checkpoint"), c));
  EXPECT_FALSE(c.response.success);
  c.request.path = "/proc/self/status";  // not a checkpoint
  ASSERT_TRUE(ros::service::call(srv("load_checkpoint"), c));
  EXPECT_FALSE(c.response.success);
  regolith_twin::ApplyBodyWrench w;
  w.request.body = "mascot";
  w.request.duration = 0;
  ASSERT_TRUE(ros::service::call(srv("apply_body_wrench"), w));
  EXPECT_FALSE(w.response.success);
  w.request.body = "nobody";
  w.request.duration = 1;
  ASSERT_TRUE(ros::service::call(srv("apply_body_wrench"), w));
  EXPECT_FALSE(w.response.success);
  const double t = g_node->sim_time();
  const auto r = step(2);
  EXPECT_TRUE(r.success);
  EXPECT_GT(r.sim_time, t);
}

TEST(TwinNodeServices, ALongStepIsCancelledByPause) {
  auto pause = persistent_client<std_srvs::Trigger>("pause");
  auto stepper = persistent_client<regolith_twin::Step>("step");
  std_srvs::Trigger p;
  ASSERT_TRUE(pause.call(p));
  ASSERT_TRUE(p.response.success);
  regolith_twin::Step one;
  one.request.steps = 1;
  ASSERT_TRUE(stepper.call(one));
  ASSERT_TRUE(one.response.success) << one.response.message;
  const double t0 = g_node->sim_time();
  regolith_twin::Step::Response r;
  std::thread caller([&r, &stepper] {
    regolith_twin::Step s;
    s.request.steps = 100000000;  // far longer than the test
    EXPECT_TRUE(stepper.call(s));
    r = s.response;
  });
  ros::WallDuration(1.0).sleep();
  EXPECT_TRUE(pause.call(p));
  EXPECT_TRUE(p.response.success);
  const std::string& msg = p.response.message;
  EXPECT_NE(msg.find("cancelled"), std::string::npos) << msg;
  caller.join();  // the step request answers at once
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.message, "cancelled by ~pause");
  EXPECT_GT(r.sim_time, t0);
  // The twin is paused where the request stopped, and steps on request.
  const double t1 = g_node->sim_time();
  ros::WallDuration(0.2).sleep();
  EXPECT_EQ(g_node->sim_time(), t1);
  EXPECT_TRUE(step(3).success);
}

TEST(TwinNodeServices, ABlockingCheckpointPathDoesNotStopTheNode) {
  // A named pipe nobody writes to: opening it blocks. The load waits
  // outside the simulation lock, so the node steps and answers meanwhile.
  ASSERT_TRUE(trigger("pause"));
  char dir[] = "/tmp/regolith_fifo_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/state.ckpt";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  auto loader_client = persistent_client<regolith_twin::Checkpoint>("load_checkpoint");
  auto stepper = persistent_client<regolith_twin::Step>("step");
  auto pause = persistent_client<std_srvs::Trigger>("pause");
  regolith_twin::Checkpoint c;
  c.request.path = std::string(dir) + "/absent.ckpt";  // opens the link; refused
  ASSERT_TRUE(loader_client.call(c));
  EXPECT_FALSE(c.response.success);
  regolith_twin::Step s;
  s.request.steps = 1;
  ASSERT_TRUE(stepper.call(s));
  std_srvs::Trigger p;
  ASSERT_TRUE(pause.call(p));
  c.request.path = fifo;
  std::atomic<bool> answered{false};
  std::thread loader([&] {
    EXPECT_TRUE(loader_client.call(c));
    answered = true;
  });
  ros::WallDuration(0.5).sleep();
  EXPECT_FALSE(answered);
  const double t = g_node->sim_time();
  s.request.steps = 5;
  EXPECT_TRUE(stepper.call(s));  // served while the load waits
  EXPECT_TRUE(s.response.success) << s.response.message;
  EXPECT_GT(s.response.sim_time, t);
  EXPECT_TRUE(pause.call(p));
  EXPECT_TRUE(p.response.success);
  // Writers come and go with nothing written: the load reads an empty file and refuses it.
  for (int k = 0; k < 1000 && !answered; ++k) {
    const int fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // succeeds only while a reader waits
    if (fd >= 0) close(fd);
    ros::WallDuration(0.01).sleep();
  }
  loader.join();
  EXPECT_FALSE(c.response.success);
  EXPECT_NE(c.response.message.find(fifo), std::string::npos) << c.response.message;
  std::remove(fifo.c_str());
  rmdir(dir);
  EXPECT_TRUE(step(2).success);
}

TEST(TwinNodeServices, PipeLoadsLeavePauseAnswered) {
  // Loads from pipes nobody writes, one for each thread of this process's
  // spinner (3, main below): on the shared queue they would hold every thread
  // that serves pause. They wait on the node's own I/O thread instead (until
  // ~io_timeout, one after the other), while pause, unpause and step answer at once.
  constexpr int kLoads = 3;
  char dir[] = "/tmp/regolith_fifo2_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  std::vector<std::string> pipes;
  std::vector<ros::ServiceClient> clients;
  std::vector<regolith_twin::Checkpoint> calls(kLoads);
  for (int k = 0; k < kLoads; ++k) {
    pipes.push_back(std::string(dir) + "/p" + std::to_string(k) + ".ckpt");
    ASSERT_EQ(mkfifo(pipes.back().c_str(), 0600), 0);
    clients.push_back(persistent_client<regolith_twin::Checkpoint>("load_checkpoint"));
    calls[k].request.path = pipes.back();
  }
  std::atomic<int> answered{0};
  std::vector<std::thread> loads;
  for (int k = 0; k < kLoads; ++k)
    loads.emplace_back([&, k] {
      EXPECT_TRUE(clients[k].call(calls[k]));
      ++answered;
    });
  ros::WallDuration(0.3).sleep();
  EXPECT_EQ(answered, 0) << "the loads wait for their pipes";
  for (const char* name : {"unpause", "pause"}) {
    const ros::WallTime t0 = ros::WallTime::now();
    EXPECT_TRUE(trigger(name));
    EXPECT_LT((ros::WallTime::now() - t0).toSec(), 1.0) << name << " answered while the loads wait";
  }
  const ros::WallTime t0 = ros::WallTime::now();
  EXPECT_TRUE(step(3).success);
  EXPECT_LT((ros::WallTime::now() - t0).toSec(), 1.0);
  for (std::thread& t : loads) t.join();
  for (const auto& c : calls) {
    EXPECT_FALSE(c.response.success);
    EXPECT_NE(c.response.message.find("within"), std::string::npos) << c.response.message;
  }
  for (const std::string& p : pipes) std::remove(p.c_str());
  rmdir(dir);
}

TEST(TwinNodeServices, CheckpointsStayInTheirDirectory) {
  // ~checkpoint_dir is /tmp here: paths outside it, links out of it and
  // targets that are not regular files are refused, naming the directory.
  char dir[] = "/tmp/regolith_ckdir_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string link = std::string(dir) + "/out", fifo = std::string(dir) + "/pipe.ckpt";
  ASSERT_EQ(symlink("/var", link.c_str()), 0);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  regolith_twin::Checkpoint c;
  for (const std::string& p : {std::string("/dev/full"), std::string("/etc/state.ckpt"), link + "/state.ckpt",
                               std::string(dir) + "/../../etc/state.ckpt"}) {
    c.request.path = p;
    ASSERT_TRUE(ros::service::call(srv("save_checkpoint"), c));
    EXPECT_FALSE(c.response.success) << p;
    EXPECT_NE(c.response.message.find("checkpoints are kept in /tmp"), std::string::npos) << c.response.message;
    ASSERT_TRUE(ros::service::call(srv("load_checkpoint"), c));
    EXPECT_FALSE(c.response.success) << p;
  }
  c.request.path = fifo;
  ASSERT_TRUE(ros::service::call(srv("save_checkpoint"), c));
  EXPECT_FALSE(c.response.success);
  EXPECT_NE(c.response.message.find("named pipe"), std::string::npos) << c.response.message;
  struct stat st {};
  ASSERT_EQ(stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe is not replaced";
  // A relative name is taken inside the directory.
  const std::string name = std::string(dir + 5) + "/good.ckpt";  // dir without "/tmp/"
  c.request.path = name;
  ASSERT_TRUE(ros::service::call(srv("save_checkpoint"), c));
  EXPECT_TRUE(c.response.success) << c.response.message;
  EXPECT_EQ(access((std::string(dir) + "/good.ckpt").c_str(), R_OK), 0);
  ASSERT_TRUE(ros::service::call(srv("load_checkpoint"), c));
  EXPECT_TRUE(c.response.success) << c.response.message;
  std::remove((std::string(dir) + "/good.ckpt").c_str());
  std::remove(fifo.c_str());
  std::remove(link.c_str());
  rmdir(dir);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "twin_node_services_test");
  ros::NodeHandle nh, pnh("~");
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  ros::AsyncSpinner spinner(3);
  spinner.start();
  try {
    g_params = rt_ros::read_params(pnh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  g_params.start_paused = true;
  g_params.io_timeout = 2;  // the pipe loads above give up after 2 s
  g_params.threads = 1;
  g_params.body_state_rate = 0;
  ros::Subscriber sub = pnh.subscribe("body_states", 1000, on_states);
  g_node = std::make_unique<rt_ros::TwinNode>(nh, pnh, g_params);
  g_node->start();
  ros::WallDuration(0.5).sleep();  // subscriber connected
  const int rc = RUN_ALL_TESTS();
  g_node->stop();
  g_node.reset();
  ros::shutdown();
  return rc;
}
