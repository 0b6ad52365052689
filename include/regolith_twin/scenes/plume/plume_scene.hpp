// The plume-erosion scene kind (`plume:` block, docs/scenes.md D): a bed in
// a periodic box under a gas flow (the scenario's `gas:` block) acting above
// an anchoring plane that follows the eroding surface; the bed is settled
// with the gas off and cached, the planes placed from its top, and each run
// measures the erosion (erosion.hpp). Variants: collisionless (no
// contacts among the free grains; the bed below the anchoring plane held and
// touching them), and the
// single-grain splash (one grain shot into the bed, no gas).
#pragma once

#include <memory>
#include <string>

#include "regolith_twin/run/scene.hpp"
#include "regolith_twin/scenes/plume/erosion.hpp"
#include "regolith_twin/scenes/plume/gas_budget.hpp"

namespace rt {

struct PlumeSpec {
  double penetration_depth = 4;  // anchoring plane below the bed top, grain diameters
  double erosion_height = 1;     // erosion plane above the bed top, grain diameters
  double duration = 0.2;         // s of plume
  PlaneMotion plane_motion = PlaneMotion::Net;
  double steps_per_contact = 50; // dt = t_c / this, t_c of two grains with damping (docs/model.md §4)
  bool collisionless = false;
  int window = 1000;             // steps of the moving averages
  double depleted_fraction = 0.9;  // depleted once this fraction of the grains is above the erosion plane
  double row_every = 1e-4;       // s between rows of erosion.csv
  double sample_every = 1e-3;    // s between rows of series.csv
  // Single-grain splash: one grain of the bed's size and material shot into
  // the bed from `splash_height` diameters above its top at `splash_speed`,
  // `splash_angle_deg` below the horizontal along +x; the gas is off.
  bool splash = false;
  double splash_speed = 1.0, splash_angle_deg = 15, splash_height = 1;
};

class PlumeScene : public Scene {
 public:
  std::string kind() const override { return "plume"; }
  double bed_top() const override { return top; }
  std::unique_ptr<SceneRun> begin(Run& run) const override;

  std::string file;
  PlumeSpec spec;
  ErosionPlanes planes;
  std::string bed_cache;
  int bed_grains = 0;
  double diameter = 0;       // mean grain diameter, m
  double top = 0;            // bed top, m
  double bed_fraction = 0;   // solid fraction of the bed's interior
  double gas_at_top = 0;     // U at the bed top, m/s (0 without gas)
  double shear_at_top = 0;   // omega* of a grain at rest at the bed top
  int splash_grain = -1;
};

class PlumeRun : public SceneRun {
 public:
  PlumeRun(const PlumeScene& scene, const Model& m);
  // The impulse bookkeeping reads the planes the step used: before the erosion observer moves them.
  std::vector<Observer*> observers() override { return {&impulse_}; }
  std::vector<Fix*> fixes() override { return {&erosion_}; }
  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override;
  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override;
  std::vector<std::pair<std::string, std::string>> files() const override;
  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override;
  const ErosionFix& erosion() const { return erosion_; }
  const ImpulseObserver& impulse() const { return impulse_; }

 private:
  const PlumeScene& scene_;
  ImpulseObserver impulse_;
  ErosionFix erosion_;
};

// The plume kind for the registry.
std::shared_ptr<const SceneKind> plume_kind();

}  // namespace rt
