// The gas field (field.hpp GasField, docs/model.md §10): drag and lift
// assembled from Loth's coefficients, their signs and limits, the anchoring
// plane, and single grains reaching the analytic terminal velocity.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/gas.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/io/generate.hpp"
#include "plume_gas.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
using rt::test::kPlumeC;
constexpr double kRho = rt::test::kPlumeRho, kMu = rt::test::kPlumeMu, kC = kPlumeC;
constexpr double kD = rt::test::kPlumeD, kGrainDensity = rt::test::kPlumeGrainDensity;

rt::GasFlowParams plume_gas() { return rt::test::plume_gas_flow(); }
rt::GasConstants constants() { return rt::test::plume_gas_constants(); }
double reynolds(double v) { return rt::test::plume_reynolds(v); }

TEST(GasField, DragIsLothsCoefficientTimesDynamicPressure) {
  rt::GasFlowParams p = plume_gas();
  p.u0 = 20;
  p.lift = false;
  const rt::GasField f(p);
  for (const Vec3& v : {Vec3(0, 0, 0), Vec3(3, -1, 2), Vec3(25, 0, -4), Vec3(-300, 0, 0)}) {
    const Vec3 v0 = Vec3(20, 0, 0) - v;
    const double speed = v0.norm();
    const Vec3 want = rt::loth_drag(reynolds(speed), speed / kC, constants()) * (kPi * kD * kD * kRho / 8) * speed * v0;
    const Vec3 got = f.force(kD / 2, 1e-3, v);
    EXPECT_LT((got - want).norm(), 1e-12 * want.norm()) << v.transpose();
  }
  EXPECT_EQ(f.force(kD / 2, 1e-3, Vec3(20, 0, 0)), Vec3::Zero());  // moving with the gas
}

TEST(GasField, LiftSignAndSize) {
  rt::GasFlowParams p = plume_gas();
  p.shear = 2000;  // U = 2000 h: 2 m/s at 1 mm
  p.drag = false;
  const rt::GasField f(p);
  const double h = 1e-3, u = 2;
  // At rest in the flow: lifted, by C_L (pi d^2 rho / 8) U^2 with omega* = G d / U.
  const Vec3 rest = f.force(kD / 2, h, Vec3::Zero());
  const double want = rt::loth_lift(reynolds(u), 2000 * kD / u) * (kPi * kD * kD * kRho / 8) * u * u;
  EXPECT_GT(want, 0);
  EXPECT_NEAR(rest.z(), want, 1e-12 * want);
  EXPECT_EQ(rest.x(), 0.0);
  EXPECT_EQ(rest.y(), 0.0);
  // Outrunning the gas: pushed down.
  EXPECT_LT(f.force(kD / 2, h, Vec3(5, 0, 0)).z(), 0);
  // Moving with the gas: no lift.
  EXPECT_EQ(f.force(kD / 2, h, Vec3(u, 0, 0)).z(), 0.0);
  // A flow of the other direction, growing the other way: the same picture mirrored.
  p.shear = -2000;
  const rt::GasField mirrored(p);
  EXPECT_NEAR(mirrored.force(kD / 2, h, Vec3::Zero()).z(), want, 1e-12 * want);
  EXPECT_LT(mirrored.force(kD / 2, h, Vec3(-5, 0, 0)).z(), 0);
  // Sheared along another horizontal direction: the same size.
  p.shear = 2000;
  p.direction = Vec3(0, 3, 0);
  EXPECT_NEAR(rt::GasField(p).force(kD / 2, h, Vec3::Zero()).z(), want, 1e-12 * want);
  // No shear: no lift.
  p.shear = 0;
  p.u0 = 2;
  EXPECT_EQ(rt::GasField(p).force(kD / 2, h, Vec3::Zero()).z(), 0.0);
}

TEST(GasField, Profile) {
  rt::GasFlowParams p = plume_gas();
  p.u0 = 1;
  p.shear = 100;
  p.u_log = 2;
  p.h_log = 1e-3;
  const double h = 3e-3;
  EXPECT_DOUBLE_EQ(p.velocity(h), 1 + 100 * h + 2 * std::log(4.0));
  EXPECT_DOUBLE_EQ(p.gradient(h), 100 + 2 / (1e-3 + h));
  const double dh = 1e-7;
  EXPECT_NEAR((p.velocity(h + dh) - p.velocity(h - dh)) / (2 * dh), p.gradient(h), 1e-6 * p.gradient(h));
}

// One grain of the plume's kind in free space, at rest 1 m above the plane.
struct OneGrain {
  rt::Model m;
  rt::State s;
};

OneGrain one_grain(const rt::GasFlowParams& p, const Vec3& g, double dt) {
  OneGrain o;
  o.m.materials.push_back(rt::test::simple_material("grain", kGrainDensity, 0.5, 0.5, 0.5));
  o.m.gravity = g;
  rt::add_grain(o.m, kD / 2, 0);
  const double mass = kGrainDensity * kPi / 6 * kD * kD * kD;
  o.m.kn = rt::kn_rule(mass, 1.0, 0.01 * kD);
  o.m.dt = dt;
  o.m.skin = 0.05;  // alone in space: a skin above the 1 cm a step of the fastest case moves
  o.m.fields.push_back(std::make_shared<rt::GasField>(p));
  rt::finalize_model(o.m);
  o.s = rt::make_state(o.m);
  o.s.pos[0] = Vec3(0, 0, 1);
  return o;
}

// Speed at which the drag balances weight m g in still gas (bisection on the
// force balance C_D Re (pi d mu / 8) v = m g).
double terminal_speed(double g) {
  const double mg = kGrainDensity * kPi / 6 * kD * kD * kD * g;
  double lo = 0, hi = 1000;
  for (int k = 0; k < 200; ++k) {
    const double v = (lo + hi) / 2;
    const double drag = rt::loth_drag_re(reynolds(v), v / kC, constants()) * (kPi * kD * kMu / 8) * v;
    (drag > mg ? hi : lo) = v;
  }
  return (lo + hi) / 2;
}

TEST(GasField, FallingGrainReachesTerminalVelocity) {
  // Lunar gravity: v_t = 2.22 m/s (Re 142), relaxation time ~1.4 s.
  rt::GasFlowParams p = plume_gas();
  p.anchor_z = -1e6;
  for (double g : {1.63, 9.81}) {
    OneGrain o = one_grain(p, Vec3(0, 0, -g), 1e-3);
    for (int k = 0; k < 20000; ++k) rt::step(o.m, o.s);
    const double vt = terminal_speed(g);
    EXPECT_GT(vt, g == 1.63 ? 2.2 : 6.7);
    EXPECT_NEAR(-o.s.vel[0].z(), vt, 1e-6 * vt) << "g = " << g;
    EXPECT_EQ(o.s.vel[0].x(), 0.0);
  }
}

TEST(GasField, GrainInAUniformFlowTakesItsVelocity) {
  rt::GasFlowParams p = plume_gas();
  p.u0 = 10;
  p.direction = Vec3(1, 1, 0);
  p.anchor_z = -1e6;
  OneGrain o = one_grain(p, Vec3::Zero(), 1e-3);
  // The last approach is Stokes-like, time constant m / (3 pi mu d) = 7.6 s: 100 s.
  for (int k = 0; k < 100000; ++k) rt::step(o.m, o.s);
  const Vec3 u = 10 * Vec3(1, 1, 0).normalized();
  EXPECT_LT((o.s.vel[0] - u).norm(), 1e-6 * 10);
}

TEST(GasField, OnlyAboveTheAnchoringPlane) {
  rt::GasFlowParams p = plume_gas();
  p.u0 = 10;
  p.anchor_z = 1.0;  // the grain's centre is at 1 m: on the plane, no force
  OneGrain o = one_grain(p, Vec3::Zero(), 1e-4);
  for (int k = 0; k < 10; ++k) rt::step(o.m, o.s);
  EXPECT_EQ(o.s.vel[0], Vec3::Zero());
  // The plane from the state's slot: moved below the grain, the gas acts.
  p.anchor_slot = 0;
  OneGrain q = one_grain(p, Vec3::Zero(), 1e-4);
  q.s.field_values = {2.0};
  rt::step(q.m, q.s);
  EXPECT_EQ(q.s.vel[0], Vec3::Zero());
  q.s.field_values[0] = 0.5;
  rt::step(q.m, q.s);
  EXPECT_GT(q.s.vel[0].x(), 0);
  // A state without the slot is refused before the first step, naming the field.
  OneGrain r = one_grain(p, Vec3::Zero(), 1e-4);
  r.s.field_values.clear();
  r.s.forces_valid = false;
  try {
    rt::step(r.m, r.s);
    ADD_FAILURE() << "a state without the anchoring plane's slot was stepped";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'gas' reads 1 entries"), std::string::npos) << e.what();
  }
}

TEST(GasField, ANozzlesPlumeFlowsOutwardAndThinsWithDistance) {
  rt::GasFlowParams p = plume_gas();
  p.u0 = 50;
  p.radial = true;
  p.nozzle = Vec3(1, 2, 3);
  p.density_length = 0.5;
  const rt::GasField f(p);
  const double r = kD / 2, h = 0.01;
  // Outward from the point below the nozzle, in any horizontal direction.
  const Vec3 east = f.force_at(r, h, Vec3(2, 2, 0), Vec3::Zero());
  const Vec3 north = f.force_at(r, h, Vec3(1, 3, 0), Vec3::Zero());
  EXPECT_GT(east.x(), 0);
  EXPECT_EQ(east.y(), 0);
  EXPECT_GT(north.y(), 0);
  EXPECT_EQ(north.x(), 0);
  EXPECT_EQ(f.force_at(r, h, Vec3(1, 2, 0), Vec3::Zero()), Vec3::Zero());  // right below: no flow
  // At r = L the density is half: the same force as a uniform gas of half the density.
  rt::GasFlowParams q = plume_gas();
  q.u0 = 50;
  q.density = p.density / 2;
  const Vec3 at_l = f.force_at(r, h, p.nozzle + Vec3(0.3, 0.4, 0), Vec3::Zero());  // |x - nozzle| = 0.5
  const Vec3 half = rt::GasField(q).force(r, h, Vec3::Zero());
  EXPECT_NEAR(at_l.x(), 0.6 * half.x(), 1e-15 * half.norm());
  EXPECT_NEAR(at_l.y(), 0.8 * half.x(), 1e-15 * half.norm());
  EXPECT_NEAR(at_l.z(), half.z(), 1e-15 * half.norm());
}

TEST(GasField, BadParametersAreRefused) {
  auto refused = [](rt::GasFlowParams p, const char* what) {
    try {
      rt::GasField f(p);
      ADD_FAILURE() << "accepted " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  rt::GasFlowParams p = plume_gas();
  p.density = 0;
  refused(p, "density");
  p = plume_gas();
  p.viscosity = NAN;
  refused(p, "viscosity");
  p = plume_gas();
  p.u_log = 1;
  refused(p, "h_log");
  p = plume_gas();
  p.direction = Vec3(1, 0, 1);
  refused(p, "horizontal");
  p = plume_gas();
  p.gamma = 1;
  refused(p, "gamma");
}

}  // namespace
