// Friction limits of every contact in a poured, then shaken, packing of the
// published 'gravel' material (docs/model.md §2, §9): at every step
//   |F_T| <= mu_s f_n,  |M_R| <= mu_R beta R f_n,  |M_T| <= mu_T beta R mu_s f_n
// to rounding, with the logged overlap and f_n = max(0, k_n x - C_n u.n)
// checked against the state, and a good share of contacts at each cap.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "test_support.hpp"

namespace {

using rt::test::figure;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;
constexpr double kRound = 1e-12;  // relative rounding allowance on the caps

struct Tally {
  long records = 0, loaded = 0;        // all records; records with f_n > 0
  long at_slide = 0, at_roll = 0, at_twist = 0;
  long violations = 0;
  long fn_mismatch = 0;
};

bool at_cap(double v, double cap) { return cap > 0 && v >= cap * (1 - 1e-9); }

// Check every contact logged by the last force pass (it saw the current
// positions). The velocity the normal dashpot saw is the integrator's choice
// (mid-step or end-of-step), so f_n is checked against the whole band
// max(0, k_n x -+ C_n V), V bounding |u.n| over the step: the current
// relative contact-point speed plus a full kick with the forces of the step
// and of the one before (`prev`), either way.
struct Forces {
  std::vector<Vec3> force, torque;
};

void check_step(const rt::Model& m, const rt::State& s, const Forces& prev, Tally& t) {
  const double dt = m.dt;
  auto kick_v = [&](int i) {
    return dt * ((s.force[i] * m.grain_inv_mass[i] + m.gravity).norm() +
                 (prev.force[i] * m.grain_inv_mass[i] + m.gravity).norm());
  };
  auto kick_w = [&](int i) { return dt * m.grain_inv_inertia[i] * (s.torque[i].norm() + prev.torque[i].norm()); };
  for (const rt::ThreadScratch& sc : s.scratch)
    for (const rt::ContactRecord& c : sc.log) {
      ++t.records;
      const int i = c.i;
      const double ri = m.grain_radius[i];
      const double li_w = s.omega[i].norm() + kick_w(i);
      double x, mstar, speed;
      const rt::PairLaw* law;
      if (c.j >= 0) {
        const int j = c.j;
        const Vec3 d = s.pos[j] - s.pos[i];
        const double rj = m.grain_radius[j];
        x = ri + rj - d.norm();
        mstar = 1.0 / (m.grain_inv_mass[i] + m.grain_inv_mass[j]);
        speed = (s.vel[j] - s.vel[i]).norm() + kick_v(i) + kick_v(j) + (ri - 0.5 * x) * li_w +
                (rj - 0.5 * x) * (s.omega[j].norm() + kick_w(j));
        law = &m.law(m.grain_material[i], m.grain_material[j]);
      } else {
        const rt::Wall& w = m.walls[-1 - c.j];
        x = rt::wall_gap(w, s.pos[i], ri).overlap;
        mstar = m.grain_mass[i];
        speed = s.vel[i].norm() + kick_v(i) + (ri - 0.5 * x) * li_w;
        law = &m.law(m.grain_material[i], w.law_material);
      }
      const double elastic = law->kn * x, damp = law->cn_coef * std::sqrt(mstar) * speed;
      // The overlap is a difference of lengths ~ r: allow a few ulps of r in it.
      const double dx = 1e-14 * ri, tol = 1e-9 * (elastic + damp) + law->kn * dx;
      const double lo = std::max(0.0, elastic - damp) - tol, hi = std::max(0.0, elastic + damp) + tol;
      if (c.fn < std::max(0.0, lo) || c.fn > hi || std::fabs(c.overlap - x) > dx) {
        if (++t.fn_mismatch <= 5)
          ADD_FAILURE() << "step " << s.step << " contact " << c.i << "-" << c.j << ": logged f_n " << c.fn
                        << " overlap " << c.overlap << ", expected f_n in [" << lo << ", " << hi << "], overlap "
                        << x;
      }

      const double cap_s = c.mu_s * c.fn;
      const double cap_r = c.mu_r * c.beta * c.reff * c.fn;
      const double cap_t = c.mu_t * c.beta * c.reff * c.mu_s * c.fn;
      const bool ok = c.ft <= cap_s * (1 + kRound) && c.mr <= cap_r * (1 + kRound) && c.mt <= cap_t * (1 + kRound);
      if (!ok && ++t.violations <= 5)
        ADD_FAILURE() << "step " << s.step << " contact " << c.i << "-" << c.j << ": ft " << c.ft << " (cap " << cap_s
                      << "), mr " << c.mr << " (cap " << cap_r << "), mt " << c.mt << " (cap " << cap_t << ")";
      if (c.fn > 0) {
        ++t.loaded;
        t.at_slide += at_cap(c.ft, cap_s);
        t.at_roll += at_cap(c.mr, cap_r);
        t.at_twist += at_cap(c.mt, cap_t);
      }
    }
}

}  // namespace

TEST(PackingLimits, GravelContactsNeverExceedTheirCaps) {
  // 2000 gravel grains (r = 1 cm +- 10 %) at random non-overlapping places
  // (solid fraction 0.3) in an open box 0.4 m x 0.4 m, poured at 1 m/s.
  const int n = 2000;
  const double L = 0.4, phi0 = 0.3;
  rt::Model m;
  rt::Material gravel;
  ASSERT_TRUE(rt::material_preset("gravel", gravel));
  ASSERT_EQ(gravel.mu_r, 1.05);
  ASSERT_EQ(gravel.beta, 1.0);
  m.materials.push_back(gravel);
  rt::Material wall = gravel;
  wall.name = "wall";
  wall.structure = true;
  m.materials.push_back(wall);
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3(L, 0, 0), -Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitY(), 1));
  m.walls.push_back(rt::make_plane(Vec3(0, L, 0), -Vec3::UnitY(), 1));

  std::mt19937_64 rng(2024);
  rt::RadiusDist dist;
  dist.mean = 0.01;
  dist.sigma = 0.1;
  const std::vector<double> radii = rt::draw_radii(dist, n, rng);
  double volume = 0, r_min = 1;
  for (double r : radii) {
    volume += 4.0 / 3.0 * kPi * r * r * r;
    r_min = std::min(r_min, r);
  }
  const double H = volume / (phi0 * L * L);
  std::uniform_real_distribution<double> uni(0, 1);
  std::vector<Vec3> pos;
  for (int i = 0; i < n; ++i) {
    const double r = radii[i];
    for (int attempt = 0;; ++attempt) {
      ASSERT_LT(attempt, 100000) << "no room for grain " << i;
      const Vec3 p(r + uni(rng) * (L - 2 * r), r + uni(rng) * (L - 2 * r), r + uni(rng) * (H - 2 * r));
      bool free = true;
      for (int j = 0; j < i && free; ++j) free = (pos[j] - p).norm() >= r + radii[j];
      if (free) {
        pos.push_back(p);
        break;
      }
    }
    rt::add_grain(m, r, 0);
  }
  const double m_p = 4.0 / 3.0 * kPi * std::pow(dist.mean, 3) * gravel.density;
  m.kn = rt::kn_rule(m_p, 1.0, 0.01 * r_min);
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  rt::finalize_model(m);
  ASSERT_TRUE(m.law(0, 0).rolling && m.law(0, 0).twisting);
  ASSERT_TRUE(m.law(0, 1).rolling && m.law(0, 1).twisting);
  rt::State s = rt::make_state(m);
  for (int i = 0; i < n; ++i) {
    s.pos[i] = pos[i];
    s.vel[i] = Vec3(0, 0, -1.0);
  }
  s.log_contacts = true;

  // Pour: 9000 steps under 4 g (quick compaction), 3000 steps at 1 g.
  Tally pour;
  Forces prev;
  auto step = [&](const Vec3& gravity, Tally& t) {
    m.gravity = gravity;
    prev.force = s.force;
    prev.torque = s.torque;
    rt::step(m, s);
    check_step(m, s, prev, t);
  };
  for (int k = 0; k < 12000; ++k) step(Vec3(0, 0, k < 9000 ? -4 * kG : -kG), pour);
  const double z = rt::coordination_number(m, s), e_kin = rt::energy(m, s).kinetic();
  RecordProperty("bed_coordination", figure(z));
  RecordProperty("bed_kinetic_energy_J", figure(e_kin));
  EXPECT_GT(z, 1.5) << "the bed did not form";
  // Mean kinetic energy per grain well below that of lifting it by its radius.
  EXPECT_LT(e_kin, 0.05 * n * m_p * kG * dist.mean) << "the bed did not settle";

  // Shake: gravity tilted 50 degrees (past the 38.5 degree angle of repose),
  // its horizontal part reversed every 200 steps, so the bed slides to and fro.
  Tally shake;
  const double tilt = 50.0 * kPi / 180.0;
  for (int k = 0; k < 800; ++k) {
    const double side = (k / 200) % 2 ? -1.0 : 1.0;
    step(kG * Vec3(side * std::sin(tilt), 0, -std::cos(tilt)), shake);
  }

  for (const Tally* t : {&pour, &shake}) {
    EXPECT_EQ(t->violations, 0);
    EXPECT_EQ(t->fn_mismatch, 0);
  }
  const double f_slide = double(shake.at_slide) / shake.loaded, f_roll = double(shake.at_roll) / shake.loaded,
               f_twist = double(shake.at_twist) / shake.loaded;
  RecordProperty("shake_fraction_at_sliding_cap", figure(f_slide));
  RecordProperty("shake_fraction_at_rolling_cap", figure(f_roll));
  RecordProperty("shake_fraction_at_twisting_cap", figure(f_twist));
  EXPECT_GT(shake.loaded, 800L * 2000);  // > 2000 loaded contacts per step
  EXPECT_GT(f_slide, 0.05);
  EXPECT_GT(f_roll, 0.05);
  EXPECT_GT(f_twist, 0.02);
  EXPECT_GT(pour.at_slide, 0);
  EXPECT_GT(pour.at_roll, 0);
  EXPECT_GT(pour.at_twist, 0);
}
