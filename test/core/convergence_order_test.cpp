// Convergence order in the time step of an oblique frictional impact on a
// wall (docs/validation/contact.md, docs/model.md §7): the rebound velocity and spin
// against a run at 2,560 steps per contact, averaged over entry phases. With
// forces that are continuous at contact onset (no dashpots: ε_n = ε_t = 1)
// the tangential spring and the rotation must keep the integrator's second
// order — a spring advanced at an inconsistent time level makes it first
// order. With dashpots the force jumps to C v_n at onset, which a step
// resolves only to within Δt: first order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/walls.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

struct Rebound {
  double vx, vz, wy;
};

// A 1 cm grain at 1 m/s onto a plane, 0.2 m/s along it (sticking most of the
// contact at μ = 0.5), entering the contact at a fraction `phase` of a step.
Rebound impact(double steps_per_contact, double eps_n, double eps_t, double phase) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2430, eps_n, eps_t, 0.5),
                 rt::test::simple_material("wall", 2430, eps_n, eps_t, 0.5)};
  m.materials[1].structure = true;
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.gravity = Vec3::Zero();
  const double r = 0.01;
  rt::add_grain(m, r, 0);
  const double mass = 4.0 / 3.0 * M_PI * r * r * r * 2430;
  m.kn = rt::kn_rule(mass, 1.0, 0.01 * r);
  m.dt = rt::dt_rule(mass, m.kn, steps_per_contact);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0, 0, r + (10 + phase) * m.dt);  // touches after 10 + phase steps at 1 m/s
  s.vel[0] = Vec3(0.2, 0, -1);
  for (long k = 0; k < 10000000; ++k) {
    rt::step(m, s);
    if (s.pos[0].z() > r + 1e-4 && s.vel[0].z() > 0) break;
  }
  return {s.vel[0].x(), s.vel[0].z(), s.omega[0].y()};
}

// Least-squares slope of log(error) against log(steps per contact).
double slope(const std::vector<double>& n, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t k = 0; k < n.size(); ++k) {
    const double x = std::log(n[k]), y = std::log(e[k]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double c = double(n.size());
  return (c * sxy - sx * sy) / (c * sxx - sx * sx);
}

// Slopes of the phase-mean errors of (v_x, v_z, ω_y) over 10..320 steps per contact.
std::vector<double> slopes(double eps_n, double eps_t) {
  const Rebound ref = impact(2560, eps_n, eps_t, 0.0);
  const std::vector<double> ns = {10, 20, 40, 80, 160, 320};
  std::vector<double> ex, ez, ew;
  constexpr int kPhases = 8;
  for (double n : ns) {
    double sx = 0, sz = 0, sw = 0;
    for (int p = 0; p < kPhases; ++p) {
      const Rebound o = impact(n, eps_n, eps_t, (p + 0.5) / kPhases);
      sx += std::fabs(o.vx - ref.vx);
      sz += std::fabs(o.vz - ref.vz);
      sw += std::fabs(o.wy - ref.wy);
    }
    ex.push_back(sx / kPhases);
    ez.push_back(sz / kPhases);
    ew.push_back(sw / kPhases);
  }
  return {slope(ns, ex), slope(ns, ez), slope(ns, ew)};
}

TEST(ConvergenceOrder, ElasticObliqueImpactIsSecondOrder) {
  const std::vector<double> s = slopes(1.0, 1.0);
  std::printf("elastic: slopes v_x %.2f, v_z %.2f, omega_y %.2f\n", s[0], s[1], s[2]);
  for (double v : s) EXPECT_LT(v, -1.7);
}

TEST(ConvergenceOrder, DampedObliqueImpactIsFirstOrder) {
  const std::vector<double> s = slopes(0.5, 0.5);
  std::printf("damped: slopes v_x %.2f, v_z %.2f, omega_y %.2f\n", s[0], s[1], s[2]);
  for (double v : s) {
    EXPECT_LT(v, -0.8);  // converges ...
    EXPECT_GT(v, -1.5);  // ... at first order, not second
  }
}

}  // namespace
