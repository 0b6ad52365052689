// Active zone (a fix, run/fix.hpp): grains farther than a radius (horizontally) from a body's
// vertical axis stay frozen where the start state left them (infinite mass,
// at rest); the zone follows the body, checked every `every` steps once it
// has moved 2 cm, and a grain once woken stays free. Changes the model's
// inverse masses, so neighbour lists and forces are rebuilt when it acts.
// At the end it reports the free grains and the RMS speed in the zone's outer
// ring, ejecta left out, which shows whether the frozen bed beyond was at rest.
#pragma once

#include "regolith_twin/observers/ejecta.hpp"
#include "regolith_twin/run/fix.hpp"

namespace rt {

class ActiveZone : public Fix {
 public:
  // radius 0: every grain stays free. `ejecta` (may be null) are left out of the edge check.
  ActiveZone(int body, double radius, double ring, int every, const Ejecta* ejecta)
      : body_(body), radius_(radius), ring_(ring), every_(every), ejecta_(ejecta) {}
  void prepare(Model& m, State& s) override;
  void after_measures(Model& m, State& s) override;
  void finish(Model& m, State& s) override;
  void summary(JsonObject& out) const override {
    out.num("active_radius", radius_).num("active_grains", double(active_)).num("active_edge_rms_speed", edge_rms_);
  }

  void grains_removed(const std::vector<int>& old_to_new) override;

  long active_grains() const { return active_; }  // free grains at the end
  double edge_rms() const { return edge_rms_; }    // m/s
  double radius() const { return radius_; }

 private:
  bool update(Model& m, State& s, const Vec3& c, bool first);
  int body_;
  double radius_, ring_;
  int every_;
  const Ejecta* ejecta_;
  std::vector<uint8_t> fixed0_, woken_;
  Vec3 last_ = Vec3::Zero();
  long active_ = 0;
  double edge_rms_ = 0;
};

}  // namespace rt
