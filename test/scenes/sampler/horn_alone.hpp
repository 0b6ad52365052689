// The shipped horn alone, for tests of its walls and filter: bottom aperture
// centre at the origin, no gravity, one gravel grain of radius r at `pos`,
// the contact law and step of a 50 m/s shot (docs/model.md §4).
#pragma once

#include <sstream>
#include <string>

#include "regolith_twin/io/scenario.hpp"

namespace rt::test {

inline Scenario horn_alone(double r, const Vec3& pos) {
  std::ostringstream yaml;
  yaml.precision(17);
  yaml << R"(
name: horn_alone
gravity: [0, 0, 0]
materials:
  regolith: {preset: gravel, density: 2430}
  horn: {preset: gravel, eps_n: 0.5, eps_t: 0.5, structure: true}
contact: {model: linear, kn: 5.47e6, dt: 1.5e-6}
bodies:
  - {name: horn, urdf: urdf/sampler_horn.urdf, material: horn, fixed: true}
stages: [{name: run, duration: 1}]
grains:
  - {name: first, material: regolith, radius: )"
       << r << ", position: [" << pos.x() << ", " << pos.y() << ", " << pos.z() << "]}\n";
  return parse_scenario_text(yaml.str(), "horn_alone");
}

}  // namespace rt::test
