// Field stage: per-grain forces added after the contact pass (see field.hpp).
#include "regolith_twin/core/field.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "regolith_twin/core/state.hpp"

namespace rt {

namespace {
bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
}  // namespace

Field::~Field() = default;

UniformField::UniformField(const Vec3& acceleration) : a_(acceleration) {
  if (!finite(a_)) throw InputError("uniform field: the acceleration must be finite");
}

void UniformField::apply(const Model& m, State& s, int begin, int end) const {
  const double* __restrict inv_mass = m.grain_inv_mass.data();
  Vec3* __restrict force = s.force.data();
  const Vec3 a = a_;
  for (int i = begin; i < end; ++i) {
    const double im = inv_mass[i];
    if (im == 0) continue;  // glued grain
    force[i] += a / im;
  }
}

LinearDragField::LinearDragField(double gamma, const Vec3& flow_velocity) : gamma_(gamma), u_(flow_velocity) {
  if (!(std::isfinite(gamma_) && gamma_ >= 0)) {
    std::ostringstream os;
    os << "linear drag field: gamma = " << gamma_ << " 1/s out of range (allowed finite, >= 0)";
    throw InputError(os.str());
  }
  if (!finite(u_)) throw InputError("linear drag field: the flow velocity must be finite");
}

void LinearDragField::apply(const Model& m, State& s, int begin, int end) const {
  const double* __restrict inv_mass = m.grain_inv_mass.data();
  // s.vel: the predicted v(n+1) that the dashpots see (v(n) in prime()).
  const Vec3* __restrict vel = s.vel.data();
  Vec3* __restrict force = s.force.data();
  const double gamma = gamma_;
  const Vec3 u = u_;
  for (int i = begin; i < end; ++i) {
    const double im = inv_mass[i];
    if (im == 0) continue;  // glued grain
    force[i] -= (gamma / im) * (vel[i] - u);
  }
}

void apply_fields(const Model& m, State& s) {
  if (m.fields.empty()) return;
  const int n = m.n_grains;
  // Fixed blocks of grains, as the force pass merges them: a thread adds to
  // the forces it has just merged. Any split gives the same result.
  const int P = std::max(1, m.partitions);
#pragma omp parallel for schedule(static) if (n >= m.parallel_min_grains)
  for (int q = 0; q < P; ++q) {
    const int begin = int(long(n) * q / P), end = int(long(n) * (q + 1) / P);
    for (const auto& f : m.fields) f->apply(m, s, begin, end);
  }
}

}  // namespace rt
