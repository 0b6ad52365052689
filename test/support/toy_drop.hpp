// A toy scene kind, defined in the tests only: a ball dropped on a bed, the
// grains above a plane counted. It shows that a kind plugs in from outside
// the package's sources: its block (`drop: {plane: z}`) is read and checked
// here, its run counts with the RegionCount observer, and its summary.json is
// the default one composed from its observers. The node's test adds its topic (test/ros/toy_drop_test.cpp).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <limits>
#include <memory>

#include "regolith_twin/observers/region_count.hpp"
#include "regolith_twin/observers/energy_series.hpp"
#include "regolith_twin/run/scene.hpp"

namespace toy {

class DropRun : public rt::SceneRun {
 public:
  explicit DropRun(double plane)
      : rt::SceneRun("drop"), above_("above", rt::Vec3(-1e300, -1e300, plane), rt::Vec3(1e300, 1e300, 1e300)) {}
  std::vector<rt::Observer*> observers() override { return {&above_}; }
  std::string result_line(const rt::Model& m, const rt::State& s, const rt::RunReport& rep) const override {
    return "drop: " + std::to_string(above_.grains()) + " grains above the plane";
  }
  const rt::RegionCount& above() const { return above_; }

 private:
  rt::RegionCount above_;
};

class DropScene : public rt::Scene {
 public:
  std::string kind() const override { return "drop"; }
  std::unique_ptr<rt::SceneRun> begin(rt::Run& run) const override {
    return std::make_unique<DropRun>(plane);
  }
  double plane = 0;
};

class DropKind : public rt::SceneKind {
 public:
  std::string name() const override { return "drop"; }
  std::unique_ptr<rt::Scene> prepare(const YAML::Node& doc, const std::string& file,
                                     const rt::SceneOptions& opt) const override {
    YAML::Node root = YAML::Clone(doc);
    const YAML::Node d = root["drop"];
    if (!d.IsMap() || !d["plane"]) throw rt::InputError(file + ": key 'drop.plane': missing (height of the plane, m)");
    const double plane = d["plane"].as<double>();
    if (!(plane > 0 && plane < 10))
      throw rt::InputError(file + ": key 'drop.plane': value out of range (allowed (0, 10) m)");
    root.remove("drop");
    auto sc = std::make_unique<DropScene>();
    sc->plane = plane;
    sc->sc = rt::parse_scenario(root, file);
    sc->start = sc->sc.initial;
    sc->plan = rt::RunPlan::of(sc->sc);
    sc->sample_every = sc->sc.output_every;
    return sc;
  }
};

// The scene file: 30 grains in a cylinder, a steel ball held above them while
// they settle, then dropped.
inline const char* kDropYaml = R"(
name: toy_drop
seed: 3
gravity: [0, 0, -9.81]
materials:
  grain: {preset: moderate}
  wall: {preset: moderate, eps_n: 0.5, eps_t: 1.0, structure: true}
  steel: {density: 7800, eps_n: 0.6, eps_t: 0.6, structure: true}
contact: {model: linear, kn: rule, v_max: 1.5, x_max: 0.05, steps_per_contact: 12}
walls:
  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}
  - {type: cylinder, base: [0, 0, 0], axis: [0, 0, 1], radius: 0.06, length: 0.4, inner: true, material: wall}
grains:
  - name: bed
    material: grain
    radius: {mean: 0.008, sigma: 0.1, cut: 1.0}
    fill: {shape: cylinder, center: [0, 0, 0], radius: 0.05, z: [0.0, 0.08], count: 30}
  - {name: ball, material: steel, radius: 0.015, position: [0, 0, 0.15], velocity: [0, 0, 0]}
stages:
  - {name: settle, duration: 0.2, hold: [ball]}
  - {name: drop, duration: 0.25}
output: {every: 0.01}
drop: {plane: 0.11}
)";

// Writes the scene file to path.
inline void write_drop_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(kDropYaml, f);
  std::fclose(f);
}

}  // namespace toy
