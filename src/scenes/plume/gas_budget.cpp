// Gas against weight, and the eroded grains' upward impulses (see
// gas_budget.hpp; docs/scenes.md D).
#include "regolith_twin/scenes/plume/gas_budget.hpp"
#include "regolith_twin/core/hold.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "regolith_twin/core/model.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {

GasForceRow gas_force_at(const GasField& gas, double radius, double h, double fraction) {
  const GasFlowParams& p = gas.params();
  GasForceRow r;
  r.h = h;
  r.fraction = fraction;
  r.u = p.velocity(h);
  const Vec3 v = fraction * r.u * p.direction;
  r.relative = std::abs((1 - fraction) * r.u);
  r.omega_star = r.relative > 0 ? std::abs(p.gradient(h)) * 2 * radius / r.relative : 0;
  r.re = p.density * r.relative * 2 * radius / p.viscosity;
  const Vec3 f = gas.force(radius, h, v);
  r.drag = f.dot(p.direction);
  r.lift = f.z();
  return r;
}

std::string gas_force_table_csv(const GasField& gas, double radius, double weight, double top,
                                const std::vector<double>& heights, const std::vector<double>& fractions) {
  const double d = 2 * radius;
  std::ostringstream o;
  o << "# gas on a grain of " << d << " m at height h above the anchoring plane (the bed top at " << top / d
    << " d), moving along the flow at a fraction of U(h); forces in N and over the weight " << weight << " N\n";
  o << "h_d,above_top_d,fraction,u,relative,omega_star,re,drag,lift,drag_over_weight,lift_over_weight\n";
  o.precision(6);
  for (double h : heights)
    for (double f : fractions) {
      const GasForceRow r = gas_force_at(gas, radius, h, f);
      o << h / d << ',' << (h - top) / d << ',' << f << ',' << r.u << ',' << r.relative << ',' << r.omega_star << ','
        << r.re << ',' << r.drag << ',' << r.lift << ',' << r.drag / weight << ',' << r.lift / weight << '\n';
    }
  return o.str();
}

Vec3 ImpulseObserver::gas_on(const Model& m, const State& s, int i, const Vec3& v, double anchor) const {
  if (!gas_) return Vec3::Zero();
  const double h = s.pos[i].z() - anchor;
  if (!(h > 0)) return Vec3::Zero();  // as GasField::apply
  return gas_->force_at(m.grain_radius[i], h, s.pos[i], v);
}

void ImpulseObserver::start(const Model& m, const State& s) {
  gas_ = nullptr;
  for (const auto& f : m.fields)
    if (const auto* g = dynamic_cast<const GasField*>(f.get())) gas_ = g;
  const int n = m.n_grains;
  force_prev_.assign(s.force.begin(), s.force.begin() + n);  // F(0), forces valid after prime()
  gas_prev_.assign(n, Vec3::Zero());
  dv_gas_.assign(n, 0);
  dv_contact_.assign(n, 0);
  dv_gravity_.assign(n, 0);
  since_.assign(n, 0);
  v_start_.assign(n, 0);
  for (auto* v : {&asc_gas_, &asc_contact_, &asc_gravity_, &asc_v_start_, &asc_since_, &asc_max_lift_}) v->assign(n, 0);
  tracking_.assign(n, 0);
  above_.assign(n, 0);
  records_.clear();
  const double anchor = s.field_values[anchor_slot_], erosion = s.field_values[erosion_slot_];
  floor_ = 1e300;
  for (int i = 0; i < n; ++i) floor_ = std::min(floor_, s.pos[i].z() - m.grain_radius[i]);
  for (int i = 0; i < n; ++i) {
    // prime() evaluates the fields at v(n).
    if (!held(m, i)) gas_prev_[i] = gas_on(m, s, i, s.vel[i], anchor);
    v_start_[i] = asc_v_start_[i] = s.vel[i].z();
    tracking_[i] = s.pos[i].z() > erosion - below_;
    above_[i] = s.pos[i].z() > erosion;
  }
}

bool ImpulseObserver::after_step(const Model& m, const State& s) {
  // The planes as the step used them (the erosion fix moves them after the measures).
  const double anchor = s.field_values[anchor_slot_], erosion = s.field_values[erosion_slot_];
  const double surface = erosion - below_, h = 0.5 * m.dt, gz = m.gravity.z();
  for (int i = 0; i < m.n_grains; ++i) {
    const double im = m.grain_inv_mass[i];
    const Vec3 f = s.force[i];
    const double z = s.pos[i].z();
    if (im == 0) {  // held (collisionless study): no gas, nothing to add
      force_prev_[i] = f;
      gas_prev_[i].setZero();
    } else {
      const Vec3 v_pred = s.vel[i] - (h * im) * (f - force_prev_[i]);
      const Vec3 g = gas_on(m, s, i, v_pred, anchor);
      const double dg = h * im * (gas_prev_[i].z() + g.z());
      const double dc = h * im * ((force_prev_[i].z() - gas_prev_[i].z()) + (f.z() - g.z()));
      dv_gas_[i] += dg;
      dv_contact_[i] += dc;
      dv_gravity_[i] += gz * m.dt;
      since_[i] += m.dt;
      asc_gas_[i] += dg;
      asc_contact_[i] += dc;
      asc_gravity_[i] += gz * m.dt;
      asc_since_[i] += m.dt;
      if (gz != 0) asc_max_lift_[i] = std::max(asc_max_lift_[i], -g.z() * im / gz);
      force_prev_[i] = f;
      gas_prev_[i] = g;
    }
    if (z <= surface || im == 0) {  // below the surface: start again from here
      dv_gas_[i] = dv_contact_[i] = dv_gravity_[i] = since_[i] = 0;
      v_start_[i] = s.vel[i].z();
      tracking_[i] = 0;
    } else {
      tracking_[i] = 1;
    }
    if (s.vel[i].z() <= 0 || im == 0) {  // not rising: the ascent starts again from here
      asc_gas_[i] = asc_contact_[i] = asc_gravity_[i] = asc_since_[i] = asc_max_lift_[i] = 0;
      asc_v_start_[i] = s.vel[i].z();
    }
    const uint8_t a = z > erosion;
    if (a && !above_[i]) {
      ImpulseRecord r;
      r.t = s.time;
      r.grain = i;
      r.since = since_[i];
      r.v_start = v_start_[i];
      r.v = s.vel[i].z();
      r.dv_gas = dv_gas_[i];
      r.dv_contact = dv_contact_[i];
      r.dv_gravity = dv_gravity_[i];
      r.ascent = asc_since_[i];
      r.ascent_v_start = asc_v_start_[i];
      r.ascent_dv_gas = asc_gas_[i];
      r.ascent_dv_contact = asc_contact_[i];
      r.ascent_dv_gravity = asc_gravity_[i];
      r.ascent_max_lift = asc_max_lift_[i];
      records_.push_back(r);
    }
    above_[i] = a;
  }
  return false;
}

void ImpulseObserver::summary(JsonObject& out) const {
  JsonObject o;
  const double n = double(records_.size());
  double since = 0, v0 = 0, v = 0, gas = 0, con = 0, grav = 0, gas_more = 0, gas_lifts = 0;
  double a_time = 0, a_gas = 0, a_con = 0, a_grav = 0, a_gas_more = 0, a_max_lift = 0, a_lift_above = 0;
  for (const ImpulseRecord& r : records_) {
    a_time += r.ascent;
    a_gas += r.ascent_dv_gas;
    a_con += r.ascent_dv_contact;
    a_grav += r.ascent_dv_gravity;
    a_gas_more += r.ascent_dv_gas > r.ascent_dv_contact;
    a_max_lift = std::max(a_max_lift, r.ascent_max_lift);
    a_lift_above += r.ascent_max_lift > 1;
    since += r.since;
    v0 += r.v_start;
    v += r.v;
    gas += r.dv_gas;
    con += r.dv_contact;
    grav += r.dv_gravity;
    gas_more += r.dv_gas > r.dv_contact;
    gas_lifts += r.dv_gas + r.dv_gravity > 0;
  }
  const double k = n > 0 ? 1 / n : 0;
  o.num("upward_crossings", n);
  o.num("mean_since", since * k).num("mean_v_start", v0 * k).num("mean_v", v * k);
  o.num("mean_dv_gas", gas * k).num("mean_dv_contact", con * k).num("mean_dv_gravity", grav * k);
  o.num("fraction_gas_above_contact", gas_more * k).num("fraction_gas_above_weight", gas_lifts * k);
  o.num("ascent_mean_time", a_time * k).num("ascent_mean_dv_gas", a_gas * k);
  o.num("ascent_mean_dv_contact", a_con * k).num("ascent_mean_dv_gravity", a_grav * k);
  o.num("ascent_fraction_gas_above_contact", a_gas_more * k);
  o.num("ascent_max_lift_over_weight", a_max_lift).num("ascent_fraction_lift_above_weight", a_lift_above * k);
  out.obj("impulse", o);
}

void ImpulseObserver::columns(std::vector<std::string>& out) const {
  for (const char* c : {"bed_vx", "floor_layer_vx", "lifted_vx", "surface_layer_lift", "surface_layer_lift_max"})
    out.push_back(c);
}

void ImpulseObserver::row(const Model& m, const State& s, std::vector<double>& out) const {
  const double erosion = s.field_values[erosion_slot_], surface = erosion - below_;
  double bed = 0, floor = 0, lifted = 0, lift = 0, lift_max = 0;
  int nb = 0, nf = 0, nl = 0, ns = 0;
  for (int i = 0; i < m.n_grains && i < int(gas_prev_.size()); ++i) {
    const double z = s.pos[i].z(), vx = s.vel[i].x();
    if (z > erosion) {
      lifted += vx;
      ++nl;
      continue;
    }
    bed += vx;
    ++nb;
    if (z < floor_ + 2 * m.grain_radius[i]) {
      floor += vx;
      ++nf;
    }
    if (z <= surface && z > surface - 2 * m.grain_radius[i] && !held(m, i) && m.gravity.z() != 0) {
      const double l = -gas_prev_[i].z() * m.grain_inv_mass[i] / m.gravity.z();
      lift += l;
      lift_max = std::max(lift_max, l);
      ++ns;
    }
  }
  out.push_back(nb ? bed / nb : 0);
  out.push_back(nf ? floor / nf : 0);
  out.push_back(nl ? lifted / nl : 0);
  out.push_back(ns ? lift / ns : 0);
  out.push_back(lift_max);
}

void ImpulseObserver::write_csv(const std::string& path) const {
  std::ostringstream f;
  f << "# upward crossings of the erosion plane: time (s), grain, time since its centre was last below the "
       "surface (s), v_z then and at the crossing, and the vertical impulses over its mass since then from the "
       "gas, the contacts and gravity (m/s): v = v_start + dv_gas + dv_contact + dv_gravity\n";
  f << "# and the same over its current ascent (since its v_z was last <= 0): duration (s), impulses over "
       "its mass (m/s), the largest lift over weight during it; v = ascent_v_start + the three ascent impulses\n";
  f << "t,grain,since,v_start,v,dv_gas,dv_contact,dv_gravity,ascent,ascent_v_start,ascent_dv_gas,ascent_dv_contact,"
       "ascent_dv_gravity,ascent_max_lift\n";
  f.precision(6);
  for (const ImpulseRecord& r : records_)
    f << r.t << ',' << r.grain << ',' << r.since << ',' << r.v_start << ',' << r.v << ',' << r.dv_gas << ','
      << r.dv_contact << ',' << r.dv_gravity << ',' << r.ascent << ',' << r.ascent_v_start << ','
      << r.ascent_dv_gas << ',' << r.ascent_dv_contact << ',' << r.ascent_dv_gravity << ',' << r.ascent_max_lift << '\n';
  write_file(path, f.str());
}

}  // namespace rt
