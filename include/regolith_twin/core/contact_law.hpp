// Contact laws as pure functions of one pair's geometry, kinematics, law
// constants and spring history (docs/model.md §2–3). They know nothing of lists,
// walls or threads, so they can be tested on a single pair.
//
// Conventions: n points from i to j; x > 0 is the overlap; the relative
// velocity u is that of j's contact point seen from i; the returned force acts
// on i (j receives its opposite); springs are oriented from i to j.
#pragma once

#include <cmath>

#include "regolith_twin/core/model.hpp"

namespace rt {

// Geometry and kinematics of one touching pair.
struct PairInput {
  Vec3 n;          // unit normal from i to j
  double x;        // overlap, m (> 0)
  double li, lj;   // lever arms r - x/2, m
  double reff;     // effective radius R = r_i r_j / (r_i + r_j), m
  double sqrt_mstar;  // square root of the reduced mass, sqrt(kg)
  Vec3 vrel;       // v_j - v_i at the end of the step (predicted), m/s: dashpots
  Vec3 wi, wj;     // angular velocities at the end of the step (predicted), rad/s: dashpots
  Vec3 vrel_mid;   // v_j - v_i at mid-step, m/s: spring increments (consistent with the drift)
  Vec3 wi_mid, wj_mid;  // angular velocities at mid-step, rad/s: spring increments
};

// Spring history of one pair (read and written by the law).
struct PairSprings {
  Vec3& s;         // tangential spring, m
  Vec3& roll;      // rolling spring, rad
  double& twist;   // twisting spring along n, rad
};

struct PairOutput {
  Vec3 force_i;    // force on i, N (j gets -force_i)
  Vec3 torque_i;   // torque on i, N m
  Vec3 torque_j;   // torque on j, N m
  double fn;       // normal force magnitude used for the friction limits, N
  Vec3 ft;         // tangential force on i, N
  Vec3 mr = Vec3::Zero();  // rolling moment on i, N m
  double mt = 0;   // twisting moment on i along n, N m
};

namespace detail {

// Rotate a spring into the plane normal to n keeping its magnitude.
inline void rotate_into_plane(Vec3& s, const Vec3& n) {
  const double s2 = s.squaredNorm();
  if (s2 == 0.0) return;
  const double sn = s.dot(n);
  s -= sn * n;
  const double p2 = s2 - sn * sn;  // |s|^2 after removing the normal part
  if (p2 > 0.0) s *= std::sqrt(s2 / p2);
}

// Spring–dashpot–slider update shared by sliding and rolling resistance:
// add rate_mid*dt (the mid-step rate, as the positions move), shorten the
// spring to the cap, scale the total (spring + dashpot on the end-of-step
// rate) to the cap without touching the spring. Returns k*s + c*rate.
// Magnitudes are compared squared, so a sticking contact takes no sqrt.
inline Vec3 slider(Vec3& s, const Vec3& rate_mid, const Vec3& rate, double k, double c, double cap, double dt) {
  s += rate_mid * dt;
  const double ks2 = k * k * s.squaredNorm();
  if (ks2 > cap * cap) s *= cap / std::sqrt(ks2);
  Vec3 f = k * s + c * rate;
  const double f2 = f.squaredNorm();
  if (f2 > cap * cap) f *= cap / std::sqrt(f2);
  return f;
}

// Scalar version for the twisting spring (kept along n).
inline double slider1(double& s, double rate_mid, double rate, double k, double c, double cap, double dt) {
  s += rate_mid * dt;
  const double ks = k * std::fabs(s);
  if (ks > cap) s *= cap / ks;
  double m = k * s + c * rate;
  if (std::fabs(m) > cap) m = std::copysign(cap, m);
  return m;
}

}  // namespace detail

// Stiffness and damping of one contact at its current overlap.
struct LawTerms {
  double fn_elastic;  // elastic normal force magnitude, N
  double kn_eff;      // normal stiffness (linear: k_n; Hertz: S_n), N/m
  double kt;          // tangential stiffness, N/m
  double cn, ct;      // normal and tangential damping, N s/m
};

template <ContactModel M>
inline LawTerms law_terms(const PairLaw& law, double x, double reff, double sm) {
  LawTerms t;
  if constexpr (M == ContactModel::Linear) {
    t.kn_eff = law.kn;
    t.fn_elastic = law.kn * x;
    t.kt = law.kt;
    t.cn = law.cn_coef * sm;
    t.ct = law.ct_coef * sm;
  } else {
    const double a = std::sqrt(reff * x);  // contact radius
    t.kn_eff = 2.0 * law.e_star * a;       // S_n
    t.fn_elastic = (2.0 / 3.0) * t.kn_eff * x;
    t.kt = 8.0 * law.g_star * a;
    t.cn = law.hm_damp * std::sqrt(t.kn_eff) * sm;
    t.ct = t.cn;  // decision: the same gamma on normal and tangential velocities (docs/model.md §3)
  }
  return t;
}

// Force and torques of one touching pair; updates the springs.
template <ContactModel M, bool Resist>
inline PairOutput pair_contact(const PairLaw& law, const PairInput& in, PairSprings sp, double dt) {
  const LawTerms k = law_terms<M>(law, in.x, in.reff, in.sqrt_mstar);
  const Vec3& n = in.n;

  // Relative velocity of the contact points and its normal / tangential
  // parts: at the end of the step for the dashpots, at mid-step for springs.
  const Vec3 u = in.vrel - (in.lj * in.wj + in.li * in.wi).cross(n);
  const double un = u.dot(n);
  const Vec3 ut = u - un * n;
  const Vec3 um = in.vrel_mid - (in.lj * in.wj_mid + in.li * in.wi_mid).cross(n);
  const Vec3 ut_mid = um - um.dot(n) * n;

  // Normal force on i: spring pushes i away from j, damping opposes approach.
  PairOutput out;
  out.force_i = (-k.fn_elastic + k.cn * un) * n;
  out.fn = std::max(0.0, k.fn_elastic - k.cn * un);

  // Tangential spring with Coulomb limit.
  detail::rotate_into_plane(sp.s, n);
  const Vec3 ft = detail::slider(sp.s, ut_mid, ut, k.kt, k.ct, law.mu_s * out.fn, dt);
  out.force_i += ft;
  out.ft = ft;
  const Vec3 tq = n.cross(ft);
  out.torque_i = in.li * tq;
  out.torque_j = in.lj * tq;

  if constexpr (Resist) {
    const double br = law.beta * in.reff;
    const double br2 = br * br;
    const Vec3 wrel = in.wj - in.wi, wrel_mid = in.wj_mid - in.wi_mid;
    const double wn = wrel.dot(n), wn_mid = wrel_mid.dot(n);
    if (law.rolling) {
      const Vec3 wroll = wrel - wn * n, wroll_mid = wrel_mid - wn_mid * n;
      detail::rotate_into_plane(sp.roll, n);
      const Vec3 mr = detail::slider(sp.roll, wroll_mid, wroll, k.kn_eff * br2, k.cn * br2,
                                     law.mu_r * br * out.fn, dt);
      out.torque_i += mr;
      out.torque_j -= mr;
      out.mr = mr;
    }
    if (law.twisting) {
      const double mt = detail::slider1(sp.twist, wn_mid, wn, 2.0 * k.kt * br2, 2.0 * k.ct * br2,
                                        law.mu_t * br * law.mu_s * out.fn, dt);
      out.torque_i += mt * n;
      out.torque_j -= mt * n;
      out.mt = mt;
    }
  }
  return out;
}

// Elastic energy stored in one contact by spring type, J (docs/model.md §2,
// §15): normal ½ k_n x² (Hertz: 2/5 F x), tangential ½ k_t |S|², rolling
// ½ k_R |δ_R|² with k_R = k_n (βR)², twisting ½ k_T δ_T² with
// k_T = 2 k_t (βR)²: the stiffnesses pair_contact() uses. A spring type the
// pair's law has not switched on holds nothing.
struct ElasticSplit {
  double normal = 0, tangential = 0, rolling = 0, twisting = 0;
  double total() const { return normal + tangential + rolling + twisting; }
  ElasticSplit& operator+=(const ElasticSplit& o) {
    normal += o.normal;
    tangential += o.tangential;
    rolling += o.rolling;
    twisting += o.twisting;
    return *this;
  }
};

template <ContactModel M>
inline ElasticSplit pair_elastic_split(const PairLaw& law, double x, double reff, const Vec3& s, const Vec3& roll,
                                       double twist) {
  const LawTerms k = law_terms<M>(law, x, reff, 1.0);
  ElasticSplit e;
  // Linear: 1/2 k x^2. Hertz: integral of F dx = 2/5 F x.
  e.normal = (M == ContactModel::Linear) ? 0.5 * k.fn_elastic * x : 0.4 * k.fn_elastic * x;
  e.tangential = 0.5 * k.kt * s.squaredNorm();
  const double br2 = law.beta * reff * law.beta * reff;
  if (law.rolling) e.rolling = 0.5 * k.kn_eff * br2 * roll.squaredNorm();
  if (law.twisting) e.twisting = 0.5 * 2.0 * k.kt * br2 * twist * twist;
  return e;
}

// Elastic energy stored in one contact, J (for energy bookkeeping).
template <ContactModel M>
inline double pair_elastic_energy(const PairLaw& law, double x, double reff, const Vec3& s,
                                  const Vec3& roll, double twist) {
  return pair_elastic_split<M>(law, x, reff, s, roll, twist).total();
}

}  // namespace rt
