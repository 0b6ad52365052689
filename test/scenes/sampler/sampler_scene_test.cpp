// The sampler scene kind (docs/scenes.md B): the shot's stiffness and step
// from its speed, the placement of horn and projectile, a short shot on a
// small bed (impact seen, horn counts equal a recount from the saved state,
// identical for 1 and 2 threads), bad input refused; the horn's counting
// volume against the URDF, the collected mass through the top; the crater's
// cell volumes and its depth and radius on a bed with a known hole.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/scenes/sampler/sampler_scene.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
constexpr double kPi = 3.14159265358979323846;
const char* kShot = "test/scenes/sampler/small_shot.yaml";

rt::SceneOptions quiet_options() {
  rt::SceneOptions o;
  o.cache_dir = ::testing::TempDir() + "/sampler_cache";
  o.quiet = true;
  return o;
}

std::unique_ptr<rt::SamplerScene> load(const std::vector<std::string>& set = {}) {
  std::unique_ptr<rt::Scene> sc = rt::load_scene(kShot, set, quiet_options());
  EXPECT_EQ(sc->kind(), "sampler");
  return std::unique_ptr<rt::SamplerScene>(static_cast<rt::SamplerScene*>(sc.release()));
}

TEST(SamplerScene, StiffnessStepAndPlacement) {
  auto sc = load();
  const rt::Model& m = sc->sc.model;
  const rt::State& s = sc->start;
  EXPECT_DOUBLE_EQ(m.kn, 5.47e6);  // 5.47e6 N/m (50/50)^2
  EXPECT_DOUBLE_EQ(m.dt, 1.5e-6);
  const int p = sc->projectile;
  ASSERT_EQ(p, m.n_grains - 1);
  EXPECT_NEAR(1 / m.grain_inv_mass[p], 0.005, 1e-12);
  EXPECT_DOUBLE_EQ(m.grain_radius[p], 0.004);
  EXPECT_NEAR((s.vel[p] - Vec3(0, 0, -50)).norm(), 0, 1e-12);
  // Lowest point 5 mm above the highest grain top on its path; horn 5 mm above the highest grain top.
  double path_top = -1, top = -1;
  for (int i = 0; i < p; ++i) {
    top = std::max(top, s.pos[i].z() + m.grain_radius[i]);
    if (std::hypot(s.pos[i].x(), s.pos[i].y()) < m.grain_radius[i] + 0.004)
      path_top = std::max(path_top, s.pos[i].z() + m.grain_radius[i]);
  }
  EXPECT_NEAR(s.pos[p].z() - 0.004 - path_top, 0.005, 1e-12);
  EXPECT_NEAR(sc->geometry.origin.z() - top, 0.005, 1e-12);
  const rt::BodyState& hb = s.bodies[sc->horn];
  EXPECT_NEAR((rt::reference_position(m.bodies[sc->horn], hb.pos, hb.q) - sc->geometry.origin).norm(), 0, 1e-12);
}

struct ShotResult {
  rt::Model m;
  rt::State s;
  rt::HornCount count;
  bool hit = false;
  int second = -1;         // the second projectile's grain, -1 if none
  double t_second = -1;    // when it was fired, s
};

// One shot of a loaded scene to its end, with the scene's observers.
ShotResult run_shot(std::unique_ptr<rt::SamplerScene> sc) {
  ShotResult out{sc->sc.model, sc->start};
  rt::test::SceneRunOutcome ran = rt::test::run_scene(*sc, out.m, out.s);
  const rt::RunReport& rep = ran.report;
  auto& sr = ran.run;
  EXPECT_EQ(rep.status, "ok") << rep.message;
  auto& r = static_cast<rt::SamplerRun&>(*sr);
  out.count = r.segments().now();
  out.hit = r.clock().hit();
  out.second = r.second().grain();
  out.t_second = r.second().t_fired();
  return out;
}

ShotResult shoot(int threads, const std::string& checkpoint = "") {
  omp_set_num_threads(threads);
  ShotResult r = run_shot(load());
  if (!checkpoint.empty()) rt::save_checkpoint(checkpoint, r.m, r.s);
  return r;
}

TEST(SamplerScene, ShortShotRecountAndThreads) {
  const std::string ck = ::testing::TempDir() + "/sampler_shot.ckpt";
  const ShotResult a = shoot(1, ck);
  EXPECT_TRUE(a.hit);
  long in_horn = 0;
  for (long c : a.count.count) in_horn += c;
  EXPECT_GT(in_horn, 0);  // ejecta reach the horn within 5 ms
  // Recount from the saved state with a fresh observer.
  auto sc = load();
  rt::Model m = sc->sc.model;
  const rt::State saved = rt::load_checkpoint(ck, m);
  rt::HornSegments recount(sc->geometry, sc->projectile, 1);
  recount.start(m, saved);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(recount.now().count[k], a.count.count[k]) << "cylinder " << k + 1;
    EXPECT_DOUBLE_EQ(recount.now().mass[k], a.count.mass[k]) << "cylinder " << k + 1;
  }
  // Same input, 2 threads: the same state bit for bit.
  const ShotResult b = shoot(2);
  ASSERT_EQ(a.s.pos.size(), b.s.pos.size());
  for (size_t i = 0; i < a.s.pos.size(); ++i) ASSERT_EQ(a.s.pos[i], b.s.pos[i]) << "grain " << i;
}

// The second projectile: added 1 ms after the first at the bottom of
// cylinder 4, it flies freely along the axis (exactly as the leapfrog moves a
// grain under gravity alone) and is counted in no horn segment: the counts
// are those of the same shot without it.
TEST(SamplerScene, SecondProjectile) {
  omp_set_num_threads(1);
  auto one = load({"sampler.duration=0.002"});
  const int n0 = one->sc.model.n_grains;
  const ShotResult a = run_shot(std::move(one));
  EXPECT_EQ(a.second, -1);
  auto two = load({"sampler.duration=0.002", "sampler.second_shot=true", "sampler.second_delay=0.001"});
  const rt::HornGeometry g = two->geometry;
  const Vec3 dir = two->direction;
  const ShotResult b = run_shot(std::move(two));
  const rt::Model& m2 = b.m;
  const int g2 = b.second;
  ASSERT_EQ(m2.n_grains, n0 + 1);
  ASSERT_EQ(g2, n0);
  EXPECT_LE(std::abs(b.t_second - 0.001), 0.5 * m2.dt + 1e-12) << "fired at the step end nearest the delay";
  EXPECT_DOUBLE_EQ(m2.grain_radius[g2], 0.004);
  EXPECT_NEAR(1 / m2.grain_inv_mass[g2], 0.005, 1e-12);
  // Free flight from the bottom of cylinder 4 (no contact on the way down).
  const Vec3 p0 = g.origin + g.axis * g.segment_z[3], v0 = dir * 50.0;
  const double T = b.s.time - b.t_second;
  const Vec3 expect = p0 + v0 * T + 0.5 * m2.gravity * T * T;
  EXPECT_LT((b.s.pos[g2] - expect).norm(), 1e-9);
  EXPECT_LT((b.s.vel[g2] - (v0 + m2.gravity * T)).norm(), 1e-9);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(b.count.count[k], a.count.count[k]) << "cylinder " << k + 1;
}

TEST(SamplerScene, BadInputIsRefused) {
  auto refused = [](const std::vector<std::string>& set, const std::string& key) {
    try {
      rt::load_scene(kShot, set, quiet_options());
      ADD_FAILURE() << "accepted " << set[0];
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused({"sampler.tilt_deg=40"}, "sampler.tilt_deg");
  refused({"sampler.offset=0.01"}, "sampler.offset");
  refused({"sampler.speed=-3"}, "sampler.speed");
  refused({"sampler.wobble=1"}, "wobble");
  refused({"sampler.horn=nothing"}, "sampler.horn");
  refused({"bodies.0.fixed=false"}, "fixed");
  refused({"sampler.projectile_material=lead"}, "sampler.projectile_material");
  refused({"sampler.second_delay=0"}, "sampler.second_delay");
  refused({"sampler.second_shot=maybe"}, "sampler.second_shot");
  // k_n and dt follow the shot speed: the file cannot also set them.
  refused({"contact.kn=1e7"}, "contact.kn");
  refused({"contact.dt=1e-7"}, "contact.dt");
}

TEST(SamplerScene, TheScheduleTakesTheShotSpeedUnlessGivenOne) {
  auto sc = load({"schedule.enabled=false"});
  EXPECT_DOUBLE_EQ(sc->sc.model.schedule.speed, 50.0);  // not contact.v_max (1 m/s)
  auto own = load({"schedule.speed=70"});
  EXPECT_DOUBLE_EQ(own->sc.model.schedule.speed, 70.0);
}

// --- horn geometry and collected mass -------------------------------------------------------

TEST(HornGeometry, ProfileIsTheUrdfs) {
  std::ifstream f("urdf/sampler_horn.urdf");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string text = ss.str();
  std::vector<std::array<double, 2>> pts;  // (z, r) in m, consecutive duplicates merged
  const std::regex line(R"(cylinder_\d: (.*))"), pair(R"(\(([0-9.]+), ([0-9.]+)\))");
  for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) {
    const std::string l = (*it)[1];
    for (std::sregex_iterator p(l.begin(), l.end(), pair); p != end; ++p) {
      const std::array<double, 2> q = {std::stod((*p)[1]) * 1e-3, 0.5 * std::stod((*p)[2]) * 1e-3};
      if (pts.empty() || std::abs(pts.back()[0] - q[0]) > 1e-12) pts.push_back(q);
    }
  }
  const rt::HornGeometry g = rt::HornGeometry::shipped();
  ASSERT_EQ(pts.size(), g.profile.size());
  for (size_t k = 0; k < pts.size(); ++k) {
    EXPECT_NEAR(pts[k][0], g.profile[k][0], 1e-12);
    EXPECT_NEAR(pts[k][1], g.profile[k][1], 1e-12);
  }
  EXPECT_NEAR(g.top(), 1.007, 1e-12);
  EXPECT_EQ(g.segment_of(Vec3(0, 0, 0.1)), 0);
  EXPECT_EQ(g.segment_of(Vec3(0.068, 0, 0.01)), 0);   // inside the 69 mm bottom radius
  EXPECT_EQ(g.segment_of(Vec3(0.070, 0, 0.01)), -1);  // outside the wall
  EXPECT_EQ(g.segment_of(Vec3(0, 0.02, 0.9)), 4);
  EXPECT_EQ(g.segment_of(Vec3(0, 0, 1.01)), -1);
  EXPECT_EQ(g.segment_of(Vec3(0, 0, -0.001)), -1);
}

TEST(HornSegments, GrainsLeavingThroughTheTopAreCollected) {
  rt::Model m;
  rt::Material mat;
  mat.name = "g";
  mat.density = 2430;
  m.materials = {mat};
  rt::HornGeometry g = rt::HornGeometry::shipped();
  g.origin = Vec3(0.1, -0.2, 0.05);
  rt::State s;
  const double r = 0.002;
  const double mass = 4.0 / 3.0 * kPi * r * r * r * 2430;
  std::vector<Vec3> pos = {Vec3(0, 0, 0.95), Vec3(0.01, 0, 1.0), Vec3(0, 0, 0.5), Vec3(0.2, 0, 1.1)};
  m.n_grains = int(pos.size());
  m.grain_radius.assign(pos.size(), r);
  m.grain_inv_mass.assign(pos.size(), 1 / mass);
  m.grain_hold.assign(pos.size(), 0);
  m.grain_material.assign(pos.size(), 0);
  for (Vec3& p : pos) p += g.origin;
  s.pos = pos;
  s.vel.assign(pos.size(), Vec3(0, 0, 1));
  rt::HornSegments h(g, -1, 1, 2.5 * mass);
  h.start(m, s);
  EXPECT_EQ(h.now().count[4], 2);
  EXPECT_EQ(h.now().count[2], 1);
  EXPECT_NEAR(h.collected_mass(), 2 * mass, 1e-15);
  // Grain 1 moves past the top inside the opening; grain 3 (outside the horn) stays out of it.
  s.pos[1].z() = g.origin.z() + 1.008;
  s.time = 0.1;
  std::vector<uint8_t> drop(m.n_grains, 0);
  EXPECT_TRUE(h.leaving(m, s, drop));
  EXPECT_EQ(drop, (std::vector<uint8_t>{0, 1, 0, 0}));
  EXPECT_EQ(h.now().top_count, 1);
  EXPECT_EQ(h.now().count[4], 1);
  EXPECT_NEAR(h.collected_mass(), 2 * mass, 1e-15);  // the left grain still counts
  EXPECT_LT(h.time_met(), 0);
  h.grains_removed({0, -1, 1, 2});
  // The grain in cylinder 3 rises into cylinder 5: 3 grains collected, the requirement (2.5 grains) met.
  m.n_grains = 3;
  s.pos = {pos[0], pos[2], pos[3]};
  s.pos[1].z() = g.origin.z() + 0.9;
  s.time = 0.2;
  drop.assign(3, 0);
  EXPECT_FALSE(h.leaving(m, s, drop));
  EXPECT_NEAR(h.collected_mass(), 3 * mass, 1e-15);
  EXPECT_DOUBLE_EQ(h.time_met(), 0.2);
}

// --- crater ---------------------------------------------------------------------------------

// Volume of sphere (c, r) in the cell by a fine midpoint grid, for comparison.
double grid_volume(const Vec3& c, double r, double z0, double z1, double r_in, double r_out) {
  const int n = 240;
  const double h = 2 * r / n;
  double v = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Vec3 p = c + Vec3(-r + (i + 0.5) * h, -r + (j + 0.5) * h, -r + (k + 0.5) * h);
        if ((p - c).squaredNorm() > r * r || p.z() < z0 || p.z() > z1) continue;
        const double d = std::hypot(p.x(), p.y());
        if (d >= r_in && d <= r_out) v += h * h * h;
      }
  return v;
}

TEST(Crater, CellVolumes) {
  const double r = 0.002, full = 4.0 / 3.0 * kPi * r * r * r;
  const Vec3 o = Vec3::Zero();
  EXPECT_NEAR(rt::sphere_cell_volume(Vec3(0, 0, 0), r, -1, 1, 0, 1, o), full, 1e-9 * full);
  EXPECT_NEAR(rt::sphere_cell_volume(Vec3(0.5, 0, 0.2), r, 0.2, 1, 0, 1, o), 0.5 * full, 1e-9 * full);
  EXPECT_EQ(rt::sphere_cell_volume(Vec3(0.5, 0, 0.2), r, 0.3, 1, 0, 1, o), 0.0);
  EXPECT_EQ(rt::sphere_cell_volume(Vec3(0.5, 0, 0.2), r, -1, 1, 0, 0.4, o), 0.0);
  // A partition of space into layers and rings adds up to the sphere.
  const Vec3 c(0.0013, 0.0007, 0.0004);
  double sum = 0;
  for (int k = -3; k < 3; ++k)
    for (int j = 0; j < 6; ++j) sum += rt::sphere_cell_volume(c, r, k * 1e-3, (k + 1) * 1e-3, j * 1e-3, (j + 1) * 1e-3, o);
  EXPECT_NEAR(sum, full, 1e-6 * full);
  // Cut by the axis column, a layer and an annulus: against a fine grid.
  EXPECT_NEAR(rt::sphere_cell_volume(c, r, 0, 1e-3, 0, 1e-3, o), grid_volume(c, r, 0, 1e-3, 0, 1e-3), 2e-3 * full);
  EXPECT_NEAR(rt::sphere_cell_volume(c, r, -1e-3, 1e-3, 1e-3, 2e-3, o), grid_volume(c, r, -1e-3, 1e-3, 1e-3, 2e-3),
              2e-3 * full);
}

TEST(Crater, DepthAndRadiusOfAHemisphericalHole) {
  // Simple cubic lattice of 0.5 mm grains (1 mm pitch) under z = 0; a
  // hemispherical hole of R = 20 mm is then dug at the origin.
  rt::Model m;
  rt::State s;
  const double r = 5e-4, R = 0.02;
  std::vector<Vec3> pos;
  for (int i = -30; i <= 30; ++i)
    for (int j = -30; j <= 30; ++j)
      for (int k = 0; k < 35; ++k) pos.push_back(Vec3(i * 1e-3, j * 1e-3, -(k + 0.5) * 1e-3));
  m.n_grains = int(pos.size());
  m.grain_radius.assign(pos.size(), r);
  m.grain_inv_mass.assign(pos.size(), 1.0);
  m.grain_hold.assign(pos.size(), 0);
  s.pos = pos;
  rt::Crater c(Vec3::Zero(), -1, 1, 0.5, 0.01, 1e-3, 0.03, 0.01, 0.028);
  c.start(m, s);
  EXPECT_NEAR(c.depth(), 0, 1e-12);
  EXPECT_NEAR(c.radius(), 0, 1e-12);
  for (Vec3& p : s.pos)
    if (p.norm() < R) p = Vec3(1, 1, 1);  // dug out
  c.finish(m, s);
  // Definitions: the column (10 mm radius) keeps >= 50 % where the hole's
  // radius sqrt(R^2 - d^2) <= 7.07 mm, i.e. d >= 18.7 mm; the top 10 mm ring
  // at rho keeps >= 50 % where sqrt(R^2 - rho^2) <= 5 mm, i.e. rho >= 19.4 mm.
  EXPECT_NEAR(c.depth(), std::sqrt(R * R - 0.5e-4), 1.5e-3);
  EXPECT_NEAR(c.radius(), std::sqrt(R * R - 0.25e-4), 1.5e-3);
}

}  // namespace
