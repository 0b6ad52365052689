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
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run that became numerically invalid (NaN, excessive overlap, energy growth).
struct BlowUpError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace rt
