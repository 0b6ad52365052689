// Per-grain force fields (field.hpp): a uniform field stands in for the
// integrator's gravity, linear drag against its closed-form solution, and the
// stage's results do not depend on the thread count.
//
// Drag resolution: the drag sees the predicted v(n+1) (as the dashpots do).
// For dv/dt = -gamma w, w = v - u, one step of kick–drift–kick with that
// prediction multiplies w by 1 - x + x^2/2 + x^3/4 + O(x^4), x = gamma dt,
// against exp(-x) = 1 - x + x^2/2 - x^3/6: 5/12 x^3 per step, so after time t
// the relative error of w is (5/12) gamma t x^2 (1 + O(x)): second order. The
// O(x) correction is below x (the recurrence evaluated for x <= 0.05 gives
// 1 + x/2 at most), hence the bound (5/12) gamma t x^2 (1 + x) used below.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::test::figure;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDensity = 2500;  // kg/m^3
const Vec3 kG(0, 0, -9.81);        // m/s^2

double grain_mass(double r) { return 4.0 / 3.0 * kPi * r * r * r * kDensity; }

// max_i |a_i - b_i| / max_i |b_i|.
double relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double diff = 0, scale = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, (a[i] - b[i]).norm());
    scale = std::max(scale, b[i].norm());
  }
  return diff / scale;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Grains (radius N(r, 0.05 r)) on a lattice in a box [0, L]^2 x [0, 1] with a
// floor and four side planes, thrown down at 1 m/s (+- 0.1 m/s at random):
// they land on the floor and on each other. Gravity zero; the caller sets it
// or a field. Every `glued_every`-th grain is glued (0: none).
struct Bed {
  rt::Model m;
  rt::State s;
};

Bed make_bed(int n, double r, double L, double spacing, int glued_every = 0) {
  Bed b;
  rt::Model& m = b.m;
  m.materials.push_back(rt::test::simple_material("grain", kDensity, 0.5, 0.5, 0.5));
  rt::Material wall = rt::test::simple_material("wall", kDensity, 0.5, 0.5, 0.5);
  wall.structure = true;
  m.materials.push_back(wall);
  m.gravity.setZero();
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3(L, 0, 0), -Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitY(), 1));
  m.walls.push_back(rt::make_plane(Vec3(0, L, 0), -Vec3::UnitY(), 1));
  std::mt19937_64 rng(7);
  rt::RadiusDist d;
  d.mean = r;
  d.sigma = 0.05;
  rt::Region box;
  box.lo = Vec3::Zero();
  box.hi = Vec3(L, L, 1.0);
  const std::vector<Vec3> sites = rt::lattice_sites(box, spacing * d.max(), d.max(), 0.0, n, rng);
  const std::vector<double> radii = rt::draw_radii(d, n, rng);
  EXPECT_EQ(int(sites.size()), n);
  for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0, glued_every > 0 && i % glued_every == 0);
  m.kn = rt::kn_rule(grain_mass(r), 1.0, 0.01 * r);
  m.dt = rt::dt_rule(grain_mass(r), m.kn, 30);
  rt::finalize_model(m);
  b.s = rt::make_state(m);
  std::normal_distribution<double> v(0.0, 0.1);
  for (int i = 0; i < n; ++i) {
    b.s.pos[i] = sites[i];
    if (!m.grain_hold[i]) b.s.vel[i] = Vec3(v(rng), v(rng), v(rng) - 1.0);
  }
  return b;
}

// One free grain far from everything, gravity zero, time step dt.
struct OneGrain {
  rt::Model m;
  rt::State s;
};

OneGrain one_grain(double dt, const Vec3& v0) {
  OneGrain g;
  const double r = 0.005;
  g.m.materials.push_back(rt::test::simple_material("grain", kDensity, 0.5, 0.5, 0.5));
  g.m.gravity.setZero();
  rt::add_grain(g.m, r, 0);
  g.m.kn = rt::kn_rule(grain_mass(r), 1.0, 0.01 * r);
  g.m.dt = dt;
  rt::finalize_model(g.m);
  g.s = rt::make_state(g.m);
  g.s.vel[0] = v0;
  return g;
}

// A free grain under drag (rate gamma, flow u) and gravity g in the
// integrator, from v0 for `steps` steps of dt, against
// v_exact = v_inf + (v0 - v_inf) exp(-gamma t), v_inf = u + g / gamma. The
// relative error is |v - v_exact| / |v_exact - v_inf|; the bound is
// (5/12) gamma t x^2 (1 + x), x = gamma dt (see the head of the file).
struct DragRun {
  double worst_over_bound = 0;  // max over steps of relative error / bound
  double worst_relative = 0;    // max over steps of the relative error
  double final_relative = 0;    // relative error at the last step
  Vec3 v_final = Vec3::Zero();
};

DragRun drag_run(double gamma, const Vec3& u, const Vec3& g, const Vec3& v0, double dt, int steps) {
  OneGrain og = one_grain(dt, v0);
  og.m.gravity = g;
  og.m.fields.push_back(std::make_shared<rt::LinearDragField>(gamma, u));
  const Vec3 v_inf = u + g / gamma;
  const double x = gamma * dt;
  DragRun out;
  for (int k = 1; k <= steps; ++k) {
    rt::step(og.m, og.s);
    const double t = og.s.time;
    const Vec3 w_exact = (v0 - v_inf) * std::exp(-gamma * t);
    const double rel = (og.s.vel[0] - v_inf - w_exact).norm() / w_exact.norm();
    const double bound = 5.0 / 12.0 * gamma * t * x * x * (1 + x);
    out.worst_over_bound = std::max(out.worst_over_bound, rel / bound);
    out.worst_relative = std::max(out.worst_relative, rel);
    out.final_relative = rel;
  }
  out.v_final = og.s.vel[0];
  return out;
}

// Runs a bed of 200 grains (radius N(5 mm, 5 %)) thrown onto the floor for
// `steps` steps twice: with gravity in the integrator, and with the model's
// gravity zero and a uniform field equal to it. Returns the largest relative
// differences over the steps, max_i |x_field - x_gravity| / max_i |x_gravity|
// and the same for velocities; `power_of_two` gives every grain the power of
// two nearest its mass.
struct GravityComparison {
  double worst_x = 0, worst_v = 0;
  double max_coordinate = 0;  // largest |x| of a grain over the run, m
  double x_max = 0;           // the overlap of the stiffness rule, m
  long contacts = 0, wall_contacts = 0;  // summed over the steps
};

GravityComparison compare_with_gravity(int steps, bool power_of_two) {
  const double r = 0.005;
  Bed with_gravity = make_bed(200, r, 0.06, 2.02);
  Bed with_field = make_bed(200, r, 0.06, 2.02);
  if (power_of_two)
    for (rt::Model* m : {&with_gravity.m, &with_field.m})
      for (int i = 0; i < m->n_grains; ++i) {
        m->grain_mass[i] = std::exp2(std::round(std::log2(m->grain_mass[i])));
        m->grain_inv_mass[i] = 1.0 / m->grain_mass[i];
      }
  with_gravity.m.gravity = kG;
  with_field.m.fields.push_back(std::make_shared<rt::UniformField>(kG));
  EXPECT_TRUE(with_field.m.gravity.isZero());
  GravityComparison c;
  c.x_max = 0.01 * r;  // make_bed's rt::kn_rule(m, 1 m/s, 0.01 r)
  for (int k = 1; k <= steps; ++k) {
    rt::step(with_gravity.m, with_gravity.s);
    rt::step(with_field.m, with_field.s);
    c.contacts += with_gravity.s.stats.contacts;
    c.wall_contacts += with_gravity.s.stats.wall_contacts;
    c.worst_x = std::max(c.worst_x, relative_difference(with_field.s.pos, with_gravity.s.pos));
    c.worst_v = std::max(c.worst_v, relative_difference(with_field.s.vel, with_gravity.s.vel));
    for (const Vec3& x : with_gravity.s.pos) c.max_coordinate = std::max(c.max_coordinate, x.norm());
  }
  return c;
}

}  // namespace

// A uniform field equal to gravity, with the model's gravity zero, reproduces
// the run with gravity in the integrator: 600 steps (20 grain-pair contact
// durations) of a bed landing on the floor, with about 12 grain pairs and 6
// grain–wall pairs in contact per step.
// The runs differ in rounding only (a force m a added to the contacts and
// multiplied by 1/m again, against a added to the acceleration): positions
// agree to 1e-14 of their largest magnitude X. Velocities agree to the
// contacts' conditioning: once a coordinate differs by one ulp (<= eps X),
// the overlap does too, and a contact of frequency omega turns that into a
// velocity difference of about omega eps X; omega = v_max / x_max of the
// stiffness rule (grain–wall; sqrt 2 that for grain pairs), so relative to
// v_max the bound is sqrt(2) eps X / x_max (about 7e-13 here). Over longer
// runs the difference keeps growing as it passes from contact to contact
// (measured 1e-12 after 1000 steps), as any rounding difference would.
TEST(Field, UniformFieldMatchesIntegratorGravity) {
  const int steps = 600;
  const GravityComparison c = compare_with_gravity(steps, false);
  const double v_bound = std::sqrt(2.0) * std::numeric_limits<double>::epsilon() * c.max_coordinate / c.x_max;
  RecordProperty("max_relative_position_difference", figure(c.worst_x));
  RecordProperty("max_relative_velocity_difference", figure(c.worst_v));
  RecordProperty("velocity_conditioning_bound", figure(v_bound));
  RecordProperty("contacts_per_step", figure(double(c.contacts) / steps));
  RecordProperty("wall_contacts_per_step", figure(double(c.wall_contacts) / steps));
  EXPECT_GT(c.contacts, 8L * steps);
  EXPECT_GT(c.wall_contacts, 4L * steps);
  EXPECT_LE(c.worst_x, 1e-14);
  EXPECT_LE(c.worst_v, v_bound);
}

// With masses that are powers of two, m_i a / m_i is exactly a and the
// rounding of (f + m_i a) / m_i equals that of f / m_i + a: the field run is
// bit-identical to the gravity run, contacts and all.
TEST(Field, UniformFieldIsGravityExactlyForPowerOfTwoMasses) {
  const int steps = 600;
  const GravityComparison c = compare_with_gravity(steps, true);
  EXPECT_GT(c.contacts, 8L * steps);
  EXPECT_GT(c.wall_contacts, 4L * steps);
  EXPECT_EQ(c.worst_x, 0.0);
  EXPECT_EQ(c.worst_v, 0.0);
}

// Fields that add nothing (zero acceleration, zero drag rate) leave the
// trajectory bit-identical to a run without fields: the stage itself changes
// no value. (The pinned hash of determinism_test covers the empty field list.)
TEST(Field, ZeroFieldsLeaveTheTrajectoryBitIdentical) {
  Bed plain = make_bed(200, 0.005, 0.06, 2.02);
  plain.m.gravity = kG;
  Bed zero = make_bed(200, 0.005, 0.06, 2.02);
  zero.m.gravity = kG;
  zero.m.fields.push_back(std::make_shared<rt::UniformField>(Vec3::Zero()));
  zero.m.fields.push_back(std::make_shared<rt::LinearDragField>(0.0, Vec3(0.3, -0.1, 0.2)));
  for (int k = 0; k < 300; ++k) {
    rt::step(plain.m, plain.s);
    rt::step(zero.m, zero.s);
  }
  EXPECT_TRUE(same_bits(plain.s.pos, zero.s.pos));
  EXPECT_TRUE(same_bits(plain.s.vel, zero.s.vel));
  EXPECT_TRUE(same_bits(plain.s.omega, zero.s.omega));
  EXPECT_TRUE(same_bits(plain.s.pairs.spring_t, zero.s.pairs.spring_t));
}

// Linear drag on a free grain (no gravity, no contacts) from v0 toward the
// flow u: v - u decays as (v0 - u) exp(-gamma t) within the second-order bound
// over gamma t = 5, and halving dt divides the error by 4.
TEST(Field, LinearDragDecaysExponentially) {
  const double gamma = 20;  // 1/s
  const Vec3 u(0.05, 0.0, -0.02), v0(0.3, -0.2, 0.1);
  const double dt = 1e-4;  // x = gamma dt = 2e-3
  const DragRun a = drag_run(gamma, u, Vec3::Zero(), v0, dt, 2500);
  const DragRun b = drag_run(gamma, u, Vec3::Zero(), v0, 0.5 * dt, 5000);
  RecordProperty("max_relative_error", figure(a.worst_relative));
  RecordProperty("max_error_over_bound", figure(a.worst_over_bound));
  RecordProperty("error_ratio_dt_over_half_dt", figure(a.final_relative / b.final_relative));
  EXPECT_LE(a.worst_over_bound, 1.0);
  EXPECT_LE(b.worst_over_bound, 1.0);
  // The error is the predicted one, not far below (a sign of a different scheme).
  EXPECT_GE(a.final_relative, 0.9 * 5.0 / 12.0 * 5.0 * std::pow(gamma * dt, 2));
  EXPECT_NEAR(a.final_relative / b.final_relative, 4.0, 0.1);
}

// Gravity (in the integrator) and drag: the grain approaches the terminal
// velocity v_inf = u + g / gamma within the same bound, and after gamma t = 40
// (exp(-40) ~ 4e-18) sits on it to rounding. The scheme's fixed point is
// exact, but a component stops changing once each half kick h a rounds away,
// |h gamma (v - v_inf)| < ulp(v) / 2 <= eps |v| / 2: so |v - v_inf| stays
// within eps |v| / (gamma dt) (1e-13 relative at gamma dt = 2e-3).
TEST(Field, GravityAndDragReachTerminalVelocity) {
  const double gamma = 20;  // 1/s
  const Vec3 u(0.1, 0.0, 0.05), v0 = Vec3::Zero();
  const double dt = 1e-4;
  const DragRun approach = drag_run(gamma, u, kG, v0, dt, 2500);
  EXPECT_LE(approach.worst_over_bound, 1.0);
  const DragRun settled = drag_run(gamma, u, kG, v0, dt, 20000);
  const Vec3 v_inf = u + kG / gamma;
  const double rel = (settled.v_final - v_inf).norm() / v_inf.norm();
  RecordProperty("approach_max_relative_error", figure(approach.worst_relative));
  RecordProperty("terminal_relative_error", figure(rel));
  EXPECT_LE(rel, std::numeric_limits<double>::epsilon() * (1 / (gamma * dt) + 4));  // + rounding of a itself
}

// prime() adds the fields too (the first half kick uses them), and glued
// grains get nothing.
TEST(Field, PrimeAddsFieldsAndSkipsGluedGrains) {
  rt::Model m;
  m.materials.push_back(rt::test::simple_material("grain", kDensity, 0.5, 0.5, 0.5));
  m.gravity.setZero();
  rt::add_grain(m, 0.005, 0);
  rt::add_grain(m, 0.005, 0, true);
  m.kn = rt::kn_rule(grain_mass(0.005), 1.0, 0.01 * 0.005);
  m.dt = 1e-4;
  const Vec3 a(1, -2, 3), u(0.5, 0, 0);
  const double gamma = 4;
  m.fields.push_back(std::make_shared<rt::UniformField>(a));
  m.fields.push_back(std::make_shared<rt::LinearDragField>(gamma, u));
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0, 0, 0);
  s.pos[1] = Vec3(1, 0, 0);
  s.vel[0] = Vec3(0.1, 0.2, -0.3);
  rt::prime(m, s);
  const double mass = m.grain_mass[0];
  const Vec3 expected = mass * a - mass * gamma * (s.vel[0] - u);
  EXPECT_LE((s.force[0] - expected).norm(), 1e-15 * expected.norm());
  EXPECT_TRUE(s.torque[0].isZero());
  EXPECT_TRUE(s.force[1].isZero());
  EXPECT_TRUE(s.torque[1].isZero());
  EXPECT_THROW(rt::LinearDragField(-1.0, u), rt::InputError);
  EXPECT_THROW(rt::UniformField(Vec3(0, 0, std::nan(""))), rt::InputError);
}

// A field that adds nothing and records how many threads ran the stage.
struct ThreadProbe final : rt::Field {
  mutable std::atomic<int> max_threads{0};
  const char* name() const override { return "thread_probe"; }
  void apply(const rt::Model&, rt::State&, int, int) const override {
    const int n = omp_get_num_threads();
    int seen = max_threads.load();
    while (n > seen && !max_threads.compare_exchange_weak(seen, n)) {
    }
  }
};

// With fields, a bed above m.parallel_min_grains (so the step and the field
// stage run in parallel) gives bit-identical states on 1, 2 and 3 threads.
TEST(Field, FieldsAreBitIdenticalAcrossThreadCounts) {
  auto run = [](int threads) {
    omp_set_num_threads(threads);
    Bed b = make_bed(3200, 0.003, 0.12, 2.02, 97);
    b.m.fields.push_back(std::make_shared<rt::UniformField>(kG));
    b.m.fields.push_back(std::make_shared<rt::LinearDragField>(5.0, Vec3(0.2, 0.0, 0.0)));
    const auto probe = std::make_shared<ThreadProbe>();
    b.m.fields.push_back(probe);
    EXPECT_GE(b.m.n_grains, b.m.parallel_min_grains) << "the bed would run serially";
    long contacts = 0;
    for (int k = 0; k < 1500; ++k) {
      rt::step(b.m, b.s);
      contacts += b.s.stats.contacts + b.s.stats.wall_contacts;
    }
    EXPECT_GT(contacts, 400L * 1500);  // about 680 contacts per step on average
    EXPECT_EQ(probe->max_threads.load(), threads) << "the field stage did not run on every thread";
    return std::move(b.s);
  };
  const int saved = omp_get_max_threads();
  const rt::State one = run(1);
  for (int threads : {2, 3}) {
    const rt::State more = run(threads);
    EXPECT_TRUE(same_bits(one.pos, more.pos)) << threads << " threads: positions differ";
    EXPECT_TRUE(same_bits(one.vel, more.vel)) << threads << " threads: velocities differ";
    EXPECT_TRUE(same_bits(one.omega, more.omega)) << threads << " threads: spins differ";
    EXPECT_TRUE(same_bits(one.force, more.force)) << threads << " threads: forces differ";
    EXPECT_TRUE(same_bits(one.torque, more.torque)) << threads << " threads: torques differ";
  }
  omp_set_num_threads(saved);
}
