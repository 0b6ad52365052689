// Free flight (docs/model.md §18): grains with nothing within the skin at a
// list build get a reach and leave the skin test of the rebuild. Checked
// against a brute-force search at every step (no touching pair, wall or body
// contact is ever missing from the lists), against the exact ballistic
// trajectory, for fewer rebuilds, for the same result as with free flight off,
// for any thread count and across a resume.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "regolith_twin/core/neighbours.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::Quat;
using rt::Vec3;

constexpr double kL = 0.1;  // box side, m

struct Scene {
  rt::Model m;
  rt::State s;
};

rt::Shape shape(rt::ShapeType t, const Vec3& size) {
  rt::Shape s;
  s.type = t;
  s.size = size;
  return s;
}

// A box with a floor and four side walls; 250 grains at rest in its lower
// part and 150 fast ejecta (up to 4 m/s, any direction) spread over the
// space above (about 2.5 cm apart, as a plume thins out);
// a free box body falling into the spray and a fixed ball standing in it.
Scene spray(bool free_flight, bool bed_and_drop = true) {
  Scene sc;
  rt::Model& m = sc.m;
  rt::test::grain_and_wall_in_open_box(m, kL);
  rt::BodyModel box;
  box.name = "box";
  box.mass = 0.05;
  box.inertia = Vec3(2e-5, 2e-5, 2e-5);
  box.material = 1;
  box.shapes = {shape(rt::ShapeType::Box, Vec3(0.015, 0.01, 0.008))};
  rt::BodyModel ball = box;
  ball.name = "ball";
  ball.fixed = true;
  ball.shapes = {shape(rt::ShapeType::Sphere, Vec3::Constant(0.012))};
  m.bodies = {box, ball};
  std::mt19937_64 rng(11);
  rt::RadiusDist d;
  d.mean = 0.0025;
  d.sigma = 0.1;
  rt::Region low;
  low.lo = Vec3::Zero();
  low.hi = Vec3(kL, kL, 0.03);
  std::vector<Vec3> sites = rt::lattice_sites(low, 2.2 * d.max(), d.max(), 0.0, 250, rng);
  if (!bed_and_drop) sites.clear();
  rt::Region high;
  high.lo = Vec3(0, 0, 0.05);
  high.hi = Vec3(kL, kL, 0.5);
  std::vector<Vec3> up = rt::lattice_sites(high, 0.025, 0.012, 0.003, 100000, rng);
  std::shuffle(up.begin(), up.end(), rng);
  const Vec3 box_at(0.05, 0.05, 0.12), ball_at(0.07, 0.03, 0.2);
  const size_t bed = sites.size();
  for (const Vec3& p : up) {
    if (sites.size() == bed + 150) break;
    if ((p - box_at).norm() < 0.03 || (p - ball_at).norm() < 0.02) continue;
    sites.push_back(p);
  }
  const int n = int(sites.size());
  const std::vector<double> radii = rt::draw_radii(d, n, rng);
  for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0);
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(d.mean, 3) * 2430;
  m.kn = rt::kn_rule(m_p, 6.0, 0.05 * d.mean);
  m.dt = rt::dt_rule(m_p, m.kn, 20);
  m.skin = 0.2 * d.mean;
  m.free_flight.enabled = free_flight;
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i) {
    sc.s.pos[i] = sites[i];
    if (i >= int(bed)) {
      Vec3 v;
      do v = Vec3(u(rng), u(rng), u(rng));
      while (v.norm() > 1 || v.norm() < 0.2);
      sc.s.vel[i] = 4.0 * v;
    }
  }
  sc.s.bodies[0].pos = box_at;
  if (bed_and_drop) sc.s.bodies[0].vel = Vec3(0.3, 0, -1.5);
  sc.s.bodies[0].q = Quat(Eigen::AngleAxisd(0.5, Vec3(1, 1, 0).normalized()));
  sc.s.bodies[1].pos = ball_at;
  return sc;
}

// Every touching grain pair, grain–wall and grain–body contact is in the lists.
void expect_lists_complete(const rt::Model& m, const rt::State& s, long step) {
  std::set<std::pair<int, int>> listed;
  for (int i = 0; i < m.n_grains; ++i)
    for (int k = s.pairs.row_start[i]; k < s.pairs.row_start[i + 1]; ++k) listed.insert({i, s.pairs.partner[k]});
  for (int i = 0; i < m.n_grains; ++i)
    for (int j = i + 1; j < m.n_grains; ++j)
      if ((s.pos[i] - s.pos[j]).norm() < m.grain_radius[i] + m.grain_radius[j])
        ASSERT_TRUE(listed.count({i, j})) << "grains " << i << " and " << j << " touch unlisted at step " << step;
  std::set<std::pair<int, int>> walls;
  for (int k = 0; k < s.wall_pairs.size(); ++k) walls.insert({s.wall_pairs.grain[k], s.wall_pairs.wall[k]});
  for (int i = 0; i < m.n_grains; ++i)
    for (int w = 0; w < int(m.walls.size()); ++w)
      if (rt::wall_gap(m.walls[w], s.pos[i], m.grain_radius[i]).overlap > 0)
        ASSERT_TRUE(walls.count({i, w})) << "grain " << i << " touches wall " << w << " unlisted at step " << step;
  std::set<std::pair<int, int>> bodies;
  for (int k = 0; k < s.body_grains.size(); ++k) bodies.insert({s.body_grains.grain[k], s.body_grains.body[k]});
  for (int b = 0; b < int(m.bodies.size()); ++b) {
    const rt::BodyState& bs = s.bodies[b];
    for (int i = 0; i < m.n_grains; ++i)
      for (const rt::Shape& sh : m.bodies[b].shapes)
        if (rt::shape_gap(m.bodies[b], sh, bs.q.conjugate() * (s.pos[i] - bs.pos), m.grain_radius[i]).overlap > 0)
          ASSERT_TRUE(bodies.count({i, b})) << "grain " << i << " touches body " << b << " unlisted at step " << step;
  }
}

constexpr int kSteps = 4000;

TEST(FreeFlight, NoContactIsMissedAndRebuildsAreFewer) {
  Scene on = spray(true), off = spray(false);
  long free_seen = 0, body_contacts = 0, wall_contacts = 0;
  for (int k = 0; k < kSteps; ++k) {
    rt::step(on.m, on.s);
    rt::step(off.m, off.s);
    expect_lists_complete(on.m, on.s, on.s.step);
    if (HasFatalFailure()) return;
    free_seen = std::max(free_seen, on.s.free_grains);
    body_contacts += on.s.stats.body_contacts;
    wall_contacts += on.s.stats.wall_contacts;
  }
  // The scene does what it is meant to: ejecta in flight, hitting walls and bodies.
  EXPECT_GE(free_seen, 100);
  EXPECT_GT(body_contacts, 0);
  EXPECT_GT(wall_contacts, 0);
  // Ejecta that hit the bed, the walls or the box are within the skin of
  // something at most builds, and their speed then sets the rebuilds as before.
  std::printf("rebuilds: free flight on %ld, off %ld; grains in free flight at most %ld\n", on.s.rebuilds,
              off.s.rebuilds, on.s.free_grains_max);
  EXPECT_LE(on.s.rebuilds, off.s.rebuilds);
  // The same contacts are evaluated; only the list's non-touching entries and
  // the rebuild steps differ, so the results agree to rounding.
  double dmax = 0;
  for (int i = 0; i < on.m.n_grains; ++i) dmax = std::max(dmax, (on.s.pos[i] - off.s.pos[i]).norm());
  std::printf("largest position difference on/off: %.3g m\n", dmax);
  EXPECT_LT(dmax, 1e-9);
}

// Ejecta alone in flight, about 2.5 cm apart: the rebuilds follow the gaps
// between them (the reach) instead of the skin. In 1,000 steps the fastest
// grain moves 9 mm: 36 rebuilds at half the 0.5 mm skin; with reaches of
// 6-13 mm (shrinking as grains near the walls, where they fall back to the
// skin test) a few.
TEST(FreeFlight, RebuildsFollowTheReachInFlight) {
  Scene on = spray(true, false), off = spray(false, false);
  for (int k = 0; k < 1000; ++k) {
    rt::step(on.m, on.s);
    rt::step(off.m, off.s);
    expect_lists_complete(on.m, on.s, on.s.step);
    if (HasFatalFailure()) return;
  }
  std::printf("in flight: rebuilds with free flight %ld, without %ld\n", on.s.rebuilds, off.s.rebuilds);
  EXPECT_LT(3 * on.s.rebuilds, off.s.rebuilds);
  for (int i = 0; i < on.m.n_grains; ++i) ASSERT_EQ(on.s.pos[i], off.s.pos[i]) << "grain " << i;
}

// The bound is tight: two grains flying head-on at each other close their
// gap at exactly the rate the test allows for, so the list must be rebuilt
// by the step they first touch (and not earlier than the gap allows).
TEST(FreeFlight, AHeadOnPairIsListedByTheStepItTouches) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5)};
  m.gravity = Vec3::Zero();
  const double r = 0.002;
  rt::add_grain(m, r, 0);
  rt::add_grain(m, r, 0);
  const double m_p = 4.0 / 3.0 * M_PI * r * r * r * 2430;
  m.kn = rt::kn_rule(m_p, 2.0, 0.05 * r);
  m.dt = rt::dt_rule(m_p, m.kn, 20);
  m.skin = 0.1 * r;
  m.free_flight.enabled = true;
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0, 0, 0);
  s.pos[1] = Vec3(12 * r, 0.3 * r, 0);  // gap about 10 r: 100 skins
  s.vel[0] = Vec3(1, 0, 0);
  s.vel[1] = Vec3(-1, 0, 0);
  long first_touch = -1;
  for (int k = 0; k < 20000 && s.vel[0].x() > 0; ++k) {
    rt::step(m, s);
    const bool touch = (s.pos[1] - s.pos[0]).norm() < 2 * r;
    if (touch && first_touch < 0) first_touch = s.step;
    if (touch) ASSERT_EQ(s.pairs.size(), 1) << "touching but unlisted at step " << s.step;
  }
  ASSERT_GT(first_touch, 0);
  EXPECT_LT(s.rebuilds, 10);  // the skin test alone: about 100 rebuilds before the touch (5 r at skin / 2)
  EXPECT_LT(s.vel[0].x(), 0);  // they bounced
}

TEST(FreeFlight, AGrainInFlightFollowsTheParabola) {
  Scene sc = spray(true, false);
  rt::Model& m = sc.m;
  rt::State& s = sc.s;
  // The ejecta's first flight: those that touch nothing for 1,000 steps.
  const std::vector<Vec3> x0 = s.pos, v0 = s.vel;
  std::vector<int> clean(m.n_grains, 1);
  for (int k = 0; k < 1000; ++k) {
    rt::step(m, s);
    for (int i = 0; i < m.n_grains; ++i)
      if (s.force[i].squaredNorm() > 0) clean[i] = 0;
  }
  const double t = s.time;
  int checked = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (!clean[i]) continue;
    const Vec3 exact = x0[i] + v0[i] * t + 0.5 * m.gravity * t * t;
    EXPECT_LT((s.pos[i] - exact).norm(), 1e-12) << "grain " << i;
    EXPECT_LT((s.vel[i] - (v0[i] + m.gravity * t)).norm(), 1e-12) << "grain " << i;
    ++checked;
  }
  EXPECT_GE(checked, 50);
}

TEST(FreeFlight, SameResultForAnyThreadCountAndAcrossAResume) {
  auto run = [](int threads, int steps) {
    Scene sc = spray(true);
    sc.m.parallel_min_grains = 1;  // the threaded loops run even on this small scene
    omp_set_num_threads(threads);
    for (int k = 0; k < steps; ++k) rt::step(sc.m, sc.s);
    return sc;
  };
  const Scene one = run(1, 2000), two = run(2, 2000);
  omp_set_num_threads(2);
  for (int i = 0; i < one.m.n_grains; ++i) ASSERT_EQ(one.s.pos[i], two.s.pos[i]) << "grain " << i;
  ASSERT_EQ(one.s.rebuilds, two.s.rebuilds);
  // Resume: the reaches and the body poses of the last build come back, so
  // the rebuilds (and every rounding) fall on the same steps.
  Scene a = run(2, 1000);
  const std::string path = "/tmp/free_flight_test_" + std::to_string(::getpid()) + ".ckpt";
  rt::save_checkpoint(path, a.m, a.s);
  rt::State b = rt::load_checkpoint(path, a.m);
  std::remove(path.c_str());
  EXPECT_EQ(b.reach, a.s.reach);
  for (int k = 0; k < 1000; ++k) {
    rt::step(a.m, a.s);
    rt::step(a.m, b);
  }
  for (int i = 0; i < a.m.n_grains; ++i) ASSERT_EQ(a.s.pos[i], b.pos[i]) << "grain " << i;
  EXPECT_EQ(a.s.rebuilds, b.rebuilds);
  EXPECT_EQ(a.s.pos, two.s.pos);
}

}  // namespace
