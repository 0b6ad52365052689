// Analytic verification of binary collisions (see collisions.hpp).
#include "regolith_twin/validate/collisions.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/walls.hpp"

namespace rt::validate {
namespace {


double sphere_mass(double r, double density) { return 4.0 / 3.0 * kPi * r * r * r * density; }

// Contacts (grain–grain and grain–wall) found by the last force pass.
long live_contacts(const State& s) { return s.stats.contacts + s.stats.wall_contacts; }

}  // namespace

// ---------------------------------------------------------------------------
const char* pair_kind_name(PairKind k) { return k == PairKind::GrainGrain ? "grain-grain" : "grain-wall"; }

LinearImpactOutcome run_linear_impact(const LinearImpactSetup& c) {
  Model m;
  Material g;
  g.name = "grain";
  g.density = c.density;
  g.eps_n = c.eps_n;
  g.eps_t = 1.0;
  g.mu_s = 0.0;  // head-on: friction plays no part; zero makes that explicit
  g.mu_r = g.mu_t = 0.0;
  m.materials.push_back(g);
  m.gravity.setZero();
  const double r = c.radius;
  const double mp = sphere_mass(r, c.density);
  const double v = c.speed;
  LinearImpactOutcome out;
  out.x_max = c.xmax_fraction * r;
  out.kn = kn_rule(mp, v, out.x_max);
  out.dt = dt_rule(mp, out.kn, c.steps);
  m.kn = out.kn;
  m.dt = out.dt;
  m.guards.allow_under_resolved = true;
  m.partitions = 1;

  const bool wall = c.kind == PairKind::GrainWall;
  rt::add_grain(m, r, 0);
  if (wall) {
    Material w = g;
    w.name = "wall";
    w.structure = true;
    m.materials.push_back(w);
    m.walls.push_back(make_plane(Vec3::Zero(), Vec3::UnitX(), 1));
  } else {
    rt::add_grain(m, r, 0);
  }
  finalize_model(m);
  out.mstar = wall ? mp : 0.5 * mp;
  out.t_contact = linear_contact_time(out.mstar, out.kn, c.eps_n);

  // Surface gap closed after (1 + phase) steps of free flight.
  const double gap = v * out.dt * (1.0 + c.phase);
  State s = make_state(m);
  if (wall) {
    s.pos[0] = Vec3(r + gap, 0, 0);
    s.vel[0] = Vec3(-v, 0, 0);
  } else {
    s.pos[0] = Vec3(-(r + 0.5 * gap), 0, 0);
    s.pos[1] = Vec3(r + 0.5 * gap, 0, 0);
    s.vel[0] = Vec3(0.5 * v, 0, 0);
    s.vel[1] = Vec3(-0.5 * v, 0, 0);
  }
  const long budget = long(10 * out.t_contact / out.dt) + 100;
  long first = -1, last = -1;
  for (long k = 0; k < budget; ++k) {
    step(m, s);
    const double x = wall ? r - s.pos[0].x() : 2 * r - (s.pos[1].x() - s.pos[0].x());
    if (live_contacts(s) > 0) {
      if (first < 0) first = k;
      last = k;
      out.max_overlap = std::max(out.max_overlap, x);
    } else if (first >= 0) {
      out.ended = true;
      break;
    }
  }
  out.contact_steps = first < 0 ? 0 : int(last - first + 1);
  out.t_measured = out.contact_steps * out.dt;
  const double un_after = wall ? s.vel[0].x() : s.vel[1].x() - s.vel[0].x();
  out.eps_measured = un_after / v;
  return out;
}

PhaseSweep sweep_phases(PairKind kind, double eps_n, double steps, int n_phases) {
  PhaseSweep ps;
  ps.kind = kind;
  ps.eps_n = eps_n;
  ps.steps = steps;
  ps.n_phases = n_phases;
  ps.eps_min = std::numeric_limits<double>::infinity();
  ps.eps_max = -ps.eps_min;
  double sum = 0, sum_abs = 0;
  for (int p = 0; p < n_phases; ++p) {
    LinearImpactSetup c;
    c.kind = kind;
    c.eps_n = eps_n;
    c.steps = steps;
    c.phase = (p + 0.5) / n_phases;
    const LinearImpactOutcome o = run_linear_impact(c);
    ps.t_contact = o.t_contact;
    ps.dt = o.dt;
    ps.steps_per_contact = o.t_contact / o.dt;
    const double e = o.eps_measured;
    const double rel = std::fabs(e - eps_n) / eps_n;
    sum += e;
    sum_abs += rel;
    ps.eps_min = std::min(ps.eps_min, e);
    ps.eps_max = std::max(ps.eps_max, e);
    ps.worst_abs_error = std::max(ps.worst_abs_error, rel);
    ps.worst_duration_error = std::max(ps.worst_duration_error, std::fabs(o.t_measured - o.t_contact) / o.dt);
    ps.max_overlap_ratio = std::max(ps.max_overlap_ratio, o.max_overlap / o.x_max);
    ps.all_ended = ps.all_ended && o.ended;
  }
  ps.eps_mean = sum / n_phases;
  ps.mean_error = (ps.eps_mean - eps_n) / eps_n;
  ps.mean_abs_error = sum_abs / n_phases;
  return ps;
}

std::vector<double> convergence_steps() { return {8, 12, 18, 30, 48, 80, 140, 240}; }

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = std::min(x.size(), y.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// ---------------------------------------------------------------------------
HertzElastic hertz_elastic_impact(double mstar, double reff, double e_star, double v) {
  HertzElastic h;
  h.max_overlap = std::pow(15.0 * mstar * v * v / (16.0 * e_star * std::sqrt(reff)), 0.4);
  h.max_force = 4.0 / 3.0 * e_star * std::sqrt(reff) * std::pow(h.max_overlap, 1.5);
  // t_c = 2 x_max/v * int_0^1 (1 - u^(5/2))^(-1/2) du = 4/5 B(2/5, 1/2) x_max / v.
  const double beta = std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
  h.contact_time = 0.8 * beta * h.max_overlap / v;
  return h;
}

double hertz_damping_prefactor_model(double e) {
  if (e >= 1.0) return 0.0;
  const double l = std::log(e);
  return 2.0 * std::sqrt(5.0 / 6.0) * std::fabs(l) / std::sqrt(l * l + kPi * kPi);
}

namespace {

// Right-hand side of the dimensionless Hertz contact with damping.
inline void hertz_rhs(double a2, double xi, double eta, double& dxi, double& deta) {
  const double xp = xi > 0 ? xi : 0.0;
  const double sx = std::sqrt(xp);
  dxi = eta;
  deta = -4.0 / 3.0 * xp * sx - a2 * std::sqrt(sx) * eta;
}

// Exit speed of the dimensionless contact (RK4). The step is h0, reduced to
// 1 % of xi / |xi'| (not below h0 * 1e-3) where xi is small: there xi^(1/4)
// is not smooth. Returns 0 if the contact has not ended by tau = 50.
double hertz_exit_speed(double alpha, double h0) {
  const double a2 = std::sqrt(2.0) * alpha;
  double xi = 0, eta = 1, tau = 0;
  const double tau_max = 50.0;
  while (tau < tau_max) {
    const double h = std::clamp(0.01 * xi / (std::fabs(eta) + 1e-300), 1e-3 * h0, h0);
    double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
    hertz_rhs(a2, xi, eta, k1x, k1v);
    hertz_rhs(a2, xi + 0.5 * h * k1x, eta + 0.5 * h * k1v, k2x, k2v);
    hertz_rhs(a2, xi + 0.5 * h * k2x, eta + 0.5 * h * k2v, k3x, k3v);
    hertz_rhs(a2, xi + h * k3x, eta + h * k3v, k4x, k4v);
    const double xn = xi + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double vn = eta + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (tau > 0 && xn <= 0) {
      // Crossing of xi = 0 inside the step: interpolate the speed linearly in xi.
      const double f = xi / (xi - xn);
      return -(eta + f * (vn - eta));
    }
    xi = xn;
    eta = vn;
    tau += h;
  }
  return 0.0;
}

}  // namespace

double hertz_restitution(double alpha) {
  if (alpha <= 0) return 1.0;
  return hertz_exit_speed(alpha, 1e-3);
}

double hertz_damping_prefactor_calibrated(double e) {
  if (!(e > 0 && e <= 1)) throw std::invalid_argument("hertz_damping_prefactor_calibrated: e must be in (0, 1]");
  if (e >= 1.0) return 0.0;
  // e(alpha) decreases monotonically from 1 at alpha = 0: bracket the root,
  // then regula falsi with the Illinois modification.
  double lo = 0.0, f_lo = 1.0 - e;
  double hi = std::max(0.1, 2.0 * hertz_damping_prefactor_model(e)), f_hi = hertz_restitution(hi) - e;
  while (f_hi > 0) {
    lo = hi;
    f_lo = f_hi;
    hi *= 2;
    if (hi > 1e3) throw std::runtime_error("hertz_damping_prefactor_calibrated: no bracket");
    f_hi = hertz_restitution(hi) - e;
  }
  int side = 0;
  double a = 0.5 * (lo + hi);
  for (int it = 0; it < 100; ++it) {
    a = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    const double f = hertz_restitution(a) - e;
    if (std::fabs(f) < 1e-13 || hi - lo < 1e-13 * hi) break;
    if (f > 0) {
      lo = a;
      f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = a;
      f_hi = f;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
  }
  return a;
}

// ---------------------------------------------------------------------------
// Chung & Ooi (2011) materials of tests 1–4 (E in Pa, nu, rho in kg/m^3):
// test 1 glass and limestone spheres, R = 10 mm, 10 m/s each; test 2
// aluminium and magnesium alloy spheres, R = 0.1 m, 0.2 m/s on a rigid plane;
// tests 3–4 aluminium oxide, R = 2.5 mm, 3.9 m/s (test 4: mu = 0.092, e = 0.98).
ElasticMaterial chung_ooi_glass() { return {"glass", 4.8e10, 0.20, 2800}; }
ElasticMaterial chung_ooi_limestone() { return {"limestone", 2.0e10, 0.25, 2500}; }
ElasticMaterial chung_ooi_aluminium_alloy() { return {"aluminium alloy", 7.0e10, 0.30, 2699}; }
ElasticMaterial chung_ooi_magnesium_alloy() { return {"magnesium alloy", 4.0e10, 0.35, 1800}; }
ElasticMaterial chung_ooi_aluminium_oxide() { return {"aluminium oxide", 3.8e11, 0.23, 4000}; }

HertzImpactOutcome run_hertz_impact(const HertzImpactSetup& c) {
  Model m;
  m.contact_model = ContactModel::HertzMindlin;
  Material g;
  g.name = c.material.name;
  g.density = c.material.density;
  g.young = c.material.young;
  g.poisson = c.material.poisson;
  g.eps_n = g.eps_t = c.restitution;
  g.mu_s = c.mu;
  g.mu_r = g.mu_t = 0.0;
  m.materials.push_back(g);
  m.gravity.setZero();
  m.partitions = 1;
  m.guards.allow_under_resolved = true;

  const double r = c.radius;
  const double mass = sphere_mass(r, g.density);
  const double th = c.angle_deg * kPi / 180.0;
  HertzImpactOutcome out;
  const double e_mat = g.young / (1 - g.poisson * g.poisson);
  if (c.wall) {
    out.mstar = mass;
    out.reff = r;
    out.e_star = e_mat;  // rigid plane
    out.v_rel = c.speed * std::cos(th);
  } else {
    out.mstar = 0.5 * mass;
    out.reff = 0.5 * r;
    out.e_star = 0.5 * e_mat;
    out.v_rel = 2.0 * c.speed;
  }
  const double tc = hertz_contact_time(out.mstar, out.reff, out.e_star, out.v_rel);
  out.dt = tc / c.steps_per_contact;
  m.dt = out.dt;
  m.kn = 1.0;  // unused by the Hertz–Mindlin law

  rt::add_grain(m, r, 0);
  if (c.wall) {
    // Rigid plane (young = 0): the grain–plane law gets E* = E/(1 - nu^2),
    // G* = G/(2 - nu).
    Material w = g;
    w.name = "rigid plane";
    w.structure = true;
    w.young = 0;
    m.materials.push_back(w);
    m.walls.push_back(make_plane(Vec3::Zero(), Vec3::UnitX(), 1));
  } else {
    rt::add_grain(m, r, 0);
  }
  finalize_model(m);
  if (c.damping_prefactor >= 0)
    for (auto& L : m.pair_law) L.hm_damp = c.damping_prefactor;

  State s = make_state(m);
  const double gap = 1.5 * out.v_rel * out.dt;
  if (c.wall) {
    s.pos[0] = Vec3(r + gap, 0, 0);
    s.vel[0] = Vec3(-c.speed * std::cos(th), c.speed * std::sin(th), 0);
  } else {
    s.pos[0] = Vec3(-(r + 0.5 * gap), 0, 0);
    s.pos[1] = Vec3(r + 0.5 * gap, 0, 0);
    s.vel[0] = Vec3(c.speed, 0, 0);
    s.vel[1] = Vec3(-c.speed, 0, 0);
  }
  out.vt_in = s.vel[0].y();
  s.log_contacts = c.mu > 0;
  const long budget = long(20 * c.steps_per_contact) + 100;
  long contact_steps = 0;
  bool touched = false;
  for (long k = 0; k < budget; ++k) {
    step(m, s);
    if (live_contacts(s) > 0) {
      touched = true;
      ++contact_steps;
      const double x = c.wall ? r - s.pos[0].x() : 2 * r - (s.pos[1].x() - s.pos[0].x());
      out.max_overlap = std::max(out.max_overlap, x);
      out.max_force = std::max(out.max_force, c.wall ? s.force[0].x() : -s.force[0].x());
      if (s.log_contacts) {
        bool stuck = false;
        for (const auto& sc : s.scratch)
          for (const ContactRecord& rec : sc.log)
            if (rec.fn > 0 && rec.ft < (1 - 1e-6) * rec.mu_s * rec.fn) stuck = true;
        out.stick_steps += stuck ? 1 : 0;
      }
    } else if (touched) {
      out.ended = true;
      break;
    }
  }
  out.t_measured = contact_steps * out.dt;
  out.steps_per_contact = double(contact_steps);
  out.e_n = c.wall ? s.vel[0].x() / out.v_rel : (s.vel[1].x() - s.vel[0].x()) / out.v_rel;
  out.vt_out = s.vel[0].y();
  out.omega_out = s.omega[0].z();
  return out;
}

ElasticBenchmark chung_ooi_test1(const ElasticMaterial& mat, double steps_per_contact) {
  HertzImpactSetup c;
  c.material = mat;
  c.wall = false;
  c.radius = 0.010;
  c.speed = 10.0;  // each sphere: relative speed 20 m/s
  c.steps_per_contact = steps_per_contact;
  ElasticBenchmark b;
  b.test = "test1";
  b.material = mat.name;
  b.measured = run_hertz_impact(c);
  b.analytic = hertz_elastic_impact(b.measured.mstar, b.measured.reff, b.measured.e_star, b.measured.v_rel);
  return b;
}

ElasticBenchmark chung_ooi_test2(const ElasticMaterial& mat, double steps_per_contact) {
  HertzImpactSetup c;
  c.material = mat;
  c.wall = true;
  c.radius = 0.10;
  c.speed = 0.2;
  c.steps_per_contact = steps_per_contact;
  ElasticBenchmark b;
  b.test = "test2";
  b.material = mat.name;
  b.measured = run_hertz_impact(c);
  b.analytic = hertz_elastic_impact(b.measured.mstar, b.measured.reff, b.measured.e_star, b.measured.v_rel);
  return b;
}

RestitutionRow chung_ooi_test3(double e_in, double steps_per_contact) {
  RestitutionRow row;
  row.e_in = e_in;
  row.alpha_model = hertz_damping_prefactor_model(e_in);
  row.alpha_calibrated = hertz_damping_prefactor_calibrated(e_in);
  row.e_ode_model = hertz_restitution(row.alpha_model);
  HertzImpactSetup c;
  c.material = chung_ooi_aluminium_oxide();
  c.wall = true;
  c.radius = 0.0025;
  c.speed = 3.9;
  c.restitution = e_in;
  c.steps_per_contact = steps_per_contact;
  const HertzImpactOutcome om = run_hertz_impact(c);
  row.e_out_model = om.e_n;
  row.steps_per_contact = om.steps_per_contact;
  c.damping_prefactor = row.alpha_calibrated;
  row.e_out_calibrated = run_hertz_impact(c).e_n;
  return row;
}

ObliqueRow chung_ooi_test4(double angle_deg, double steps_per_contact) {
  const ElasticMaterial mat = chung_ooi_aluminium_oxide();
  const double v = kTest4Speed, mu = kTest4Friction, e = kTest4Restitution, R = kTest4Radius;
  HertzImpactSetup c;
  c.material = mat;
  c.wall = true;
  c.radius = R;
  c.speed = v;
  c.angle_deg = angle_deg;
  c.restitution = e;
  c.mu = mu;
  c.steps_per_contact = steps_per_contact;
  const HertzImpactOutcome o = run_hertz_impact(c);

  ObliqueRow row;
  row.angle_deg = angle_deg;
  row.steps_per_contact = o.steps_per_contact;
  const double th = angle_deg * kPi / 180.0;
  const double vn = v * std::cos(th), vt = v * std::sin(th);
  const double vn_out = o.e_n * vn;
  row.e_n = o.e_n;
  row.vt_ratio = o.vt_out / vt;
  row.omega_r_over_v = o.omega_out * R / v;
  row.rebound_deg = std::atan2(o.vt_out, vn_out) * 180.0 / kPi;
  row.patch_rebound_deg = std::atan2(o.vt_out - o.omega_out * R, vn_out) * 180.0 / kPi;

  // Rigid-body Coulomb theory (solid sphere, I = 2/5 m R^2).
  const double slide_impulse = mu * (1 + e) * vn;  // tangential impulse per unit mass when sliding
  row.vt_ratio_sliding = (vt - slide_impulse) / vt;
  row.omega_r_over_v_sliding = 2.5 * slide_impulse / v;
  row.gross_sliding_rigid = vt >= 3.5 * slide_impulse;
  const double vt_rigid = row.gross_sliding_rigid ? vt - slide_impulse : 5.0 / 7.0 * vt;
  const double wr_rigid = row.gross_sliding_rigid ? 2.5 * slide_impulse : 5.0 / 7.0 * vt;
  row.vt_ratio_rigid = vt_rigid / vt;
  row.omega_r_over_v_rigid = wr_rigid / v;
  row.rebound_deg_rigid = std::atan2(vt_rigid, e * vn) * 180.0 / kPi;
  row.patch_rebound_deg_rigid = std::atan2(vt_rigid - wr_rigid, e * vn) * 180.0 / kPi;

  const double chi = 2 * (1 - mat.poisson) / (2 - mat.poisson);
  row.psi1 = chi * std::tan(th) / mu;
  row.psi2 = chi * (o.vt_out - o.omega_out * R) / (mu * vn);
  row.slid_throughout = o.ended && o.stick_steps == 0;
  return row;
}

}  // namespace rt::validate
