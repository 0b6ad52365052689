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

// The field stage: every field of m.fields over fixed blocks of grains (the
// force pass's m.partitions grain blocks), static OpenMP schedule, serial
// below m.parallel_min_grains grains. Fields act in the order of m.fields.
void apply_fields(const Model& m, State& s);

}  // namespace rt
