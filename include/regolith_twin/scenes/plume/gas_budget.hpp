// Where the eroded grains' upward momentum comes from (docs/scenes.md D,
// "Measurements of the mechanism"):
//
// - gas_force_at / gas_force_table_csv: the gas field's own drag and lift
//   (GasField::force) on a grain at a height above the anchoring plane, at
//   rest or moving along the flow at a fraction of the gas speed, against
//   its weight;
// - ImpulseObserver: for every grain, the vertical impulse from the gas and
//   from contacts (grains and floor) since its centre was last below the
//   bed surface (the erosion plane minus the erosion height), recorded at
//   each upward crossing of the erosion plane. The step's gas force is
//   evaluated as the field stage did (docs/model.md §7, §10): at the
//   predicted end-of-step velocity v(n+1) - (Δt/2)(F(n+1) - F(n))/m, with
//   the anchoring plane of that step; the contact force is the rest of the
//   step's force. Each step adds (Δt/2)(F(n) + F(n+1)) of each part, so
//   m v_z at the crossing = m v_z when last below the surface + the gas's
//   and the contacts' impulses + m g_z times the time since, to rounding.
//   The same sums are kept over the grain's current ascent (since its v_z
//   was last <= 0), which leaves out the support of a grain at rest, and the
//   largest lift over weight during that ascent;
// - columns of series.csv: the mean velocity along the flow of the grains
//   below the erosion plane, of those in the lowest layer (centre within
//   1 d of the floor, the lowest grain bottom at the start) and of those
//   above the erosion plane, and the mean and largest lift over weight of
//   the grains of the surface layer (centre within 1 d below the surface).
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/run/observer.hpp"

namespace rt {

// The gas on a grain of radius r at height h above the anchoring plane,
// moving along the flow at `fraction` of U(h) (no vertical velocity).
struct GasForceRow {
  double h = 0;           // above the anchoring plane, m
  double fraction = 0;    // grain speed along the flow / U(h)
  double u = 0;           // U(h), m/s
  double relative = 0;    // |v0|, m/s
  double omega_star = 0;  // |dU/dh| d / |v0| (0 at v0 = 0)
  double re = 0;          // Reynolds number of the relative speed
  double drag = 0;        // force along the flow, N
  double lift = 0;        // vertical force, N
};
GasForceRow gas_force_at(const GasField& gas, double radius, double h, double fraction);

// CSV: one row per height and fraction, forces also over the weight
// `weight` (N); `top` is the bed top's height above the anchoring plane (m),
// for the column of heights above the top.
std::string gas_force_table_csv(const GasField& gas, double radius, double weight, double top,
                                const std::vector<double>& heights, const std::vector<double>& fractions);

// One upward crossing of the erosion plane. Velocities in m/s: the
// impulses over the grain's mass.
struct ImpulseRecord {
  double t = 0;            // s
  int grain = -1;
  double since = 0;        // s since the grain's centre was last below the surface
  double v_start = 0;      // v_z when last below the surface
  double v = 0;            // v_z at the crossing
  double dv_gas = 0;       // gas impulse / m
  double dv_contact = 0;   // contact impulse / m
  double dv_gravity = 0;   // g_z * since
  // The same over the grain's current ascent (since v_z was last <= 0).
  double ascent = 0;            // s
  double ascent_v_start = 0;    // v_z at its start (<= 0, or v_z at the run start)
  double ascent_dv_gas = 0, ascent_dv_contact = 0, ascent_dv_gravity = 0;
  double ascent_max_lift = 0;   // largest gas force z over the weight during the ascent
};

class ImpulseObserver : public Observer {
 public:
  // surface_below_erosion: the bed surface's depth below the erosion plane, m.
  ImpulseObserver(int anchor_slot, int erosion_slot, double surface_below_erosion)
      : anchor_slot_(anchor_slot), erosion_slot_(erosion_slot), below_(surface_below_erosion) {}
  void start(const Model& m, const State& s) override;
  // Must run before an observer that moves the planes (it reads the planes
  // the step used).
  bool after_step(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void summary(JsonObject& out) const override;

  const std::vector<ImpulseRecord>& records() const { return records_; }
  // The running sums of grain i since its centre was last below the surface (m/s).
  double dv_gas(int i) const { return dv_gas_[i]; }
  double dv_contact(int i) const { return dv_contact_[i]; }
  double dv_gravity(int i) const { return dv_gravity_[i]; }
  double v_start(int i) const { return v_start_[i]; }
  // Over the current ascent: v_z = v_z at its start (<= 0) + these three.
  double ascent_dv_gas(int i) const { return asc_gas_[i]; }
  double ascent_dv_contact(int i) const { return asc_contact_[i]; }
  double ascent_dv_gravity(int i) const { return asc_gravity_[i]; }
  double ascent_v_start(int i) const { return asc_v_start_[i]; }
  bool tracking(int i) const { return tracking_[i] != 0; }
  // The gas force of the last step on grain i, N.
  const Vec3& gas_force(int i) const { return gas_prev_[i]; }
  void write_csv(const std::string& path) const;

 private:
  Vec3 gas_on(const Model& m, const State& s, int i, const Vec3& v, double anchor) const;
  int anchor_slot_, erosion_slot_;
  double below_;
  double floor_ = 0;  // lowest grain bottom at the start, m
  const GasField* gas_ = nullptr;
  std::vector<Vec3> force_prev_, gas_prev_;
  std::vector<double> dv_gas_, dv_contact_, dv_gravity_, v_start_, since_;
  std::vector<double> asc_gas_, asc_contact_, asc_gravity_, asc_v_start_, asc_since_, asc_max_lift_;
  std::vector<uint8_t> tracking_, above_;
  std::vector<ImpulseRecord> records_;
};

}  // namespace rt
