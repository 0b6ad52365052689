// The registry of scene kinds' ROS topics (see scene_topics.hpp).
#include "regolith_twin/ros/scene_topics.hpp"

#include <map>
#include <mutex>
#include <utility>
#include <vector>

namespace rt_ros {

// The built-in kinds' topics, one line each (src/ros/scenes/registry.cpp).
std::vector<std::pair<std::string, SceneTopicsFactory>> builtin_scene_topics();

namespace {

struct Registry {
  std::mutex mu;
  std::map<std::string, SceneTopicsFactory> make;
};

Registry& registry() {
  static Registry r;
  static std::once_flag once;
  std::call_once(once, [] {
    for (auto& [kind, make] : builtin_scene_topics()) r.make[kind] = std::move(make);
  });
  return r;
}

}  // namespace

void register_scene_topics(const std::string& kind, SceneTopicsFactory make) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lk(r.mu);
  r.make[kind] = std::move(make);
}

std::unique_ptr<SceneTopics> make_scene_topics(const std::string& kind, ros::NodeHandle& pnh, const rt::Twin& twin) {
  Registry& r = registry();
  SceneTopicsFactory make;
  {
    std::lock_guard<std::mutex> lk(r.mu);
    auto it = r.make.find(kind);
    if (it != r.make.end()) make = it->second;
  }
  if (make) return make(pnh, twin);
  return std::make_unique<SceneTopics>();
}

}  // namespace rt_ros
