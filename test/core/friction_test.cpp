// Friction of a single sphere on a plane wall against closed-form results
// (docs/model.md §2, §5): sliding-to-rolling transition, constant deceleration by
// rolling resistance at its cap, and the Coulomb limit on an incline.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "regolith_twin/core/walls.hpp"
#include "test_support.hpp"

namespace {

using rt::test::figure;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;
constexpr double kR = 0.005;        // grain radius, m
constexpr double kDensity = 2500;   // kg/m^3

struct Scene {
  rt::Model m;
  double mass = 0, inertia = 0;
};

// One grain (material 0) above the plane z = 0 (material 1, a structure
// material that takes the grain's friction), stiffness and step from the
// pkdgrav rule with v_max = 1 m/s, x_max = 1 % of r, 30 steps per contact.
Scene make_scene(double mu_s, double mu_r, double beta, const rt::Vec3& gravity) {
  Scene sc;
  rt::Model& m = sc.m;
  rt::Material g = rt::test::simple_material("grain", kDensity, 0.5, 0.5, mu_s);
  g.mu_r = mu_r;
  g.beta = beta;
  m.materials.push_back(g);
  rt::Material w = rt::test::simple_material("wall", kDensity, 0.5, 0.5, 0.0);
  w.structure = true;
  m.materials.push_back(w);
  rt::add_grain(m, kR, 0);
  m.walls.push_back(rt::make_plane(rt::Vec3::Zero(), rt::Vec3::UnitZ(), 1));
  m.gravity = gravity;
  sc.mass = 4.0 / 3.0 * kPi * kR * kR * kR * kDensity;
  sc.inertia = 0.4 * sc.mass * kR * kR;
  m.kn = rt::kn_rule(sc.mass, 1.0, 0.01 * kR);
  m.dt = rt::dt_rule(sc.mass, m.kn, 30);
  rt::finalize_model(m);
  return sc;
}

// Slope of the least-squares line through (t, y).
double fit_slope(const std::vector<double>& t, const std::vector<double>& y) {
  const double n = double(t.size());
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    st += t[k];
    sy += y[k];
    stt += t[k] * t[k];
    sty += t[k] * y[k];
  }
  return (n * sty - st * sy) / (n * stt - st * st);
}

double overlap(const rt::Model& m, const rt::State& s) { return rt::wall_gap(m.walls[0], s.pos[0], kR).overlap; }

}  // namespace

// A sphere launched sliding (v0, omega0 = 0) decelerates at mu g while
// friction spins it up; it rolls without slip from t = 2 v0 / (7 mu g) on,
// at 5/7 v0 (angular momentum about the contact point is conserved).
TEST(Friction, SlidingSphereEndsRollingAtFiveSevenths) {
  const double mu = 0.5, v0 = 0.5;
  Scene sc = make_scene(mu, 0.0, 0.0, rt::Vec3(0, 0, -kG));
  const rt::Model& m = sc.m;
  rt::State s = rt::make_state(m);
  const double x_eq = sc.mass * kG / m.kn;  // static overlap
  s.pos[0] = rt::Vec3(0, 0, kR - x_eq);
  s.vel[0] = rt::Vec3(v0, 0, 0);

  // Slip velocity of the contact point: v - l omega_y with lever arm l = r - x/2.
  auto slip = [&] { return s.vel[0].x() - (kR - 0.5 * overlap(m, s)) * s.omega[0].y(); };
  const double t_roll = 2.0 * v0 / (7.0 * mu * kG);
  double t_meas = -1;
  while (s.time < 3.0 * t_roll) {
    rt::step(m, s);
    if (t_meas < 0 && slip() <= 0) t_meas = s.time;
  }
  ASSERT_GT(t_meas, 0) << "the sphere never stopped slipping";
  const double ratio = s.vel[0].x() / v0;
  RecordProperty("five_sevenths_rel_error", figure(ratio / (5.0 / 7.0) - 1));
  RecordProperty("roll_time_error_steps", figure((t_meas - t_roll) / m.dt));
  EXPECT_NEAR(t_meas, t_roll, 3 * m.dt) << "rolling reached after " << t_meas / m.dt << " steps, expected "
                                         << t_roll / m.dt;
  EXPECT_NEAR(ratio, 5.0 / 7.0, 0.01 * 5.0 / 7.0);
  // Rolling without slip at the end, the grain still on the plane.
  EXPECT_LT(std::fabs(slip()), 1e-6 * v0);
  EXPECT_NEAR(overlap(m, s), x_eq, 1e-3 * x_eq);
  EXPECT_NEAR(s.vel[0].y(), 0.0, 1e-12);
}

// A sphere rolling on a plane with rolling resistance at its cap feels the
// constant moment M = mu_R beta R f_n (R = r for a wall contact, f_n = m g).
// With static friction F at the contact (lever arm l = r - x/2) and rolling
// without slip (v = l omega):
//   m dv/dt = -F,  I domega/dt = l F - M,  dv/dt = l domega/dt
//   => a = -M l / (I + m l^2).
TEST(Friction, RollingResistanceGivesConstantDeceleration) {
  const double mu_s = 0.5, mu_r = 0.2, beta = 0.5, v0 = 0.5;
  Scene sc = make_scene(mu_s, mu_r, beta, rt::Vec3(0, 0, -kG));
  const rt::Model& m = sc.m;
  ASSERT_TRUE(m.law(0, 1).rolling);
  ASSERT_FALSE(m.law(0, 1).twisting);
  rt::State s = rt::make_state(m);
  const double x_eq = sc.mass * kG / m.kn;
  const double l = kR - 0.5 * x_eq;
  s.pos[0] = rt::Vec3(0, 0, kR - x_eq);
  s.vel[0] = rt::Vec3(v0, 0, 0);
  s.omega[0] = rt::Vec3(0, v0 / l, 0);

  const double M = mu_r * beta * kR * sc.mass * kG;
  const double a_pred = M * l / (sc.inertia + sc.mass * l * l);
  // Fit over a window that starts after the tangential spring has settled and
  // ends well before the sphere stops (v0 / a ~ 0.7 s).
  std::vector<double> ts, vs, ws;
  const double t_stop = v0 / a_pred;
  while (s.time < 0.7 * t_stop) {
    rt::step(m, s);
    if (s.time > 0.05 * t_stop && s.step % 50 == 0) {
      ts.push_back(s.time);
      vs.push_back(s.vel[0].x());
      ws.push_back(s.omega[0].y());
    }
  }
  const double a_meas = -fit_slope(ts, vs);
  const double alpha_meas = -fit_slope(ts, ws);
  RecordProperty("deceleration_rel_error", figure(a_meas / a_pred - 1));
  EXPECT_NEAR(a_meas, a_pred, 0.02 * a_pred);
  EXPECT_NEAR(alpha_meas * l, a_pred, 0.02 * a_pred);  // still rolling without slip
  // The closed form with l = r, a = 5/7 mu_R beta g, differs from this by O(x/r).
  EXPECT_NEAR(a_pred, 5.0 / 7.0 * mu_r * beta * kG, 1e-4 * a_pred);
}

namespace {

// A grain that cannot rotate (infinite moment of inertia, so it cannot roll)
// on the plane z = 0, gravity tilted by theta about y.
struct Incline {
  Scene sc;
  rt::State s;
  double theta;
};

Incline make_incline(double mu, double theta) {
  Incline inc{make_scene(mu, 0.0, 0.0, kG * rt::Vec3(std::sin(theta), 0, -std::cos(theta))), {}, theta};
  rt::Model& m = inc.sc.m;
  m.grain_inv_inertia[0] = 0;  // rotation locked
  inc.s = rt::make_state(m);
  const double x_eq = inc.sc.mass * kG * std::cos(theta) / m.kn;
  inc.s.pos[0] = rt::Vec3(0, 0, kR - x_eq);
  return inc;
}

}  // namespace

// Below the friction angle atan(mu) the grain sticks: after the tangential
// spring has settled, it does not move.
TEST(Friction, CoulombBelowFrictionAngleSticks) {
  const double mu = 0.5;
  Incline inc = make_incline(mu, 0.9 * std::atan(mu));
  const rt::Model& m = inc.sc.m;
  rt::State& s = inc.s;
  while (s.time < 0.03) rt::step(m, s);
  const rt::Vec3 p_settled = s.pos[0];
  while (s.time < 0.2) rt::step(m, s);
  EXPECT_LT((s.pos[0] - p_settled).norm(), 1e-6 * kR);
  EXPECT_LT(s.vel[0].norm(), 1e-9);
  // Held by static friction below its cap.
  EXPECT_NEAR(s.force[0].x(), -inc.sc.mass * kG * std::sin(inc.theta), 1e-9 * inc.sc.mass * kG);
  EXPECT_LT(std::fabs(s.force[0].x()), mu * s.force[0].z());
}

// Above it the grain slides with a = g (sin theta - mu cos theta).
TEST(Friction, CoulombAboveFrictionAngleSlides) {
  const double mu = 0.5;
  Incline inc = make_incline(mu, 1.1 * std::atan(mu));
  const rt::Model& m = inc.sc.m;
  rt::State& s = inc.s;
  std::vector<double> ts, vs;
  while (s.time < 0.1) {
    rt::step(m, s);
    if (s.time > 0.01 && s.step % 20 == 0) {
      ts.push_back(s.time);
      vs.push_back(s.vel[0].x());
    }
  }
  const double a_pred = kG * (std::sin(inc.theta) - mu * std::cos(inc.theta));
  ASSERT_GT(a_pred, 0);
  EXPECT_NEAR(fit_slope(ts, vs), a_pred, 1e-3 * a_pred);
  EXPECT_NEAR(s.vel[0].z(), 0.0, 1e-9);
}
