// Field stage: per-grain forces added after the contact pass (see field.hpp).
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "regolith_twin/core/gas.hpp"
#include "regolith_twin/core/model.hpp"
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

double GasFlowParams::velocity(double h) const {
  return u0 + shear * h + (u_log != 0 ? u_log * std::log1p(h / h_log) : 0.0);
}

double GasFlowParams::gradient(double h) const { return shear + (u_log != 0 ? u_log / (h_log + h) : 0.0); }

GasField::GasField(const GasFlowParams& p) : p_(p) {
  auto need = [](bool ok, const char* what, double v, const char* range) {
    if (ok) return;
    std::ostringstream os;
    os << "gas field: " << what << " = " << v << " out of range (allowed " << range << ")";
    throw InputError(os.str());
  };
  need(std::isfinite(p.density) && p.density > 0, "density", p.density, "finite, > 0 kg/m^3");
  need(std::isfinite(p.viscosity) && p.viscosity > 0, "viscosity", p.viscosity, "finite, > 0 Pa s");
  need(std::isfinite(p.sound_speed) && p.sound_speed > 0, "sound_speed", p.sound_speed, "finite, > 0 m/s");
  need(std::isfinite(p.gamma) && p.gamma > 1, "gamma", p.gamma, "finite, > 1");
  need(std::isfinite(p.tp_over_tg) && p.tp_over_tg > 0, "tp_over_tg", p.tp_over_tg, "finite, > 0");
  need(std::isfinite(p.u0), "u0", p.u0, "finite");
  need(std::isfinite(p.shear), "shear", p.shear, "finite");
  need(std::isfinite(p.u_log), "u_log", p.u_log, "finite");
  need(p.u_log == 0 || (std::isfinite(p.h_log) && p.h_log > 0), "h_log", p.h_log, "finite, > 0 m with u_log");
  need(std::isfinite(p.anchor_z), "anchor_z", p.anchor_z, "finite");
  need(p.anchor_slot >= -1, "anchor_slot", p.anchor_slot, ">= -1");
  need(std::isfinite(p.density_length) && p.density_length >= 0, "density_length", p.density_length,
       "finite, >= 0 m");
  if (!finite(p.nozzle)) throw InputError("gas field: the nozzle position must be finite");
  if (!finite(p.direction) || p.direction.z() != 0 || !(p.direction.norm() > 0))
    throw InputError("gas field: the flow direction must be a finite horizontal vector (z = 0), not zero");
  p_.direction = p.direction.normalized();
}

double GasField::anchor(const State& s) const {
  return p_.anchor_slot >= 0 ? s.field_values[p_.anchor_slot] : p_.anchor_z;  // size checked by prime()
}

Vec3 GasField::force_at(double r, double h, const Vec3& x, const Vec3& v) const {
  Vec3 e = p_.direction;
  double rho = p_.density;
  if (p_.radial) {
    const Vec3 out(x.x() - p_.nozzle.x(), x.y() - p_.nozzle.y(), 0);
    const double n = out.norm();
    e = n > 0 ? Vec3(out / n) : Vec3(Vec3::Zero());
  }
  if (p_.density_length > 0) rho /= 1 + (x - p_.nozzle).squaredNorm() / (p_.density_length * p_.density_length);
  return force(r, h, v, e, rho);
}

Vec3 GasField::force(double r, double h, const Vec3& v, const Vec3& e, double rho) const {
  const double d = 2 * r;
  const double u = p_.velocity(h);
  const Vec3 v0 = u * e - v;
  const double speed = v0.norm();
  const double re = rho * speed * d / p_.viscosity, ma = speed / p_.sound_speed;
  GasConstants g;
  g.gamma = p_.gamma;
  g.tp_over_tg = p_.tp_over_tg;
  g.kn = knudsen_number(p_.gamma, p_.viscosity, rho, d, p_.sound_speed);
  Vec3 f = Vec3::Zero();
  if (p_.drag) f += loth_drag_re(re, ma, g) * (kPi * d * p_.viscosity / 8) * v0;
  const double grad = p_.gradient(h);
  const double along = v0.dot(e);
  if (p_.lift && speed > 0 && grad != 0 && along != 0) {
    const double omega_star = std::abs(grad) * d / speed;
    const double sign = (along > 0) == (grad > 0) ? 1.0 : -1.0;
    f.z() += sign * loth_lift(re, omega_star) * (kPi * d * d * rho / 8) * speed * speed;
  }
  return f;
}

void GasField::apply(const Model& m, State& s, int begin, int end) const {
  const double* __restrict inv_mass = m.grain_inv_mass.data();
  const double* __restrict radius = m.grain_radius.data();
  // s.vel: the predicted v(n+1) that the dashpots see (v(n) in prime()).
  const Vec3* __restrict pos = s.pos.data();
  const Vec3* __restrict vel = s.vel.data();
  Vec3* __restrict force = s.force.data();
  const double z0 = anchor(s);
  const bool local = p_.radial || p_.density_length > 0;
  for (int i = begin; i < end; ++i) {
    if (inv_mass[i] == 0) continue;  // glued grain
    const double h = pos[i].z() - z0;
    if (!(h > 0)) continue;  // at or below the anchoring plane: no gas
    force[i] += local ? force_at(radius[i], h, pos[i], vel[i]) : this->force(radius[i], h, vel[i]);
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
