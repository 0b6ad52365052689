// Grains in a region (an axis-aligned box; unbounded sides at +-infinity):
// their count and mass after every step, as two series columns
// "<name>_count" and "<name>_mass" (kg).
#pragma once

#include <string>

#include "regolith_twin/run/observer.hpp"

namespace rt {

class RegionCount : public Observer {
 public:
  RegionCount(std::string name, const Vec3& lo, const Vec3& hi) : name_(std::move(name)), lo_(lo), hi_(hi) {}
  void start(const Model& m, const State& s) override { count(m, s); }
  bool after_step(const Model& m, const State& s) override {
    count(m, s);
    return false;
  }
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void summary(JsonObject& out) const override { out.num(name_ + "_count", double(n_)).num(name_ + "_mass", mass_); }

  const std::string& name() const { return name_; }
  long grains() const { return n_; }
  double mass() const { return mass_; }

 private:
  void count(const Model& m, const State& s);
  std::string name_;
  Vec3 lo_, hi_;
  long n_ = 0;
  double mass_ = 0;
};

}  // namespace rt
