// The landing's ROS topics: ~landing (regolith_twin/LandingOutcome, latched)
// at the clock rate and on every phase change, the outcome as a text marker,
// and the outcome in the node's log at the run end.
#pragma once

#include "regolith_twin/ros/scene_topics.hpp"

namespace rt_ros {

std::unique_ptr<SceneTopics> make_landing_topics(ros::NodeHandle& pnh, const rt::Twin& twin);

}  // namespace rt_ros
