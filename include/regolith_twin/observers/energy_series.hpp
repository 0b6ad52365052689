// Energy and contact statistics of a run, and the motion of its small grain
// groups (impactors, probes): the series of a plain scenario.
#pragma once

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/run/run.hpp"

namespace rt {

class EnergySeries : public Observer {
 public:
  // Groups of at most this many grains are followed individually.
  static constexpr int kTrackedGroupMax = 8;
  // The run gives the current groups (a trim renumbers them) and held grains.
  explicit EnergySeries(const Run& run) : run_(run) {}
  void start(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void finish(const Model& m, const State& s) override;

  const Energy& initial() const { return initial_; }
  const Energy& final() const { return final_; }      // at the end (after a blow-up: not set)
  std::vector<const GrainGroup*> tracked() const;      // the groups followed
  // Mean position and velocity of a group.
  static Vec3 group_mean(const std::vector<Vec3>& a, const GrainGroup& g);

 private:
  const Run& run_;
  std::vector<std::string> tracked_names_;
  Energy initial_, final_;
};

}  // namespace rt
