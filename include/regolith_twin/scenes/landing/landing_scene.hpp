// The landing scene kind (`landing:` block, docs/scenes.md A): the scenario
// and landing block read, the bed relaxed once under the scene gravity and
// cached (run/bed_cache.hpp), the perturbed repeat applied and the lander
// placed; each run follows the lander (tracker), the active zone and the
// ejecta, and writes series.csv, surface.csv and summary.json.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/observers/active_zone.hpp"
#include "regolith_twin/observers/ejecta.hpp"
#include "regolith_twin/run/scene.hpp"
#include "regolith_twin/scenes/landing/landing.hpp"

namespace rt {

class LandingScene : public Scene {
 public:
  std::string kind() const override { return "landing"; }
  double bed_top() const override { return bed_top_; }
  std::unique_ptr<SceneRun> begin(Run& run) const override;

  std::string file;         // landing file it was read from
  LandingSpec spec;         // as given
  LandingSpec run_spec;     // with the perturbation of the repeat applied (aim)
  Perturbation pert;
  int lander = -1;          // body index of the lander
  std::string bed_cache;    // checkpoint of the relaxed bed
  double packing = 0;       // grains below the trim plane / container volume
  double bulk_density = 0;  // kg/m^3
  double bed_top_ = std::numeric_limits<double>::infinity();  // trim plane + mean radius, m
};

// One landing run: tracker, active zone, ejecta; the outcome assembled from them.
class LandingRun : public SceneRun {
 public:
  LandingRun(const LandingScene& scene, const Model& m);
  std::vector<Observer*> observers() override { return {&tracker_, &ejecta_}; }
  std::vector<Fix*> fixes() override { return {&zone_}; }
  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override;
  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override;
  std::vector<std::pair<std::string, std::string>> files() const override;
  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override;

  // The outcome so far (final: with the end-of-run checks; the run's observers must have finished).
  LandingOutcome outcome(const RunReport& rep, bool final) const;
  const LandingTrackerObserver& tracker() const { return tracker_; }
  const char* phase(bool ended) const { return ended ? "ended" : tracker_.tracker().phase(); }

 private:
  const LandingScene& scene_;
  LandingTrackerObserver tracker_;
  Ejecta ejecta_;
  ActiveZone zone_;
};

// The landing kind for the registry.
std::shared_ptr<const SceneKind> landing_kind();

// summary.json of a landing: input, bed, outcome, run figures.
void write_landing_summary(const std::string& path, const LandingScene& ls, const LandingOutcome& o, int threads,
                           const RunReport* rep = nullptr);

}  // namespace rt
