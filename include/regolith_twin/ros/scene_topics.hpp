// What a scene kind adds to the ROS node: its own topics, published after a
// step and at the run end, and its markers. The node knows no scene kind: it
// asks this registry for the topics of the twin's kind (built-in kinds:
// src/ros/scenes/registry.cpp; tests register their own).
#pragma once

#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <functional>
#include <memory>
#include <string>

#include "regolith_twin/run/twin.hpp"

namespace rt_ros {

class SceneTopics {
 public:
  virtual ~SceneTopics() = default;
  // After a step (or at start-up with force set). clock_due: the node's
  // /clock publication was due at this step (topics at the clock rate).
  virtual void after_step(const rt::Twin& twin, bool clock_due, bool force) {}
  // The run ended (stages done, an observer ended it, or a blow-up).
  virtual void on_end(const rt::Twin& twin) {}
  // Markers of the scene; make(ns, type) gives a marker with stamp, frame and id set.
  virtual void markers(const rt::Twin& twin,
                       const std::function<visualization_msgs::Marker(const std::string&, int)>& make,
                       visualization_msgs::MarkerArray& out) {}
};

// Makes the topics of a kind, advertised under the node's private namespace.
using SceneTopicsFactory = std::function<std::unique_ptr<SceneTopics>(ros::NodeHandle& pnh, const rt::Twin& twin)>;

void register_scene_topics(const std::string& kind, SceneTopicsFactory make);
// The kind's topics (none registered: a SceneTopics that publishes nothing).
std::unique_ptr<SceneTopics> make_scene_topics(const std::string& kind, ros::NodeHandle& pnh, const rt::Twin& twin);

// Sim time as a ROS stamp (time zero goes out as 1 ns: ROS takes a zero time for "no clock yet").
inline ros::Time stamp(double t) { return t > 0 ? ros::Time(t) : ros::Time(0, 1); }

}  // namespace rt_ros
