// The plume scene kind (docs/scenes.md D): the erosion planes' bookkeeping
// (counts, crossings, the planes' motion by N_lost V_p / (phi A), the moving
// averages, the erosion rate's least-squares fit), contacts among free
// grains switched off, the collisionless hold, a short plume over a small settled
// bed (the step from t_c / steps_per_contact, the planes placed from the top,
// N equal to the net crossings, the same run for 1 and 2 threads), and bad
// input refused.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/scenes/plume/plume_scene.hpp"
#include "regolith_twin/core/model.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
constexpr double kPi = 3.14159265358979323846;
const char* kPlume = "test/scenes/plume/small_plume.yaml";

// Four free grains of 1 mm, far apart, no gravity.
struct Four {
  rt::Model m;
  rt::State s;
};

Four four() {
  Four f;
  rt::test::grains_in_a_row(f.m, f.s, std::vector<double>(4, 5e-4), 0.01);
  return f;
}

rt::ErosionPlanes planes(rt::PlaneMotion motion) {
  rt::ErosionPlanes p;
  p.anchor = 0.0;
  p.erosion = 0.002;
  p.grain_volume = kPi / 6 * 1e-9;
  p.bed_fraction = 0.6;
  p.area = 5e-5;
  p.motion = motion;
  p.window = 2;
  return p;
}

TEST(ErosionFix, CountsCrossingsAndMovesThePlanes) {
  for (rt::PlaneMotion motion : {rt::PlaneMotion::Net, rt::PlaneMotion::Upward, rt::PlaneMotion::Fixed}) {
    Four f = four();
    rt::ErosionFix e(planes(motion));
    e.prepare(f.m, f.s);
    ASSERT_EQ(f.s.field_values.size(), 2u);
    e.start(f.m, f.s);
    const double dz = kPi / 6 * 1e-9 / (0.6 * 5e-5);  // one grain's share of the bed's height
    // Step 1: grains 0 and 1 rise above the erosion plane.
    f.s.pos[0].z() = 0.003;
    f.s.pos[1].z() = 0.003;
    f.s.time = 1e-6;
    e.after_measures(f.m, f.s);
    EXPECT_EQ(e.above(), 2);
    const double moved1 = motion == rt::PlaneMotion::Fixed ? 0 : 2 * dz;
    EXPECT_NEAR(f.s.field_values[1], 0.002 - moved1, 1e-15);
    EXPECT_NEAR(f.s.field_values[0], 0.0 - moved1, 1e-15);
    // Step 2: grain 0 falls back; grain 2 rises.
    f.s.pos[0].z() = 0.0005;
    f.s.pos[2].z() = 0.003;
    f.s.time = 2e-6;
    e.after_measures(f.m, f.s);
    EXPECT_EQ(e.above(), 2);
    const double moved2 = motion == rt::PlaneMotion::Net ? 2 * dz : motion == rt::PlaneMotion::Upward ? 3 * dz : 0;
    EXPECT_NEAR(f.s.field_values[1], 0.002 - moved2, 1e-15);
    EXPECT_EQ(e.total_up(), 3);
    EXPECT_EQ(e.total_down(), 1);
    EXPECT_DOUBLE_EQ(e.sedimentation_from(), 2e-6);
    // Moving averages over the 2-step window: (2 + 1) / 2 up, (0 + 1) / 2 down.
    const rt::ErosionRow& r = e.rows().back();
    EXPECT_DOUBLE_EQ(r.up, 1.5);
    EXPECT_DOUBLE_EQ(r.down, 0.5);
    // Step 3: every grain above.
    for (int i = 0; i < 4; ++i) f.s.pos[i].z() = 0.01;
    f.s.time = 3e-6;
    e.after_measures(f.m, f.s);
    EXPECT_EQ(e.above(), 4);
    EXPECT_DOUBLE_EQ(e.all_above_at(), 3e-6);
    EXPECT_DOUBLE_EQ(e.depleted_at(), 3e-6);  // 4 >= 0.9 * 4 first here
    e.finish(f.m, f.s);
    // N(t) = 0, 2, 2, 4 at t = 0, 1, 2, 3 us: least-squares slope 1.2 grains/us.
    EXPECT_NEAR(e.rate(), 1.2e6, 1e-6);
    EXPECT_NEAR(e.rate_per_area(), 1.2e6 / 5e-5, 1e-3);
  }
}

TEST(ErosionFix, CollisionlessHoldsTheBedBelowTheAnchoringPlane) {
  Four f = four();
  rt::ErosionPlanes p = planes(rt::PlaneMotion::Fixed);
  p.anchor = 0.0015;
  p.hold_below_anchor = true;
  rt::ErosionFix e(p);
  e.prepare(f.m, f.s);  // every grain (z = 1 mm) is below: held
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f.m.grain_inv_mass[i], 0) << i;
  EXPECT_FALSE(f.s.forces_valid);
  e.start(f.m, f.s);
  f.s.field_values[0] = 0.0005;  // the plane passes below them: freed
  e.after_measures(f.m, f.s);
  for (int i = 0; i < 4; ++i) EXPECT_GT(f.m.grain_inv_mass[i], 0) << i;
  f.s.pos[3].z() = 0.0001;  // one sinks below it: held again, at rest
  f.s.vel[3] = Vec3(1, 0, -1);
  e.after_measures(f.m, f.s);
  EXPECT_EQ(f.m.grain_inv_mass[3], 0);
  EXPECT_EQ(f.s.vel[3], Vec3::Zero());
  e.finish(f.m, f.s);  // the masses restored
  for (int i = 0; i < 4; ++i) EXPECT_GT(f.m.grain_inv_mass[i], 0) << i;
}

TEST(MobileContacts, FreeGrainsPassThroughEachOtherButTouchGluedOnes) {
  Four f = four();
  f.s.pos[1] = Vec3(0.0009, 0, 0.001);  // 0.1 mm overlap with grain 0
  f.m.mobile_contacts = false;  // free grains pass through each other ...
  for (int k = 0; k < 10; ++k) rt::step(f.m, f.s);
  EXPECT_EQ(f.s.pairs.size(), 0);
  EXPECT_EQ(f.s.vel[0], Vec3::Zero());
  EXPECT_EQ(f.s.vel[1], Vec3::Zero());
  rt::hold_grain(f.m, f.s, 0, rt::kHoldGlued);  // ... but touch a glued one
  f.s.rebuild_requested = true;
  rt::step(f.m, f.s);
  EXPECT_GT(f.s.vel[1].x(), 0);
  EXPECT_EQ(f.s.vel[0], Vec3::Zero());
  rt::release_grain(f.m, 0, rt::kHoldGlued);
  f.s.vel[1] = Vec3::Zero();
  f.m.mobile_contacts = true;  // the same overlap pushes both apart
  f.s.rebuild_requested = true;
  rt::step(f.m, f.s);
  EXPECT_LT(f.s.vel[0].x(), 0);
  EXPECT_GT(f.s.vel[1].x(), 0);
}

rt::SceneOptions quiet_options() {
  rt::SceneOptions o;
  o.cache_dir = ::testing::TempDir() + "/plume_cache";
  o.quiet = true;
  return o;
}

std::unique_ptr<rt::PlumeScene> load(const std::vector<std::string>& set = {}) {
  std::unique_ptr<rt::Scene> sc = rt::load_scene(kPlume, set, quiet_options());
  EXPECT_EQ(sc->kind(), "plume");
  return std::unique_ptr<rt::PlumeScene>(static_cast<rt::PlumeScene*>(sc.release()));
}

struct PlumeResult {
  rt::Model m;
  rt::State s;
  int above = 0, up = 0, down = 0;
  double rate = 0;
};

PlumeResult run_plume(const rt::PlumeScene& sc, bool parallel = false) {
  PlumeResult out{sc.sc.model, sc.start};
  if (parallel) out.m.parallel_min_grains = 0;  // the threaded passes even for 400 grains
  rt::test::SceneRunOutcome ran = rt::test::run_scene(sc, out.m, out.s);
  const rt::RunReport& rep = ran.report;
  auto& sr = ran.run;
  EXPECT_EQ(rep.status, "ok") << rep.message;
  const auto& e = static_cast<rt::PlumeRun&>(*sr).erosion();
  out.above = e.above();
  out.up = e.total_up();
  out.down = e.total_down();
  out.rate = e.rate();
  return out;
}

TEST(PlumeScene, ASettledBedErodesWithThePlanesFollowing) {
  auto sc = load();
  const rt::Model& m = sc->sc.model;
  const double d = 1e-3, mass = 2700 * kPi / 6 * d * d * d;
  // dt = t_c / 20 with damping, m* = m / 2.
  EXPECT_NEAR(m.dt, std::sqrt(mass / 2 * (kPi * kPi + std::pow(std::log(0.8), 2)) / 8000) / 20, 1e-15);
  EXPECT_NEAR(sc->diameter, d, 1e-15);
  EXPECT_GT(sc->top / d, 6.0);  // 400 grains in 10 d x 5 d at about 0.6
  EXPECT_LT(sc->top / d, 9.0);
  EXPECT_GT(sc->bed_fraction, 0.5);
  EXPECT_LT(sc->bed_fraction, 0.66);
  EXPECT_NEAR(sc->planes.anchor, sc->top - 4 * d, 1e-15);
  EXPECT_NEAR(sc->planes.erosion, sc->top + d, 1e-15);
  ASSERT_EQ(sc->start.field_values.size(), 2u);
  EXPECT_EQ(sc->start.field_values[0], sc->planes.anchor);
  // U at the top: 30 + 9 ln(1 + 4 d / 1 mm).
  EXPECT_NEAR(sc->gas_at_top, 30 + 9 * std::log(5.0), 1e-9);
  omp_set_num_threads(1);
  const PlumeResult a = run_plume(*sc);
  EXPECT_GT(a.up, 0);  // the strong gas lifts grains within 20 ms
  EXPECT_EQ(a.above, a.up - a.down);  // none above at the start
  // The erosion plane moved down by the net loss's share of the bed.
  const double dz = (a.up - a.down) * kPi / 6 * d * d * d / (sc->bed_fraction * 1e-4 * 0.5);
  EXPECT_NEAR(a.s.field_values[1], sc->planes.erosion - dz, 1e-12);
  EXPECT_NEAR(a.s.field_values[0], sc->planes.anchor - dz, 1e-12);
  EXPECT_GT(a.rate, 0);
  // Same input, same result through the threaded passes on 2 threads.
  omp_set_num_threads(2);
  const PlumeResult b = run_plume(*sc, true);
  EXPECT_EQ(a.above, b.above);
  EXPECT_EQ(a.up, b.up);
  for (int i = 0; i < a.m.n_grains; ++i) ASSERT_EQ(a.s.pos[i], b.s.pos[i]) << i;
}

TEST(PlumeScene, WithoutGasTheBedStaysPut) {
  auto sc = load({"gas.u0=0", "gas.u_log=0", "plume.duration=0.005"});
  const PlumeResult r = run_plume(*sc);
  EXPECT_EQ(r.up, 0);
  EXPECT_EQ(r.above, 0);
  EXPECT_EQ(r.s.field_values[1], sc->planes.erosion);
}

TEST(PlumeScene, BadInputIsRefused) {
  auto refused = [](const std::vector<std::string>& set, const std::string& what) {
    try {
      rt::load_scene(kPlume, set, quiet_options());
      ADD_FAILURE() << "accepted: " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("small_plume.yaml"), std::string::npos) << e.what();
    }
  };
  refused({"plume.plane_motion=sideways"}, "plume.plane_motion");
  refused({"plume.penetration_depth=-1"}, "plume.penetration_depth");
  refused({"plume.depleted_fraction=0"}, "plume.depleted_fraction");
  refused({"plume.wind=1"}, "wind");
  refused({"periodic.y=null"}, "periodic");
}

}  // namespace
