// Packing fraction below the horn's filter (docs/scenes.md B.3), the
// jamming check: the solid fraction in 1 mm slices along the horn axis,
// going down from the bottom of the filter plates through the straight neck
// of cylinder 4 and below it — grain volume inside the inner wall within the
// slice over the slice's inner volume. Measured at the run end. The horn axis
// is taken vertical (as the sampler scene places it).
#pragma once

#include <vector>

#include "regolith_twin/run/observer.hpp"
#include "regolith_twin/scenes/sampler/horn_geometry.hpp"

namespace rt {

class PackingBelowFilter : public Observer {
 public:
  explicit PackingBelowFilter(const HornGeometry& g, double slice = 1e-3, int slices = 45)
      : g_(g), slice_(slice), n_(slices) {}
  void finish(const Model& m, const State& s) override { prof_ = profile(m, s); }
  void summary(JsonObject& out) const override;
  // Solid fraction of slice k = [filter_bottom - (k+1) slice, filter_bottom - k slice] (horn frame).
  std::vector<double> profile(const Model& m, const State& s) const;
  const std::vector<double>& last() const { return prof_; }

 private:
  HornGeometry g_;
  double slice_;
  int n_;
  std::vector<double> prof_;
};

}  // namespace rt
