// The bucket-impact scene kind (`impact:` block, docs/scenes.md C.1): a
// rigid sphere dropped into a settled, cut bed of beads under Earth gravity.
// The bed is poured, settled and cut by the scenario's stages (cached); the
// sphere is placed on a vertical through its aim point (the container's axis
// by default) just above the bed's surface, moving down so that it reaches
// the surface at the impact speed. Each run follows the sphere: stopping
// depth (below the bed's nominal surface, the published definition, and
// below the mean top of its highest beads), collision durations, bounce, and
// the force law m a = -m g + f0 + m v^2 / d1 fitted to its deceleration.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/run/scene.hpp"

namespace rt {

struct ImpactSpec {
  std::string impactor = "sphere";  // body name
  double speed = 0.5;               // impact speed at the surface, m/s
  Vec3 aim = Vec3::Zero();          // x, y of the vertical the sphere falls along (z unused), m
  double gap = 1e-3;                // sphere bottom above the surface at the start (at most V^2 / 4g), m
  double duration = 1.0;            // s at most
  double rest_speed = 1e-3;         // the run ends once |v| stays below this after contact ...
  double rest_time = 0.05;          // ... for this long, s
  double fit_every = 2e-4;          // s between acceleration samples of the force-law fit
  double sample_every = 1e-3;       // s between rows of series.csv
};

// Follows the impactor (after every step).
class ImpactTracker : public Observer {
 public:
  // `surface`: the height depths are measured from (the bed's nominal surface);
  // `mean_top`: the mean top of the highest beads (the variant's reference).
  ImpactTracker(int body, double radius, double surface, double mean_top, double gravity, const ImpactSpec& spec)
      : body_(body), radius_(radius), surface_(surface), mean_top_(mean_top), g_(gravity), spec_(spec) {}
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void finish(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void summary(JsonObject& out) const override;
  std::string progress(const Model& m, const State& s) const override;
  void write_csv(const std::string& path) const;

  double stopping_depth() const { return surface_ - min_bottom_; }  // m below the nominal surface
  double stopping_depth_mean_top() const { return mean_top_ - min_bottom_; }  // m below the mean top
  double contact_time() const { return t_contact_; }                 // s, < 0 before contact
  double duration_1cm() const { return t_1cm_ >= 0 ? t_1cm_ - t_contact_ : -1; }
  double duration_1mm() const { return t_1mm_ >= 0 ? t_1mm_ - t_contact_ : -1; }
  // Bounce (docs/scenes.md C.1): the sphere's bottom rose by more than 0.1 mm
  // above the lowest point it had reached, or it moved up faster than 1 cm/s;
  // the variant: it ever moved up faster than 1 mm/s.
  bool bounced() const { return rebound_ > 1e-4 || max_up_ > 1e-2; }
  bool bounced_1mm_s() const { return max_up_ > 1e-3; }
  double rebound() const { return rebound_; }  // largest rise above the lowest point reached before, m
  double max_upward_speed() const { return max_up_; }
  double f0() const { return f0_; }            // N
  double inv_d1() const { return inv_d1_; }    // 1/m
  double fit_rms() const { return fit_rms_; }  // m/s^2, residual of the fit
  int fit_samples() const { return int(fit_v_.size()); }

 private:
  int body_;
  double radius_, surface_, mean_top_, g_;
  ImpactSpec spec_;
  double mass_ = 1;
  double min_bottom_ = 1e300;
  double rebound_ = 0;  // largest rise of the bottom above its lowest point so far, m
  double t_contact_ = -1, t_1cm_ = -1, t_1mm_ = -1, t_rest_from_ = -1, max_up_ = 0;
  double fit_t0_ = 0, fit_v0_ = 0;
  std::vector<double> fit_v_, fit_a_;
  double f0_ = 0, inv_d1_ = 0, fit_rms_ = 0;
  struct Row {
    double t, depth, v, a;
  };
  std::vector<Row> rows_;
};

class ImpactScene : public Scene {
 public:
  std::string kind() const override { return "impact"; }
  double bed_top() const override { return surface; }
  std::unique_ptr<SceneRun> begin(Run& run) const override;

  std::string file;
  ImpactSpec spec;
  int body = -1;
  double radius = 0;         // sphere radius, m
  double surface = 0;        // nominal bed surface H: the last cut's height (tops; centres + largest radius), m
  double mean_top = 0;       // mean top of the highest A/d^2 beads, m
  double first_touch = 0;    // highest position of the sphere's bottom at which it meets a bead, m
  double container_radius = 0;
  int bed_grains = 0;
  double bed_mass = 0, bulk_density = 0, packing = 0, grain_diameter = 0;
  std::string bed_cache;
};

class ImpactRun : public SceneRun {
 public:
  ImpactRun(const ImpactScene& scene, const Model& m);
  std::vector<Observer*> observers() override { return {&tracker_}; }
  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override;
  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override;
  std::vector<std::pair<std::string, std::string>> files() const override;
  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override;
  const ImpactTracker& tracker() const { return tracker_; }

 private:
  const ImpactScene& scene_;
  ImpactTracker tracker_;
};

std::shared_ptr<const SceneKind> impact_kind();

}  // namespace rt
