// Ejecta: grains whose centre rises above a plane (z = height) during the
// run, sampled every `every` steps; grains above it at the start are not
// counted. A grain counts once, with its volume.
#pragma once

#include "regolith_twin/run/observer.hpp"

namespace rt {

class Ejecta : public Observer {
 public:
  Ejecta(double height, int every) : height_(height), every_(every) {}
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override { out.push_back("ejected_grains"); }
  void row(const Model& m, const State& s, std::vector<double>& out) const override { out.push_back(double(count_)); }
  void summary(JsonObject& out) const override {
    out.num("ejected_grains", double(count_)).num("ejected_volume", volume_);
  }

  void grains_removed(const std::vector<int>& old_to_new) override;

  long count() const { return count_; }
  double volume() const { return volume_; }  // m^3
  bool ejected(int i) const { return flag_[i] != 0; }

 private:
  double height_;
  int every_;
  std::vector<uint8_t> flag_, above0_;
  long count_ = 0;
  double volume_ = 0;
};

}  // namespace rt
