// The ROS adapter over rt::Twin (docs/ros.md): owns /clock, publishes tf,
// body states, contacts, particles, markers, status and diagnostics, and
// serves pause / unpause / reset / step / checkpoints / body state / wrench.
// It knows no scene kind: the kind's own topics (the landing outcome, ...)
// come from the scene-topics registry (scene_topics.hpp). The simulation runs in its own thread; service
// callbacks take the same lock, so a request always sees a whole step.
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <std_srvs/Trigger.h>

#include "regolith_twin/ApplyBodyWrench.h"
#include "regolith_twin/Checkpoint.h"
#include "regolith_twin/SetBodyState.h"
#include "regolith_twin/Step.h"
#include "regolith_twin/ros/scene_topics.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/run/twin.hpp"

namespace rt_ros {

// Parameters of the node (private namespace), read once at start-up.
struct NodeParams {
  std::string scenario_file;          // ~scenario_file (required)
  std::vector<std::string> overrides; // ~set: list of "dotted.key=value"
  double realtime_factor = 0;         // ~realtime_factor: <= 0 as fast as possible
  double clock_rate = 100;            // ~clock_rate: Hz of sim time (and at least every 0.1 s wall)
  double status_rate = 10;            // ~status_rate: Hz of wall time
  double body_state_rate = 0;         // ~body_state_rate: Hz of sim time; 0: every step
  double contacts_rate = 100;         // ~contacts_rate: Hz of sim time; 0: every step
  double particles_rate = 5;          // ~particles_rate: Hz (wall, or sim with visual_clock=sim)
  double markers_rate = 1;            // ~markers_rate: Hz (wall, or sim with visual_clock=sim)
  bool visual_sim_clock = false;      // ~visual_clock: "wall" (live) or "sim" (recording)
  int max_contact_points = 32;        // ~max_contact_points: points listed per pair (the deepest)
  std::string out_dir;                // ~out_dir: the run's summary.json written here at the run end ("" none)
  std::string cache_dir;              // ~cache_dir: relaxed beds ("" default)
  bool start_paused = false;          // ~start_paused
  bool shutdown_at_end = false;       // ~shutdown_at_end: stop the node when the run ends
  bool wait_for_recorder = false;     // ~wait_for_recorder: start stepping only once ~body_states and
                                      //   ~status have a subscriber (a rosbag recorder) and 1 s has passed
  int threads = 0;                    // ~threads: OpenMP threads (0: all cores)
  double max_step_wall = 600;         // ~max_step_wall: wall seconds a ~step request may take before it is stopped
  std::string checkpoint_dir;         // ~checkpoint_dir: where ~save_checkpoint and ~load_checkpoint paths must lie
                                      //   ("" : <out_dir>/checkpoints, else $ROS_HOME or ~/.ros + /regolith_twin/checkpoints)
  double io_timeout = 30;             // ~io_timeout: wall seconds a checkpoint load waits for a pipe's data
  long max_steps = 0;                 // ~max_steps: steps a run may take (0: no limit; the node is stepped,
                                      //   paused and cancelled from outside)
};

// The checkpoint directory the node uses for p (created if missing).
std::string checkpoint_dir(const NodeParams& p);

// Throws std::invalid_argument naming the parameter and its allowed range.
NodeParams read_params(const ros::NodeHandle& pnh);

class TwinNode {
 public:
  // Loads the scenario (may relax a bed); throws rt::InputError / rt::BlowUpError.
  TwinNode(ros::NodeHandle nh, ros::NodeHandle pnh, const NodeParams& p);
  ~TwinNode();
  void start();  // starts the simulation thread
  void stop();   // stops and joins it

  // For tests and the main: thread-safe readings.
  double sim_time();
  double dt();
  bool paused();
  bool ended();

 private:
  using WallClock = std::chrono::steady_clock;
  void loop();
  void after_step(bool force_publish);
  void on_end();
  void publish_clock();
  void publish_tf();
  void publish_static();
  void publish_body_states();
  void publish_contacts();
  void publish_status();
  void publish_particles();
  void publish_markers();
  void publish_diagnostics(int level, const std::string& message);
  void reset_pacing();

  bool on_pause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&);
  bool on_unpause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&);
  bool on_reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&);
  bool on_step(regolith_twin::Step::Request&, regolith_twin::Step::Response&);
  bool on_save(regolith_twin::Checkpoint::Request&, regolith_twin::Checkpoint::Response&);
  bool on_load(regolith_twin::Checkpoint::Request&, regolith_twin::Checkpoint::Response&);
  bool on_set_body_state(regolith_twin::SetBodyState::Request&, regolith_twin::SetBodyState::Response&);
  bool on_apply_wrench(regolith_twin::ApplyBodyWrench::Request&, regolith_twin::ApplyBodyWrench::Response&);

  ros::NodeHandle nh_, pnh_;
  NodeParams p_;
  std::string checkpoint_dir_;
  // Checkpoint saves and loads are served from their own queue and thread:
  // a slow file or a pipe nobody writes never holds the threads that answer
  // pause, unpause, reset and step (docs/ros.md).
  ros::CallbackQueue io_queue_;
  std::unique_ptr<ros::AsyncSpinner> io_spinner_;
  std::unique_ptr<rt::OutputFolder> out_folder_;  // ~out_dir, held for the node's life
  std::unique_ptr<rt::Twin> twin_;
  std::unique_ptr<SceneTopics> topics_;  // the scene kind's own topics
  std::mutex mu_;
  std::condition_variable cv_;       // wakes the loop (unpause, step request, stop)
  std::condition_variable step_cv_;  // wakes a step request when its steps are done
  bool paused_ = false;
  long pending_steps_ = 0;
  double pending_until_ = -1;  // a ~step by duration: simulated time it ends at (-1: by count)
  bool step_cancelled_ = false;  // the ~step in progress was cancelled by ~pause
  bool failed_ = false;              // a blow-up stopped the run: its state is not published, saved or edited
  double status_ke_ = 0, status_overlap_ = 0;  // the last values ~status published from a sound state
  std::string failure_;
  std::atomic<bool> running_{false};
  std::thread thread_;

  ros::Publisher clock_pub_, body_pub_, contacts_pub_, status_pub_, particles_pub_, markers_pub_,
      contact_markers_pub_, diag_pub_;
  std::vector<ros::ServiceServer> services_;
  tf2_ros::TransformBroadcaster tf_;
  tf2_ros::StaticTransformBroadcaster static_tf_;

  // Publication bookkeeping.
  double last_clock_sim_ = -1e300, last_body_sim_ = -1e300, last_contacts_sim_ = -1e300;
  double last_particles_ = -1e300, last_markers_ = -1e300;
  WallClock::time_point last_clock_wall_, last_status_wall_, last_diag_wall_, start_wall_;
  WallClock::time_point pace_wall0_;
  double pace_sim0_ = 0;
  double status_sim0_ = 0;
  long status_step0_ = 0;
  bool end_handled_ = false;
  bool waiting_for_recorder_ = false;
  WallClock::time_point recorder_seen_{};
  bool recorder_seen_set_ = false;
};

}  // namespace rt_ros
