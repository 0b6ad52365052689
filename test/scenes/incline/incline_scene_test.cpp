// The inclined-plane scene kind (docs/scenes.md C.2): the Bagnold fit gives
// back the amplitude of an exact Bagnold profile, and the inertial number
// of Bagnold's solution for a chosen I; the onset test takes a decelerating
// transient for no flow and a sustained one for flow; bad input is refused; a
// flowing bed wraps across the periodic boundary without tripping the energy guard.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "regolith_twin/core/model.hpp"
#include "regolith_twin/run/run.hpp"
#include "regolith_twin/scenes/incline/incline_scene.hpp"
#include "test_support.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Bagnold, FitAndInertialNumberOfAnExactProfile) {
  // Bagnold's profile for I = 0.3, d = 1 cm, h = 0.25 m, Phi = 0.58, theta = 25 deg:
  // v(z) = (2 I h^1.5 / (3 d)) sqrt(Phi g cos theta) [1 - (1 - z/h)^1.5].
  const double I = 0.3, d = 0.01, h = 0.25, phi = 0.58, g = 9.81, th = 25 * kPi / 180;
  const double a = 2 * I * std::pow(h, 1.5) / (3 * d) * std::sqrt(phi * g * std::cos(th));
  std::vector<double> z, v;
  for (int k = 0; k < 30; ++k) {  // 1 cm layers, some above the flow (v = 0 there, ignored)
    z.push_back((k + 0.5) * 0.01);
    v.push_back(z.back() < h ? a * (1 - std::pow(1 - z.back() / h, 1.5)) : 0.0);
  }
  double rms = 1;
  const double fit = rt::bagnold_amplitude(z, v, h, &rms);
  EXPECT_NEAR(fit, a, 1e-12 * a);
  EXPECT_LT(rms, 1e-12);
  EXPECT_NEAR(rt::bagnold_inertial_number(fit, d, h, phi, g, th), I, 1e-12);
  // A uniform profile is no Bagnold profile: the residual says so.
  std::vector<double> flat(z.size(), 1.0);
  rt::bagnold_amplitude(z, flat, h, &rms);
  EXPECT_GT(rms, 0.1);
}

TEST(InclineOnset, TheHoldEndTrendSeparatesATransientFromFlow) {
  const double thr = 0.003;  // m/s
  EXPECT_FALSE(rt::onset_flowing(0.002, 0.0, 1.0, thr));   // too slow
  EXPECT_TRUE(rt::onset_flowing(0.01, 0.5, 1.0, thr));     // flowing and accelerating
  EXPECT_TRUE(rt::onset_flowing(0.01, -0.005, 1.0, thr));  // easing towards a steady flow above the threshold
  // Gravel tilted to 35 deg: surged to 0.35 m/s, left at 0.006 m/s at the end of a 1 s hold, still
  // slowing at 0.12 m/s^2. Above the threshold, but it comes to rest well within one more hold.
  EXPECT_FALSE(rt::onset_flowing(0.006, -0.12, 1.0, thr));
}

TEST(InclineOnset, AStepThroughAnglesSkipsADyingSurgeAndStopsAtSustainedFlow) {
  // The measure and the fix that tilts gravity for it, driven with prescribed grain speeds: at rest at 30 deg, a surge that dies (still above
  // the threshold at the end of the hold) at 31 deg, and an accelerating flow at 32 deg. A hold-end speed
  // alone would call 31 deg the onset.
  rt::InclineSpec sp;
  sp.onset = true;
  sp.start_deg = 30;
  sp.max_deg = 35;
  sp.hold = 0.1;
  const double d = 0.01, g = 9.81;  // threshold 0.01 sqrt(g d) = 3.1 mm/s
  rt::InclineObserver ob(sp, 0.0, 0.1, d, 0.02, g);
  rt::InclineFix fix(sp, ob, g, 0.0);
  rt::Model m;
  m.n_grains = 2;
  m.grain_inv_mass = {1.0, 1.0};
  m.grain_hold = {0, 0};
  m.dt = 1e-3;
  rt::State s;
  s.pos.assign(2, rt::Vec3::Zero());
  s.vel.assign(2, rt::Vec3::Zero());
  fix.prepare(m, s);
  ob.start(m, s);
  EXPECT_DOUBLE_EQ(ob.theta_deg(), 30);
  EXPECT_NEAR(m.gravity.x(), g * std::sin(30 * kPi / 180), 1e-12);
  double theta = ob.theta_deg(), t0 = 0;
  bool done = false;
  for (int k = 0; k < 1000 && !done; ++k) {
    s.time += m.dt;
    ++s.step;
    const double t = s.time - t0;
    double v = 0;
    if (theta == 31) v = 0.05 * (1 - t / 0.11);  // 4.5 mm/s at the end of the hold, slowing at 0.45 m/s^2
    if (theta == 32) v = 0.02 + 0.5 * t;
    for (auto& u : s.vel) u = rt::Vec3(v, 0, 0);
    done = ob.after_step(m, s);
    fix.after_measures(m, s);
    if (ob.theta_deg() != theta) {
      theta = ob.theta_deg();
      t0 = s.time;
    }
  }
  ASSERT_TRUE(done);
  EXPECT_DOUBLE_EQ(ob.onset_deg(), 32);
  EXPECT_NEAR(m.gravity.x(), g * std::sin(32 * kPi / 180), 1e-12);
}

// Loading `file` with the overrides `set` is refused with an error naming `what`.
void expect_refused(const std::string& file, const std::vector<std::string>& set, const std::string& what) {
  rt::SceneOptions o;
  o.quiet = true;
  o.cache_dir = ::testing::TempDir() + "/incline_cache";
  try {
    rt::load_scene(file, set, o);
    ADD_FAILURE() << "accepted: " << what;
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(InclineScene, BadInputIsRefused) {
  auto refused = [](const std::vector<std::string>& set, const std::string& what) {
    expect_refused("config/incline_moderate.yaml", set, what);
  };
  refused({"incline.mode=tilt"}, "incline.mode");
  refused({"incline.angle_deg=95"}, "incline.angle_deg");
  refused({"incline.average=10"}, "incline.average");  // longer than the run
  refused({"periodic.y=null"}, "periodic");
}

TEST(InclineScene, AFlowingPeriodicBedWrapsWithoutTrippingTheEnergyGuard) {
  // 150 grains at 40 degrees: they flow downhill (+x) and wrap across the periodic boundary, each wrap
  // raising the potential energy -m g.x by m g_x L. Gravity along a periodic axis is an energy input
  // (docs/model.md §13): the energy-growth guard must not stop the run; the other guards stay on.
  rt::SceneOptions o;
  o.quiet = true;
  o.cache_dir = ::testing::TempDir() + "/incline_cache";
  auto sc = rt::load_scene("config/incline_moderate.yaml",
                           {"grains.1.fill.count=150", "incline.angle_deg=40", "incline.duration=0.4",
                            "incline.average=0.1"},
                           o);
  rt::Model m = sc->sc.model;
  rt::State s = sc->start;
  ASSERT_GT(m.guards.max_energy_growth, 0);
  const std::vector<rt::Vec3> x0 = s.pos;
  rt::RunOptions ro;
  ro.progress_every = 0;
  rt::Run run(m, s, sc->plan, ro);
  auto sr = sc->begin(run);
  sr->attach(run);
  const rt::RunReport rep = run.run();
  ASSERT_EQ(rep.status, "ok") << rep.message;
  int wrapped = 0;  // grains that crossed the downhill boundary (without the input rule, the guard stops at 0.32 s)
  for (int i = 0; i < m.n_grains; ++i)
    if (m.grain_inv_mass[i] != 0) wrapped += s.pos[i].x() < x0[i].x() - 0.5 * m.periodic.length.x();
  EXPECT_GT(wrapped, 0);
}

TEST(InclineRain, TrendIsTheLeastSquaresSlope) {
  EXPECT_NEAR(rt::trend({0, 1, 2, 3}, {1, 3, 5, 7}), 2.0, 1e-12);
  EXPECT_NEAR(rt::trend({0, 1, 2}, {1, 1, 1}), 0.0, 1e-12);
  EXPECT_EQ(rt::trend({1}, {5}), 0.0);  // one point: no trend
}

// Runs the rain protocol on a small box (300 grains, 0.5 s, the last 0.2 s averaged).
std::unique_ptr<rt::Scene> rain_scene(const std::vector<std::string>& extra, rt::Model& m, rt::State& s,
                                      std::unique_ptr<rt::SceneRun>& sr, rt::RunReport& rep) {
  rt::SceneOptions o;
  o.quiet = true;
  o.cache_dir = ::testing::TempDir() + "/incline_cache";
  std::vector<std::string> set = {"grains.0.fill.count=300", "grains.0.fill.hi=[0.20,0.10,0.12]",
                                  "incline.duration=0.5", "incline.average=0.2"};
  set.insert(set.end(), extra.begin(), extra.end());
  auto sc = rt::load_scene("config/incline_rain.yaml", set, o);
  m = sc->sc.model;
  s = sc->start;
  rt::test::SceneRunOutcome ran = rt::test::run_scene(*sc, m, s);
  sr = std::move(ran.run);
  rep = ran.report;
  return sc;
}

TEST(InclineRain, GrainsThatTouchThePlaneAreGluedWhereTheyLand) {
  rt::Model m;
  rt::State s;
  std::unique_ptr<rt::SceneRun> sr;
  rt::RunReport rep;
  auto sc = rain_scene({"incline.angle_deg=20"}, m, s, sr, rep);
  ASSERT_EQ(rep.status, "ok") << rep.message;
  const auto& ob = static_cast<rt::InclineRun&>(*sr).observer();
  // The tilt was there from the start; no grain began glued, and those glued now all touched the plane.
  EXPECT_NEAR(m.gravity.x(), 9.81 * std::sin(20 * kPi / 180), 1e-12);
  int glued = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    EXPECT_FALSE(sc->sc.model.grain_hold[i]);
    if (!m.grain_hold[i]) {
      EXPECT_GE(s.pos[i].z() - m.grain_radius[i], -1e-3) << "a free grain sank into the plane";
      continue;
    }
    ++glued;
    EXPECT_LT(s.pos[i].z() - m.grain_radius[i], 0.0) << "glued without touching the plane";
    EXPECT_EQ(s.vel[i].norm(), 0.0);
  }
  EXPECT_EQ(glued, ob.glued());
  EXPECT_GT(glued, 20);      // the first to land form a base ...
  EXPECT_LT(glued, 200);     // ... the others rest on it
  // 20 degrees is far below any onset: the deposit is coming to rest.
  EXPECT_FALSE(ob.flowing());
  EXPECT_LT(ob.end_dvdt(), 0.0);
}

TEST(InclineRain, SteepEnoughTheDepositFlows) {
  rt::Model m;
  rt::State s;
  std::unique_ptr<rt::SceneRun> sr;
  rt::RunReport rep;
  auto sc = rain_scene({"incline.angle_deg=60"}, m, s, sr, rep);
  ASSERT_EQ(rep.status, "ok") << rep.message;
  const auto& ob = static_cast<rt::InclineRun&>(*sr).observer();
  EXPECT_TRUE(ob.flowing());
  EXPECT_GT(ob.end_vx(), 0.5);
  EXPECT_GT(ob.profile().height, 0.0);
}

TEST(InclineRain, TheRestStopEndsARestingDepositWithTheFullRunsVerdict) {
  // 150 grains at 20 degrees, 1 s: the full run and the run that ends once every grain has been slow for 0.1 s
  // (at 0.82 s) agree that the deposit does not flow; the stopped run ends before the full one, with its end
  // speed below the rest limit (0.01 sqrt(g d)) and the full run's end speed below that limit too.
  rt::Model m1, m2;
  rt::State s1, s2;
  std::unique_ptr<rt::SceneRun> r1, r2;
  rt::RunReport rep1, rep2;
  const std::vector<std::string> small = {"grains.0.fill.count=150", "grains.0.fill.hi=[0.20,0.10,0.06]",
                                          "incline.angle_deg=20", "incline.duration=1.0"};
  std::vector<std::string> full_run = small, stopped = small;
  full_run.push_back("incline.rest_speed=0");
  stopped.insert(stopped.end(), {"incline.rest_speed=0.01", "incline.rest_hold=0.1"});
  rain_scene(full_run, m1, s1, r1, rep1);
  rain_scene(stopped, m2, s2, r2, rep2);
  ASSERT_EQ(rep1.status, "ok") << rep1.message;
  ASSERT_EQ(rep2.status, "ok") << rep2.message;
  const auto& full = static_cast<rt::InclineRun&>(*r1).observer();
  const auto& stop = static_cast<rt::InclineRun&>(*r2).observer();
  EXPECT_FALSE(full.rested());
  ASSERT_TRUE(stop.rested());
  EXPECT_LT(stop.rest_time(), 0.95);
  // What the stop leaves out: the deposit moves by less than 1 % of a diameter between the stop and 1 s.
  ASSERT_EQ(m1.n_grains, m2.n_grains);
  double moved = 0;
  for (int i = 0; i < m1.n_grains; ++i) moved = std::max(moved, (s1.pos[i] - s2.pos[i]).norm());
  EXPECT_LT(moved, 1e-4);
  EXPECT_NEAR(s2.time, stop.rest_time(), 1e-9);
  EXPECT_EQ(full.flowing(), stop.flowing());
  EXPECT_FALSE(stop.flowing());
  const double limit = 0.01 * std::sqrt(9.81 * 0.01);
  EXPECT_LT(std::abs(stop.end_vx()), limit);
  EXPECT_LT(std::abs(full.end_vx()), limit);
}

TEST(InclineRain, TheRestStopStaysOffWhileTheDepositFlows) {
  rt::Model m;
  rt::State s;
  std::unique_ptr<rt::SceneRun> sr;
  rt::RunReport rep;
  rain_scene({"incline.angle_deg=60", "incline.rest_speed=0.01"}, m, s, sr, rep);
  ASSERT_EQ(rep.status, "ok") << rep.message;
  const auto& ob = static_cast<rt::InclineRun&>(*sr).observer();
  EXPECT_FALSE(ob.rested());
  EXPECT_TRUE(ob.flowing());
  EXPECT_NEAR(s.time, 0.5, 1e-6);
}

TEST(InclineRain, BadInputIsRefused) {
  expect_refused("config/incline_moderate.yaml", {"incline.rest_speed=0.01"}, "mode rain only");
  expect_refused("config/incline_rain.yaml", {"grains.0.fixed=true"}, "fixed");
  expect_refused("config/incline_rain.yaml", {"walls=[]"}, "plane floor");
}

}  // namespace
