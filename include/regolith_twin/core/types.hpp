// Basic numeric types shared by every part of the engine.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

namespace rt {

using Vec3 = Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;

// An error in user input (scenario file, parameter, data file). The message
// names the file, the key and the allowed range.
// Bounds every state value is checked against when it comes from a file
// (checkpoints, beds; docs/files.md): simulated time within what ROS time
// holds (2^32 s) with room to spare, coordinates and speeds far beyond any
// scene (Ryugu is 450 m in radius, the sampler's projectile 300 m/s).
constexpr double kMaxStateTime = 1e9;     // s
constexpr double kMaxCoordinate = 1e6;    // m
constexpr double kMaxStateSpeed = 1e6;    // m/s (and rad/s for spins)

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run that became numerically invalid (NaN, excessive overlap, energy growth).
struct BlowUpError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run that reached the number of steps it was allowed (RunOptions::max_steps):
// stopped like a blow-up, with outputs kept, but reported as step_limit.
struct StepLimitError : BlowUpError {
  using BlowUpError::BlowUpError;
};

}  // namespace rt
