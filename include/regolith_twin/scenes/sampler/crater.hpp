// Crater depth and radius from local solid fractions (docs/scenes.md B.3):
// the grain volume overlapping each cell over the cell volume, in 1 mm layers
// of a vertical column of 10 mm radius under the impact point (depth), and in
// 1 mm rings about the axis over the top 10 mm of the bed (radius). The
// pre-impact profiles are taken at start(); the crater edge is the first
// layer (going down) or ring (going out) whose solid fraction is back to at
// least `threshold` (50 %) of its pre-impact value; layers and rings whose
// pre-impact fraction is below 0.1 (the rough surface) are passed over. The
// projectile is not counted, nor grains added during the run. Series columns crater_depth, crater_radius (m).
#pragma once

#include <vector>

#include "regolith_twin/run/observer.hpp"
#include "regolith_twin/scenes/sampler/not_bed.hpp"

namespace rt {

// Volume of the sphere (centre c, radius r) inside the cell z0 <= z <= z1,
// r_in <= distance from the vertical axis through axis_point <= r_out, m^3:
// slices of the sphere in z by 24-point Gauss-Legendre quadrature, each
// slice's disk intersected exactly with the annulus (circle-circle lens areas).
double sphere_cell_volume(const Vec3& c, double r, double z0, double z1, double r_in, double r_out,
                          const Vec3& axis_point);

class Crater : public Observer {
 public:
  // impact: on the surface (x, y: the axis; z: the surface reference the depth is measured from).
  Crater(const Vec3& impact, int projectile, int every, double threshold = 0.5, double column_radius = 0.01,
         double layer = 1e-3, double max_depth = 0.15, double ring_depth = 0.01, double max_radius = 0.15);
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  void grains_added(const Model& m, const State& s, int first) override { not_bed_.added(first, m.n_grains); }
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void finish(const Model& m, const State& s) override { measure(m, s); }
  void summary(JsonObject& out) const override;

  double depth() const { return depth_; }    // m
  double radius() const { return radius_; }  // m
  const std::vector<double>& column_profile() const { return col_; }
  const std::vector<double>& ring_profile() const { return ring_; }
  const std::vector<double>& initial_column() const { return col0_; }
  const std::vector<double>& initial_rings() const { return ring0_; }
  // The column and ring solid fractions of a state.
  void profiles(const Model& m, const State& s, std::vector<double>& col, std::vector<double>& ring) const;

 private:
  void measure(const Model& m, const State& s);
  Vec3 impact_;
  NotBed not_bed_;
  int every_;
  double threshold_, col_r_, layer_, max_depth_, ring_depth_, max_radius_;
  std::vector<double> col0_, ring0_, col_, ring_;
  double depth_ = 0, radius_ = 0;
};

}  // namespace rt
