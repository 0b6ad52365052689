// Energy bookkeeping (docs/model.md §2, §4, §7): an elastic, frictionless gas in a
// closed box conserves rt::energy().total() (kinetic + elastic springs); with
// damping or friction the total energy at contact-free instants never rises.
//
// Resolution: each linear contact carries an energy error of order (pi/N)^2
// of its normal collision energy, with a sign set by where entry and exit fall
// within a step (the two errors cancel only when the contact lasts a whole
// number of steps, e.g. two equal grains at exactly the rule's dt). Over many
// collisions these errors add up as a random walk. At N = 30 steps per
// contact a 1000-grain gas at solid fraction 0.13 drifts by 1.6e-4 .. 3.2e-4
// over 1e5 steps (three seeds); at N = 60 by about 2e-5. The conservation test
// below therefore runs at N = 60, and the per-contact error and its order are
// asserted at N = 30 by GrainWallContactEnergyErrorIsSecondOrder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::test::figure;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 0.005;       // mean grain radius, m
constexpr double kDensity = 2500;  // kg/m^3

double grain_mass(double r) { return 4.0 / 3.0 * kPi * r * r * r * kDensity; }

// A closed cubic box [0, L]^3 of six plane walls of material `wall`.
void add_box(rt::Model& m, double L, int wall) {
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = Vec3::Unit(a);
    m.walls.push_back(rt::make_plane(Vec3::Zero(), e, wall));
    m.walls.push_back(rt::make_plane(Vec3::Constant(L), -e, wall));
  }
}

// Grains of radius N(r, 0.1 r) truncated at 1 sigma on a cubic lattice in the
// box, with Maxwellian velocities of rms speed `v_rms` per component.
rt::State gas(rt::Model& m, int n, double L, double v_rms, uint64_t seed, double steps_per_contact) {
  std::mt19937_64 rng(seed);
  rt::RadiusDist d;
  d.mean = kR;
  d.sigma = 0.1;
  rt::Region box;
  box.lo = Vec3::Zero();
  box.hi = Vec3::Constant(L);
  const std::vector<Vec3> sites = rt::lattice_sites(box, 2.2 * d.max(), d.max(), 0.0, n, rng);
  const std::vector<double> radii = rt::draw_radii(d, n, rng);
  EXPECT_EQ(int(sites.size()), n);
  for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0);
  m.kn = rt::kn_rule(grain_mass(kR), 1.0, 0.01 * kR);
  m.dt = rt::dt_rule(grain_mass(kR), m.kn, steps_per_contact);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  std::normal_distribution<double> vel(0.0, v_rms);
  for (int i = 0; i < n; ++i) {
    s.pos[i] = sites[i];
    s.vel[i] = Vec3(vel(rng), vel(rng), vel(rng));
  }
  return s;
}

rt::Material material(const char* name, double eps_n, double eps_t, double mu_s, bool structure) {
  rt::Material mat = rt::test::simple_material(name, kDensity, eps_n, eps_t, mu_s);
  mat.structure = structure;
  return mat;
}

}  // namespace

// >= 1000 elastic frictionless grains in a closed box without gravity:
// total energy (kinetic + elastic) within 1e-4 over 1e5 steps.
TEST(Energy, ElasticGasInClosedBoxConservesTotalEnergy) {
  rt::Model m;
  m.materials.push_back(material("grain", 1.0, 1.0, 0.0, false));
  m.materials.push_back(material("wall", 1.0, 1.0, 0.0, true));
  m.gravity.setZero();
  const double L = 0.16;  // solid fraction ~0.13
  add_box(m, L, 1);
  rt::State s = gas(m, 1000, L, 0.3, 1, 60.0);
  ASSERT_EQ(m.law(0, 0).cn_coef, 0.0);
  ASSERT_EQ(m.law(0, 1).cn_coef, 0.0);

  rt::prime(m, s);
  const double e0 = rt::energy(m, s).total();
  double worst = 0;
  long contact_steps = 0;
  for (int k = 1; k <= 100000; ++k) {
    rt::step(m, s);
    contact_steps += s.stats.contacts + s.stats.wall_contacts;
    if (k % 100 == 0) worst = std::max(worst, std::fabs(rt::energy(m, s).total() / e0 - 1));
  }
  RecordProperty("max_relative_energy_drift", figure(worst));
  // The gas is collisional: every grain takes part in many contacts.
  EXPECT_GT(contact_steps / 60.0 / m.n_grains, 10.0);
  EXPECT_LT(worst, 1e-4);
  // Nothing left the box.
  for (int i = 0; i < m.n_grains; ++i)
    ASSERT_TRUE((s.pos[i].array() > 0).all() && (s.pos[i].array() < L).all()) << "grain " << i;
}

// Energy error of one elastic grain–wall contact (m* = m, so the contact
// lasts sqrt 2 N steps, never a whole number): swept over 64 entry phases, the
// rms error falls as N^-2 and is below 1e-3 of the collision energy at N = 30.
TEST(Energy, GrainWallContactEnergyErrorIsSecondOrder) {
  auto rms_error = [](double n_steps) {
    double sum2 = 0;
    const int phases = 64;
    for (int p = 0; p < phases; ++p) {
      rt::Model m;
      m.materials.push_back(material("grain", 1.0, 1.0, 0.0, false));
      m.materials.push_back(material("wall", 1.0, 1.0, 0.0, true));
      m.gravity.setZero();
      m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
      rt::add_grain(m, kR, 0);
      m.kn = rt::kn_rule(grain_mass(kR), 1.0, 0.01 * kR);
      m.dt = rt::dt_rule(grain_mass(kR), m.kn, n_steps);
      rt::finalize_model(m);
      rt::State s = rt::make_state(m);
      const double v = 0.5;
      s.pos[0] = Vec3(0, 0, kR + v * m.dt * (2.0 + (p + 0.5) / phases));  // first overlap at a swept phase
      s.vel[0] = Vec3(0.3, 0, -v);
      rt::prime(m, s);
      const double e0 = rt::energy(m, s).total();
      bool touched = false;
      for (int k = 0; k < 100000; ++k) {
        rt::step(m, s);
        if (s.stats.wall_contacts) touched = true;
        else if (touched) break;
      }
      EXPECT_TRUE(touched);
      const double normal_energy = 0.5 * m.grain_mass[0] * v * v;
      const double err = (rt::energy(m, s).total() - e0) / normal_energy;
      sum2 += err * err;
    }
    return std::sqrt(sum2 / phases);
  };
  const double e30 = rms_error(30), e60 = rms_error(60), e120 = rms_error(120);
  RecordProperty("wall_contact_rms_energy_error_N30", figure(e30));
  const double order = std::log(e30 / e120) / std::log(4.0);
  RecordProperty("wall_contact_energy_error_order", figure(order));
  EXPECT_LT(e30, 1e-3);
  EXPECT_GT(e30, e60);
  EXPECT_NEAR(order, 2.0, 0.3) << "rms errors " << e30 << ", " << e60 << ", " << e120;
}

namespace {

// Total energy at every contact-free instant over `steps`; checks it never
// rises (to rounding) and returns how many such instants there were.
void expect_no_rise_when_free(const rt::Model& m, rt::State& s, int steps, int* free_samples, double* e_first,
                              double* e_last) {
  double prev = NAN;
  *free_samples = 0;
  int rises = 0;
  for (int k = 0; k < steps; ++k) {
    rt::step(m, s);
    if (s.stats.contacts != 0 || s.stats.wall_contacts != 0) continue;
    const double e = rt::energy(m, s).total();
    if (*free_samples == 0) *e_first = e;
    if (*free_samples > 0 && e > prev + 1e-12 * std::fabs(prev)) {
      if (++rises <= 5) ADD_FAILURE() << "energy rose at step " << s.step << ": " << prev << " -> " << e;
    }
    prev = e;
    *e_last = e;
    ++*free_samples;
  }
  EXPECT_EQ(rises, 0);
}

}  // namespace

// A sparse gas of 8 grains in a box without gravity, with damping, sliding,
// rolling and twisting friction: each collision can only take energy out.
TEST(Energy, DampedSparseGasNeverGainsEnergyBetweenContacts) {
  rt::Model m;
  rt::Material g = material("grain", 0.9, 1.0, 1.0, false);  // glass-bead-like: no tangential damping
  g.mu_r = 1.05;
  g.mu_t = 1.3;
  g.beta = 0.2;
  m.materials.push_back(g);
  m.materials.push_back(material("wall", 0.5, 1.0, 1.0, true));
  m.gravity.setZero();
  const double L = 0.05;
  add_box(m, L, 1);
  rt::State s = gas(m, 8, L, 0.5, 3, 30.0);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> spin(0.0, 100.0);
  for (int i = 0; i < m.n_grains; ++i) s.omega[i] = Vec3(spin(rng), spin(rng), spin(rng));
  ASSERT_TRUE(m.any_resistance);

  int samples = 0;
  double e_first = 0, e_last = 0;
  expect_no_rise_when_free(m, s, 300000, &samples, &e_first, &e_last);
  EXPECT_GT(samples, 100000);
  EXPECT_LT(e_last, 0.5 * e_first) << "too few collisions to test anything";
}

// One spinning grain bouncing in a box under gravity (kinetic + potential).
TEST(Energy, DampedGrainBouncingInBoxNeverGainsEnergyBetweenContacts) {
  rt::Model m;
  rt::Material g = material("grain", 0.8, 0.5, 0.3, false);
  g.mu_r = 0.5;
  g.mu_t = 0.5;
  g.beta = 0.5;
  m.materials.push_back(g);
  m.materials.push_back(material("wall", 0.8, 0.5, 0.3, true));
  m.gravity = Vec3(0, 0, -9.81);
  const double L = 0.05;
  add_box(m, L, 1);
  rt::add_grain(m, kR, 0);
  m.kn = rt::kn_rule(grain_mass(kR), 1.0, 0.01 * kR);
  m.dt = rt::dt_rule(grain_mass(kR), m.kn, 30.0);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0.02, 0.03, 0.04);
  s.vel[0] = Vec3(0.7, -0.4, 0.3);
  s.omega[0] = Vec3(50, -80, 120);

  int samples = 0;
  double e_first = 0, e_last = 0;
  expect_no_rise_when_free(m, s, 100000, &samples, &e_first, &e_last);
  EXPECT_GT(samples, 50000);
  // Potential energy is measured from z = 0: the floor contact is at z = r.
  const double e_floor = m.grain_mass[0] * 9.81 * kR;
  EXPECT_LT(e_last - e_floor, 0.5 * (e_first - e_floor)) << "too few bounces to test anything";
}
