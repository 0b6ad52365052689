// Gas against weight and the impulse bookkeeping of the plume scene
// (scenes/plume/gas_budget.hpp, docs/scenes.md D): the force table against
// Loth's reference values (docs/model.md §10.1), a grain resting on the
// floor under a constant lift (the gas's and the floor's impulses known in
// closed form), and on a small eroding bed every grain's vertical momentum
// balance closed by the gas, contact and gravity impulses, one record per
// upward crossing.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <sstream>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/model.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/scenes/plume/gas_budget.hpp"
#include "regolith_twin/scenes/plume/plume_scene.hpp"
#include "plume_gas.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
constexpr double kPi = 3.14159265358979323846;
constexpr double kD = rt::test::kPlumeD, kRho = rt::test::kPlumeRho, kMu = rt::test::kPlumeMu;
const double kQ = kPi * kD * kD * kRho / 8;  // C (pi d^2 rho_g / 8): force over |v0|^2 per unit coefficient

// A linear profile U = G h whose grain at rest at h = d / 0.3 has omega* = 0.3 and Re = 3000,
// the reference point of Loth's lift (C_L = 0.03696, docs/model.md §10.1).
constexpr double kH = kD / 0.3;
const double kU = 3000 * kMu / (kRho * kD), kG = kU / kH;

TEST(GasForceTable, DragAndLiftAtLothsReferencePoints) {
  rt::GasFlowParams p = rt::test::plume_gas_flow();
  p.u0 = 10;  // uniform 10 m/s: C_D = 0.5306, no lift
  const rt::GasField uniform(p);
  const rt::GasForceRow r = rt::gas_force_at(uniform, kD / 2, 2e-3, 0);
  EXPECT_NEAR(r.drag, 0.5306 * kQ * 100, 2e-4 * 0.5306 * kQ * 100);
  EXPECT_EQ(r.lift, 0.0);
  EXPECT_DOUBLE_EQ(r.u, 10);
  const rt::GasForceRow half = rt::gas_force_at(uniform, kD / 2, 2e-3, 0.5);
  EXPECT_DOUBLE_EQ(half.relative, 5);
  const rt::GasForceRow with = rt::gas_force_at(uniform, kD / 2, 2e-3, 1);
  EXPECT_EQ(with.drag, 0.0);

  p.u0 = 0;
  p.shear = kG;
  const rt::GasField linear(p);
  const rt::GasForceRow l = rt::gas_force_at(linear, kD / 2, kH, 0);
  EXPECT_NEAR(l.u, kU, 1e-12 * kU);
  EXPECT_NEAR(l.omega_star, 0.3, 1e-12);
  EXPECT_NEAR(l.re, 3000, 1e-9);
  EXPECT_NEAR(l.lift, 0.03696 * kQ * kU * kU, 1e-3 * 0.03696 * kQ * kU * kU);
  // Moving at half the gas speed: half the relative speed, twice omega*.
  const rt::GasForceRow m = rt::gas_force_at(linear, kD / 2, kH, 0.5);
  EXPECT_NEAR(m.omega_star, 0.6, 1e-12);
  EXPECT_NEAR(m.relative, kU / 2, 1e-12 * kU);
  EXPECT_GT(m.lift, 0);
  EXPECT_LT(m.lift, l.lift);

  // The table: a header, a comment, one row per height and fraction; the weight divides the forces.
  const std::string csv = rt::gas_force_table_csv(linear, kD / 2, 2.0 * l.lift, 4 * kD, {kH, 2 * kH}, {0, 0.5});
  std::istringstream in(csv);
  std::string line;
  int rows = 0;
  double lift_over_weight = -1, above_top = 1e9;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'h') continue;
    if (rows++ == 0) {
      std::vector<double> v;
      std::istringstream ls(line);
      std::string c;
      while (std::getline(ls, c, ',')) v.push_back(std::stod(c));
      ASSERT_EQ(v.size(), 11u);
      above_top = v[1];
      lift_over_weight = v[10];
    }
  }
  EXPECT_EQ(rows, 4);
  EXPECT_NEAR(lift_over_weight, 0.5, 1e-5);
  EXPECT_NEAR(above_top, 1 / 0.3 - 4, 1e-5);
}

// One grain resting on the floor under a lift smaller than its weight (drag
// off, so it stays): the gas gives L t / m, the floor (g - L/m) t.
TEST(ImpulseObserver, RestingGrainUnderConstantLift) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2700, 0.8, 0.8, 0.2),
                 rt::test::simple_material("floor", 2700, 0.8, 0.8, 0.2)};
  m.materials[1].structure = true;
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.gravity = Vec3(0, 0, -100);  // heavier than the lift
  rt::add_grain(m, kD / 2, 0);
  m.kn = 8000;
  m.dt = 2e-7;
  rt::GasFlowParams p = rt::test::plume_gas_flow();
  p.shear = kG;
  p.drag = false;
  p.anchor_slot = 0;
  m.fields.push_back(std::make_shared<rt::GasField>(p));
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  const double mass = m.grain_mass[0], lift = 0.03696 * kQ * kU * kU;
  ASSERT_LT(lift, mass * 100);
  // At rest at its equilibrium overlap; the anchoring plane kH below its centre.
  s.pos[0] = Vec3(0, 0, kD / 2 - (mass * 100 - lift) / m.kn);
  s.field_values = {s.pos[0].z() - kH, -1.0};  // erosion plane far below: the grain is above the surface
  rt::ImpulseObserver o(0, 1, 0.0);
  rt::prime(m, s);
  o.start(m, s);
  EXPECT_TRUE(o.tracking(0));
  const int steps = 20000;
  for (int k = 0; k < steps; ++k) {
    rt::step(m, s);
    o.after_step(m, s);
  }
  const double t = steps * m.dt;
  EXPECT_NEAR(o.dv_gas(0), lift / mass * t, 1e-3 * lift / mass * t);
  EXPECT_NEAR(o.dv_contact(0), (100 - lift / mass) * t, 1e-3 * 100 * t);
  EXPECT_NEAR(o.dv_gravity(0), -100 * t, 1e-12);
  EXPECT_NEAR(s.vel[0].z() - o.v_start(0), o.dv_gas(0) + o.dv_contact(0) + o.dv_gravity(0), 1e-12);
  EXPECT_LT(std::abs(s.vel[0].z()), 1e-6);  // it stayed put
  EXPECT_TRUE(o.records().empty());  // never crossed upward
}

// A grain in flight (no contact): the observer's gas force is the field's,
// so the contacts' impulse stays zero to rounding while the gas accelerates it.
TEST(ImpulseObserver, GrainInFlightHasNoContactImpulse) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2700, 0.8, 0.8, 0.2)};
  m.gravity = Vec3(0, 0, -1.63);
  rt::add_grain(m, kD / 2, 0);
  m.kn = 8000;
  m.dt = 5e-7;
  rt::GasFlowParams p = rt::test::plume_gas_flow();
  p.u0 = 5;
  p.shear = kG;
  p.anchor_slot = 0;
  m.fields.push_back(std::make_shared<rt::GasField>(p));
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0, 0, kH);
  s.vel[0] = Vec3(0, 0, 0.3);
  s.field_values = {0.0, -1.0};
  rt::ImpulseObserver o(0, 1, 0.0);
  rt::prime(m, s);
  o.start(m, s);
  for (int k = 0; k < 20000; ++k) {
    rt::step(m, s);
    o.after_step(m, s);
  }
  EXPECT_GT(s.vel[0].x(), 1);         // dragged along
  EXPECT_GT(o.dv_gas(0), 1e-3);       // and lifted
  EXPECT_LT(std::abs(o.dv_contact(0)), 1e-13);
  EXPECT_NEAR(s.vel[0].z() - 0.3, o.dv_gas(0) + o.dv_gravity(0), 1e-12);
  // Rising all along: one ascent since the start, the same sums.
  ASSERT_GT(s.vel[0].z(), 0.3);
  EXPECT_EQ(o.ascent_v_start(0), 0.3);
  EXPECT_EQ(o.ascent_dv_gas(0), o.dv_gas(0));
  EXPECT_EQ(o.ascent_dv_gravity(0), o.dv_gravity(0));
}

TEST(ImpulseObserver, EveryGrainsMomentumBalanceClosesOnAnErodingBed) {
  rt::SceneOptions opt;
  opt.cache_dir = ::testing::TempDir() + "/plume_cache";
  opt.quiet = true;
  std::unique_ptr<rt::Scene> base = rt::load_scene("test/scenes/plume/small_plume.yaml", {}, opt);
  const auto& sc = static_cast<const rt::PlumeScene&>(*base);
  rt::Model m = sc.sc.model;
  rt::State s = sc.start;
  omp_set_num_threads(1);
  rt::test::SceneRunOutcome ran = rt::test::run_scene(sc, m, s);
  const rt::RunReport& rep = ran.report;
  auto& sr = ran.run;
  ASSERT_EQ(rep.status, "ok") << rep.message;
  const auto& pr = static_cast<rt::PlumeRun&>(*sr);
  const rt::ImpulseObserver& o = pr.impulse();
  // One record per upward crossing the erosion observer counted.
  ASSERT_GT(pr.erosion().total_up(), 0);
  EXPECT_EQ(int(o.records().size()), pr.erosion().total_up());
  double gas = 0;
  for (const rt::ImpulseRecord& r : o.records()) {
    EXPECT_NEAR(r.v, r.v_start + r.dv_gas + r.dv_contact + r.dv_gravity, 1e-10) << r.grain;
    EXPECT_NEAR(r.dv_gravity, -1.63 * r.since, 1e-9 * (1 + r.since));
    // The ascent started at v_z <= 0 (or at the run start).
    EXPECT_NEAR(r.v, r.ascent_v_start + r.ascent_dv_gas + r.ascent_dv_contact + r.ascent_dv_gravity, 1e-10);
    if (r.ascent < r.t - 1e-9) {
      EXPECT_LE(r.ascent_v_start, 0.0) << r.grain;
    }
    EXPECT_NEAR(r.ascent_dv_gravity, -1.63 * r.ascent, 1e-9 * (1 + r.ascent));
    gas += r.dv_gas;
  }
  EXPECT_GT(gas, 0);  // the lift points up for grains slower than the gas
  int tracked = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    EXPECT_NEAR(s.vel[i].z(), o.v_start(i) + o.dv_gas(i) + o.dv_contact(i) + o.dv_gravity(i), 1e-10) << i;
    EXPECT_NEAR(s.vel[i].z(),
                o.ascent_v_start(i) + o.ascent_dv_gas(i) + o.ascent_dv_contact(i) + o.ascent_dv_gravity(i), 1e-10)
        << i;
    tracked += o.tracking(i);
  }
  EXPECT_GT(tracked, 0);
}

}  // namespace
