// The scene kinds built into the package: one line each in
// src/scenes/registry.cpp (their ROS topics: src/ros/scenes/registry.cpp).
#pragma once

#include <memory>
#include <vector>

#include "regolith_twin/run/scene.hpp"

namespace rt {

std::vector<std::shared_ptr<const SceneKind>> builtin_scene_kinds();

}  // namespace rt
