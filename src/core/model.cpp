// Model construction: masses, the pair-law table, stiffness and time-step rules.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/model.hpp"
#include "regolith_twin/core/types.hpp"

#include "regolith_twin/core/body_collision.hpp"

namespace rt {
namespace {


double ln2_pi2(double eps) {
  const double l = std::log(eps);
  return l * l + kPi * kPi;
}

void check_material(const Material& mat) {
  auto bad = [&](const char* key, const char* range) {
    std::ostringstream os;
    os << "material '" << mat.name << "': " << key << " out of range (allowed " << range << ")";
    throw InputError(os.str());
  };
  if (!(mat.eps_n > 0 && mat.eps_n <= 1)) bad("eps_n", "0 < eps_n <= 1");
  if (!(mat.eps_t > 0 && mat.eps_t <= 1)) bad("eps_t", "0 < eps_t <= 1");
  if (!(mat.mu_s >= 0)) bad("mu_s", ">= 0");
  if (!(mat.mu_r >= 0)) bad("mu_r", ">= 0");
  if (!(mat.mu_t >= 0)) bad("mu_t", ">= 0");
  if (!(mat.beta >= 0)) bad("beta", ">= 0");
  if (!(mat.density > 0)) bad("density", "> 0");
  if (!(mat.kt_over_kn > 0)) bad("kt_over_kn", "> 0");
  if (!(mat.poisson > -1 && mat.poisson < 0.5)) bad("poisson", "-1 < poisson < 0.5");
}

// Law constants for a pair of materials a and b (docs/model.md §2–3).
PairLaw make_law(const Model& m, const Material& a, const Material& b) {
  // Restitution: a structure material imposes its own; grains average.
  double eps_n, eps_t;
  if (a.structure != b.structure) {
    const Material& s = a.structure ? a : b;
    eps_n = s.eps_n;
    eps_t = s.eps_t;
  } else {
    eps_n = 0.5 * (a.eps_n + b.eps_n);
    eps_t = 0.5 * (a.eps_t + b.eps_t);
  }
  // Friction: the grain's, unless a structure material brings its own.
  const Material* fa = &a;
  const Material* fb = &b;
  if (a.structure && !a.own_friction && !b.structure) fa = &b;
  if (b.structure && !b.own_friction && !a.structure) fb = &a;
  PairLaw L;
  L.eps_n = eps_n;
  L.eps_t = eps_t;
  L.mu_s = 0.5 * (fa->mu_s + fb->mu_s);
  L.mu_r = 0.5 * (fa->mu_r + fb->mu_r);
  L.mu_t = 0.5 * (fa->mu_t + fb->mu_t);
  L.beta = 0.5 * (fa->beta + fb->beta);
  L.rolling = L.mu_r > 0 && L.beta > 0;
  L.twisting = L.mu_t > 0 && L.beta > 0 && L.mu_s > 0;

  // Linear law.
  L.kn = m.kn;
  L.kt = 0.5 * (a.kt_over_kn + b.kt_over_kn) * m.kn;
  L.cn_coef = linear_damping_coef(L.kn, eps_n);
  const double ct_ratio = std::max(a.ct_over_cn, b.ct_over_cn);
  L.ct_coef = ct_ratio > 0 ? ct_ratio * L.cn_coef : linear_damping_coef(L.kt, eps_t);

  // Hertz–Mindlin: a zero Young's modulus is a rigid partner.
  auto inv_e = [](const Material& x) { return x.young > 0 ? (1 - x.poisson * x.poisson) / x.young : 0.0; };
  auto inv_g = [](const Material& x) {
    return x.young > 0 ? (2 - x.poisson) / (x.young / (2 * (1 + x.poisson))) : 0.0;
  };
  const double ie = inv_e(a) + inv_e(b), ig = inv_g(a) + inv_g(b);
  L.e_star = ie > 0 ? 1 / ie : 0;
  L.g_star = ig > 0 ? 1 / ig : 0;
  L.hm_damp = 2 * std::sqrt(5.0 / 6.0) * std::fabs(std::log(eps_n)) / std::sqrt(ln2_pi2(eps_n));
  return L;
}

}  // namespace

double kn_rule(double grain_mass, double v_max, double x_max) {
  const double r = v_max / x_max;
  return grain_mass * r * r;
}

double dt_rule(double grain_mass, double kn, double steps_per_contact) {
  return kPi * std::sqrt(grain_mass / (2 * kn)) / steps_per_contact;
}

double linear_contact_time(double mstar, double kn, double eps_n) {
  return std::sqrt(mstar * ln2_pi2(eps_n) / kn);
}

double linear_damping_coef(double k, double eps) {
  if (eps >= 1.0) return 0.0;
  return -2.0 * std::log(eps) * std::sqrt(k / ln2_pi2(eps));
}

double hertz_contact_time(double mstar, double reff, double e_star, double v) {
  return 2.8682 * std::pow(mstar * mstar / (reff * e_star * e_star * v), 0.2);
}

int add_grain(Model& m, double radius, int material, bool fixed) {
  m.grain_radius.push_back(radius);
  m.grain_material.push_back(material);
  m.grain_hold.push_back(fixed ? kHoldGlued : 0);
  return m.n_grains++;
}

namespace {
// Periodic boxes (docs/model.md §11): long enough that a grain meets at most
// one image of another, walls that do not cut a periodic axis, and none of
// the features that keep absolute positions between list builds.
void check_periodic(const Model& m) {
  const Periodic& p = m.periodic;
  if (!p.any()) return;
  const double least = 2 * (2 * m.max_radius + m.skin);
  const char* names[2] = {"x", "y"};
  const bool on[2] = {p.x, p.y};
  for (int a = 0; a < 2; ++a) {
    if (!on[a]) continue;
    const double L = p.length[a];
    if (!std::isfinite(p.lo[a]) || !std::isfinite(L) || !(L >= least)) {
      std::ostringstream os;
      os << "model: the periodic box along " << names[a] << " (periodic." << names[a] << ") is " << L
         << " m long; it must be at least "
         << least << " m = 2 (2 r_max + skin), so that a grain meets one image of another at most";
      throw InputError(os.str());
    }
  }
  for (size_t k = 0; k < m.walls.size(); ++k) {
    const Wall& w = m.walls[k];
    const std::string key = "walls[" + std::to_string(k) + "]";
    if (w.type != WallType::Plane)
      throw InputError("model: wall '" + w.name + "' (" + key + ".type): only plane walls are allowed in a periodic box");
    if ((p.x && w.axis.x() != 0) || (p.y && w.axis.y() != 0))
      throw InputError("model: wall '" + w.name + "' (" + key +
                       ".normal) cuts a periodic direction: its normal must be perpendicular to the periodic axes");
  }
  if (m.n_grains >= (1 << 27))  // list entries are packed as 16 j + image code while searching
    throw InputError("model: a periodic box holds at most 134,217,727 grains");
  if (!m.bodies.empty()) throw InputError("model: rigid bodies are not supported in a periodic box");
  if (m.sleep.enabled) throw InputError("model: sleep.enabled is not supported in a periodic box");
  if (m.free_flight.enabled) throw InputError("model: free_flight.enabled is not supported in a periodic box");
}
}  // namespace

void finalize_model(Model& m) {
  const int nm = m.n_materials();
  if (nm == 0) throw InputError("model: no materials defined");
  for (const auto& mat : m.materials) check_material(mat);
  if (m.contact_model == ContactModel::Linear && !(m.kn > 0))
    throw InputError("model: contact.kn must be > 0 for the linear law");
  if (!(m.dt > 0)) throw InputError("model: dt must be > 0");
  if (m.partitions < 1 || m.partitions > 256) throw InputError("model: partitions must be in [1, 256]");

  const int n = m.n_grains;
  m.grain_mass.assign(n, 0);
  m.grain_inv_mass.assign(n, 0);
  m.grain_inv_inertia.assign(n, 0);
  m.max_radius = 0;
  m.min_radius = n ? 1e300 : 0;
  for (int i = 0; i < n; ++i) {
    const double r = m.grain_radius[i];
    const int mat = m.grain_material[i];
    if (!(r > 0)) throw InputError("model: grain " + std::to_string(i) + " has radius <= 0");
    if (mat < 0 || mat >= nm) throw InputError("model: grain " + std::to_string(i) + " has an unknown material");
    const double mass = 4.0 / 3.0 * kPi * r * r * r * m.materials[mat].density;
    m.grain_mass[i] = mass;
    if (!held(m, i)) {
      const InverseMass im = grain_inverse_mass(m, i);
      m.grain_inv_mass[i] = im.mass;
      m.grain_inv_inertia[i] = im.inertia;
    }
    m.max_radius = std::max(m.max_radius, r);
    m.min_radius = std::min(m.min_radius, r);
  }
  m.single_grain_material = n ? m.grain_material[0] : -1;
  for (int i = 1; i < n; ++i)
    if (m.grain_material[i] != m.single_grain_material) m.single_grain_material = -1;
  for (const auto& w : m.walls)
    if (w.law_material < 0 || w.law_material >= nm) throw InputError("model: wall '" + w.name + "' has an unknown material");
  for (auto& b : m.bodies) {
    if (b.material < 0 || b.material >= nm) throw InputError("model: body '" + b.name + "' has an unknown material");
    finalize_body(b);
  }

  m.pair_law.assign(static_cast<size_t>(nm) * nm, PairLaw{});
  m.any_resistance = false;
  for (int a = 0; a < nm; ++a)
    for (int b = 0; b < nm; ++b) {
      PairLaw L = make_law(m, m.materials[a], m.materials[b]);
      // A rigid structure (young = 0) needs an elastic partner; structure pairs
      // (wall-wall) never use this table.
      const bool grain_pair = !m.materials[a].structure || !m.materials[b].structure;
      if (m.contact_model == ContactModel::HertzMindlin && grain_pair && !(L.e_star > 0))
        throw InputError("model: Hertz–Mindlin needs young > 0 for material '" + m.materials[a].name + "' or '" +
                         m.materials[b].name + "'");
      m.any_resistance = m.any_resistance || L.rolling || L.twisting;
      m.pair_law[a * nm + b] = L;
    }
  if (m.skin <= 0) m.skin = 0.5 * m.max_radius;
  // Tunnelling guard (docs/model.md §13): in one step a body point may drift
  // at most the list skin (a grain could otherwise be passed) and, with two
  // or more bodies, the half thickness of the thinnest shape that is not a mesh.
  double limit = 0;
  const auto take = [&limit](double v) {
    if (v > 0) limit = limit > 0 ? std::min(limit, v) : v;
  };
  if (!m.bodies.empty() && m.n_grains > 0) take(m.skin);
  if (m.bodies.size() >= 2)
    for (const BodyModel& b : m.bodies)
      for (const Shape& sh : b.shapes)
        if (sh.type != ShapeType::Mesh) take(sh.size.minCoeff());
  m.body_step_limit = limit;
  check_periodic(m);
  build_body_geometry(m);
}

std::vector<PairResolution> pair_resolution(const Model& m, double v_ref) {
  std::vector<PairResolution> out;
  // Smallest grain of each material.
  const int nm = m.n_materials();
  std::vector<double> mmin(nm, 0), rmin(nm, 0);
  std::vector<long> count(nm, 0);
  for (int i = 0; i < m.n_grains; ++i) {
    const int a = m.grain_material[i];
    ++count[a];
    if (mmin[a] == 0 || m.grain_mass[i] < mmin[a]) {
      mmin[a] = m.grain_mass[i];
      rmin[a] = m.grain_radius[i];
    }
  }
  auto time_of = [&](const PairLaw& L, double mstar, double reff, double eps) {
    if (m.contact_model == ContactModel::Linear) return linear_contact_time(mstar, L.kn, eps);
    return hertz_contact_time(mstar, reff, L.e_star, v_ref);
  };
  for (int a = 0; a < nm; ++a) {
    if (mmin[a] == 0) continue;
    for (int b = a; b < nm; ++b) {
      if (mmin[b] == 0 || (a == b && count[a] < 2)) continue;  // no such pair in the scene
      const double ms = mmin[a] * mmin[b] / (mmin[a] + mmin[b]);
      const double re = rmin[a] * rmin[b] / (rmin[a] + rmin[b]);
      const double tc = time_of(m.law(a, b), ms, re, m.law(a, b).eps_n);
      out.push_back({"grain-grain (" + m.materials[a].name + "/" + m.materials[b].name + ")", tc, tc / m.dt});
    }
  }
  std::vector<bool> seen(nm, false);
  for (const auto& w : m.walls) {
    if (seen[w.law_material]) continue;
    seen[w.law_material] = true;
    for (int a = 0; a < nm; ++a) {
      if (mmin[a] == 0) continue;
      const PairLaw& L = m.law(a, w.law_material);
      const double tc = time_of(L, mmin[a], rmin[a], L.eps_n);
      out.push_back({"grain-wall (" + m.materials[a].name + "/" + m.materials[w.law_material].name + ")", tc,
                     tc / m.dt});
    }
  }
  for (const auto& b : m.bodies)
    for (int a = 0; a < nm; ++a) {
      if (mmin[a] == 0) continue;
      const PairLaw& L = m.law(a, b.material);
      const double ms = b.fixed ? mmin[a] : mmin[a] * b.mass / (mmin[a] + b.mass);
      const double tc = time_of(L, ms, rmin[a], L.eps_n);
      out.push_back({"grain-body (" + m.materials[a].name + "/" + b.name + ")", tc, tc / m.dt});
    }
  // Body–body pairs (at least one movable): the linear law of the pair at its
  // full stiffness k_body (a face contact; an edge or a corner is softer and
  // lasts longer), m* from the two masses, a fixed body counting as infinite.
  const int nb = static_cast<int>(m.bodies.size());
  const double k_body = m.body_kn > 0 ? m.body_kn : m.kn;
  for (int a = 0; a < nb; ++a)
    for (int b = a + 1; b < nb; ++b) {
      const BodyModel& A = m.bodies[a];
      const BodyModel& B = m.bodies[b];
      if ((A.fixed && B.fixed) || !(k_body > 0)) continue;
      const double ms = A.fixed ? B.mass : B.fixed ? A.mass : A.mass * B.mass / (A.mass + B.mass);
      const double tc = linear_contact_time(ms, k_body, m.law(A.material, B.material).eps_n);
      out.push_back({"body-body (" + A.name + "/" + B.name + ")", tc, tc / m.dt});
    }
  return out;
}

}  // namespace rt
