// Field stage: per-grain forces (and torques) that depend on each grain's own
// state alone (a uniform acceleration, drag in a flow, ...). They are added
// to s.force / s.torque after the contact pass, in step() and in prime(), for
// every grain with inverse mass != 0; rigid bodies are not affected. As each
// grain's contribution depends only on that grain, the result is
// bit-identical for any thread count. With no fields the stage does nothing.
#pragma once

#include "regolith_twin/core/types.hpp"

namespace rt {

struct Model;
struct State;

// A per-grain force slot. apply() adds the field's force (and torque, if any)
// into s.force[i] / s.torque[i] for grains i in [begin, end), leaves grains
// with inverse mass 0 (glued) alone, writes nothing else, allocates nothing
// and does not throw (it runs inside an OpenMP region, on disjoint ranges of
// grains at once). Held by the Model as shared_ptr<const Field>: immutable.
class Field {
 public:
  virtual ~Field();
  virtual const char* name() const = 0;
  virtual void apply(const Model& m, State& s, int begin, int end) const = 0;
  // How many entries of State::field_values the field reads (prime() refuses
  // a state with fewer).
  virtual int state_values() const { return 0; }
};

// Uniform acceleration a: force m_i a on every free grain.
class UniformField final : public Field {
 public:
  explicit UniformField(const Vec3& acceleration);  // m/s^2, finite (else InputError)
  const char* name() const override { return "uniform"; }
  void apply(const Model& m, State& s, int begin, int end) const override;
  const Vec3& acceleration() const { return a_; }

 private:
  Vec3 a_;
};

// Linear (Stokes-like) drag toward a uniform flow: force -m_i gamma (v_i - u).
// The grain velocity is s.vel, i.e. the predicted v(n+1) in the step (v(n)
// in prime()), as the contact dashpots see it: the step stays second order.
class LinearDragField final : public Field {
 public:
  LinearDragField(double gamma, const Vec3& flow_velocity);  // 1/s >= 0, m/s; finite (else InputError)
  const char* name() const override { return "linear_drag"; }
  void apply(const Model& m, State& s, int begin, int end) const override;
  double gamma() const { return gamma_; }
  const Vec3& flow_velocity() const { return u_; }

 private:
  double gamma_;
  Vec3 u_;
};

// A gas flowing over the bed (docs/model.md §10): velocity U(h) along a
// horizontal direction e, h the height above an anchoring plane, acting on
// grains whose centre is above that plane with Loth's drag (gas.hpp)
//   F_D = C_D Re (pi d mu_g / 8) v0,   v0 = U(h) e - v_i,
// and, where the flow is sheared, Loth's lift, vertical:
//   F_L = C_L (pi d^2 rho_g / 8) |v0|^2 sign((v0 . e) dU/dh) z,
// with omega* = |dU/dh| d / |v0| (downward for a grain that outruns the gas).
// No fluid torque. U(h) = u0 + shear h + u_log ln(1 + h / h_log).
// The plane's height is s.field_values[anchor_slot] when anchor_slot >= 0
// (a scene moves it as the bed erodes; the state must hold that entry), else
// anchor_z.
struct GasFlowParams {
  double density = 0;       // rho_g, kg/m^3 (> 0)
  double viscosity = 0;     // mu_g, Pa s (> 0)
  double sound_speed = 0;   // c, m/s (> 0)
  double gamma = 1.33;      // ratio of specific heats (> 1)
  double tp_over_tg = 1;    // grain over gas temperature (> 0)
  Vec3 direction = Vec3::UnitX();  // e: horizontal, normalised on construction
  double u0 = 0;            // m/s
  double shear = 0;         // 1/s
  double u_log = 0;         // m/s
  double h_log = 0;         // m (> 0 when u_log != 0)
  double anchor_z = 0;      // m
  int anchor_slot = -1;     // index into State::field_values, or -1
  bool drag = true, lift = true;
  // A nozzle's plume instead of a uniform flow: with `radial`, e is the
  // horizontal unit vector from the point below the nozzle to the grain (no
  // flow right below it); with density_length L > 0 the density falls off
  // with the distance r from the nozzle as rho_g / (1 + r^2 / L^2).
  bool radial = false;
  Vec3 nozzle = Vec3::Zero();  // m
  double density_length = 0;   // m (<= 0: uniform density)

  double velocity(double h) const;  // U(h), m/s
  double gradient(double h) const;  // dU/dh, 1/s
};

class GasField final : public Field {
 public:
  explicit GasField(const GasFlowParams& p);  // InputError naming the value out of range
  const char* name() const override { return "gas"; }
  void apply(const Model& m, State& s, int begin, int end) const override;
  int state_values() const override { return p_.anchor_slot + 1; }
  const GasFlowParams& params() const { return p_; }
  // The anchoring plane's height in state s, m.
  double anchor(const State& s) const;
  // Drag and lift on a grain of radius r at height h above the plane moving
  // at v, N: in the uniform flow, and at position x (radial flow, density falloff).
  Vec3 force(double r, double h, const Vec3& v) const { return force(r, h, v, p_.direction, p_.density); }
  Vec3 force_at(double r, double h, const Vec3& x, const Vec3& v) const;

 private:
  Vec3 force(double r, double h, const Vec3& v, const Vec3& e, double rho) const;
  GasFlowParams p_;
};

// The field stage: every field of m.fields over fixed blocks of grains (the
// force pass's m.partitions grain blocks), static OpenMP schedule, serial
// below m.parallel_min_grains grains. Fields act in the order of m.fields.
void apply_fields(const Model& m, State& s);

}  // namespace rt
