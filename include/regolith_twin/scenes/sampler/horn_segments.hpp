// Grains in the sampler horn (docs/scenes.md B.3): count and mass in each of
// its five segments over time, and the collected mass: the grains that left
// through the open top of cylinder 5 plus those inside cylinder 5 (the
// science requirement is 100 mg after about 1 s on the surface). A grain
// whose centre passes the top plane within the top opening (widened by its
// radius) is taken out of the run and logged. Series columns seg1_n..seg5_n,
// seg1_mass..seg5_mass (kg), collected_mass (kg).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "regolith_twin/run/observer.hpp"
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"
#include "regolith_twin/scenes/sampler/not_bed.hpp"

namespace rt {

struct HornCount {
  std::array<long, 5> count{};
  std::array<double, 5> mass{};  // kg
  long top_count = 0;            // left through the top
  double top_mass = 0;           // kg
  double collected_mass() const { return top_mass + mass[4]; }
};

class HornSegments : public Observer {
 public:
  struct Exit {
    double t = 0, mass = 0;
    Vec3 pos = Vec3::Zero(), vel = Vec3::Zero();
  };
  // projectile: grain left out of the counts (-1 none), as are grains added
  // during the run (a second projectile); checked every `every` steps.
  HornSegments(const HornGeometry& g, int projectile, int every, double requirement = 1e-4)
      : g_(g), not_bed_(projectile), every_(every), requirement_(requirement) {}
  void start(const Model& m, const State& s) override { count(m, s); }
  bool leaving(const Model& m, const State& s, std::vector<uint8_t>& drop) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  void grains_added(const Model& m, const State& s, int first) override { not_bed_.added(first, m.n_grains); }
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void finish(const Model& m, const State& s) override { count(m, s); }
  void summary(JsonObject& out) const override;
  std::string progress(const Model& m, const State& s) const override;

  const HornCount& now() const { return c_; }
  double collected_mass() const { return c_.collected_mass(); }  // kg
  double time_met() const { return t_met_; }   // s, -1 if the requirement was never met
  const std::vector<Exit>& exits() const { return exits_; }
  void write_csv(const std::string& path) const;  // the grains collected through the top

 private:
  void count(const Model& m, const State& s);
  HornGeometry g_;
  NotBed not_bed_;
  int every_;
  double requirement_;
  HornCount c_;
  double t_met_ = -1;
  std::vector<Exit> exits_;
};

}  // namespace rt
