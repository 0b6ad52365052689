// The sampler's ROS topics (docs/ros.md): ~collected_mass (CollectedMass:
// grains and mass per horn segment, the collected mass and whether the
// requirement is met) at the node's clock rate and at the run end, and a
// text marker with the collected mass.
#pragma once

#include "regolith_twin/ros/scene_topics.hpp"

namespace rt_ros {

std::unique_ptr<SceneTopics> make_sampler_topics(ros::NodeHandle& pnh, const rt::Twin& twin);

}  // namespace rt_ros
