// The built-in scene kinds' ROS topics: one line per kind that has its own.
#include "regolith_twin/ros/scene_topics.hpp"
#include "regolith_twin/ros/scenes/landing.hpp"
#include "regolith_twin/ros/scenes/sampler.hpp"

namespace rt_ros {

std::vector<std::pair<std::string, SceneTopicsFactory>> builtin_scene_topics() {
  return {
      {"landing", make_landing_topics},  // ~landing: the landing outcome (docs/ros.md)
      {"sampler", make_sampler_topics},  // ~collected_mass: horn segments and collected mass (docs/ros.md)
  };
}

}  // namespace rt_ros
