// The sampler scene kind (`sampler:` block, docs/scenes.md B): the gravel bed
// relaxed once at the shot's stiffness and cached (run/bed_cache.hpp), the
// horn placed with its bottom edge above the bed surface, the projectile
// added as a grain of its own material above the impact point; each run
// follows the horn segments and the collected mass, the crater, ejecta,
// energy partition, impact wave and Z-model flow, and writes series.csv,
// summary.json and the measurement files.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/run/scene.hpp"
#include "regolith_twin/observers/escape.hpp"
#include "regolith_twin/scenes/sampler/crater.hpp"
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"
#include "regolith_twin/scenes/sampler/horn_segments.hpp"
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "regolith_twin/scenes/sampler/packing_below_filter.hpp"

namespace rt {

struct SamplerSpec {
  std::string horn = "horn";       // body name of the horn (fixed)
  std::string projectile_material = "projectile";
  double speed = 300;              // m/s (50-300)
  double tilt_deg = 0;             // from the axis, in the x-z plane (-25..25)
  double offset = 0;               // of the aim along x, m (-2.5e-3..2.5e-3)
  double mass = 0.005;             // projectile, kg
  double radius = 0.004;           // projectile, m
  double start_gap = 0.005;        // projectile surface above the highest surface grain on the axis, m
  double horn_clearance = 0.005;   // bottom edge above the bed surface, m
  double container_radius = 0.15;  // m
  double duration = 0.02;          // s of simulated time after firing
  double kn_ref = 5.47e6;          // k_n = kn_ref (v / v_ref)^2, N/m (docs/model.md §4)
  double dt_ref = 1.5e-6;          // dt = dt_ref (v_ref / v), s
  double v_ref = 50;               // m/s
  double dt_factor = 1;            // dt multiplied by this (convergence studies: 0.5, 0.25)
  double sample_every = 1e-4;      // s between series rows
  double escape_half_width = 2.0;  // grains beyond this horizontal distance from the axis leave, m
  double escape_height = 3.0;      // ... or above this height, m
  int repeat = 0;                  // > 0: perturbed bed (rotated, impact point shifted within a mean radius)
  unsigned long perturb_seed = 1;
  std::vector<double> z_times = {45e-6, 1.25e-3, 12.5e-3};  // Z-model fits, s after impact
  std::vector<double> wave_times = {1.2e-5, 6.2e-5};        // wave profiles, s after impact
  double energy_window = 2e-4;     // energy partition, s after impact
  double requirement = 1e-4;       // collected mass required, kg
  bool second_shot = false;        // a second projectile, fired from the bottom of cylinder 4
  double second_delay = 0.2;       // ... this long after the first, s
};

SamplerSpec parse_sampler(const YAML::Node& n, const std::string& src);

class SamplerScene : public Scene {
 public:
  std::string kind() const override { return "sampler"; }
  double bed_top() const override { return surface_; }
  std::unique_ptr<SceneRun> begin(Run& run) const override;

  std::string file;
  SamplerSpec spec;
  int horn = -1;             // body index
  int projectile = -1;       // grain index at the start
  int projectile_material = -1;  // material index of the projectile(s)
  HornGeometry geometry;     // placed horn
  Vec3 impact = Vec3::Zero();   // aim point on the surface (x, y of the aim; z the surface there)
  Vec3 direction = -Vec3::UnitZ();  // of the projectile's flight
  double surface_ = 0;       // highest bed grain centre before the shot (ejecta line), m
  double surface_top = 0;    // highest bed grain top (z + r), m
  double rest_rms = 0;       // bed RMS speed at the start, m/s
  double bed_rotation = 0;   // rad (repeat)
  Vec3 impact_shift = Vec3::Zero();
  std::string bed_cache;
  int bed_grains = 0;
  double bed_mass = 0, packing = 0, bulk_density = 0, bed_depth = 0;
};

// One shot: the observers of docs/scenes.md B, the impact clock first (the
// others count their times from it).
// The optional second projectile (docs/scenes.md B): second_delay after the
// first, a grain like the first is added on the horn axis at the bottom of
// cylinder 4, moving along the first one's direction at the shot speed.
class SecondShot : public Fix {
 public:
  explicit SecondShot(const SamplerScene& sc);
  void add_grains(Model& m, State& s) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  void summary(JsonObject& out) const override;
  int grain() const { return grain_; }   // current index, -1 before firing or once it left the run
  double t_fired() const { return t_fired_; }  // s after the first shot, -1 before

 private:
  bool enabled_;
  double t_, radius_;
  int material_;
  Vec3 p0_, v0_;
  int grain_ = -1;
  double t_fired_ = -1;
};

class SamplerRun : public SceneRun {
 public:
  SamplerRun(const SamplerScene& sc, const Model& m);
  std::vector<Observer*> observers() override {
    return {&clock_, &segments_, &escape_, &ejecta_, &energy_, &wave_, &zfit_, &crater_, &packing_};
  }
  std::vector<Fix*> fixes() override { return {&second_}; }
  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override;
  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override;
  std::vector<std::pair<std::string, std::string>> files() const override;
  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override;

  const SamplerScene& scene() const { return scene_; }
  const HornSegments& segments() const { return segments_; }
  const ImpactClock& clock() const { return clock_; }
  const Crater& crater() const { return crater_; }
  const EjectionAngles& ejecta() const { return ejecta_; }
  const SecondShot& second() const { return second_; }

 private:
  const SamplerScene& scene_;
  ImpactClock clock_;
  HornSegments segments_;
  Escape escape_;
  EjectionAngles ejecta_;
  EnergyPartition energy_;
  WaveAttenuation wave_;
  ZModelSampler zfit_;
  Crater crater_;
  PackingBelowFilter packing_;
  SecondShot second_;
};

std::shared_ptr<const SceneKind> sampler_kind();

}  // namespace rt
