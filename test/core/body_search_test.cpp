// The grain–body candidate search (neighbours.cpp) visits only the grain
// cells around each body; its list must be the one a test of every grain
// against every body gives (same entries, same order, same sqrt(m*)), for
// bodies partly or wholly outside the bed, far-away grains, glued grains and
// immovable bodies, after a full list build and after a body-only rebuild.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "regolith_twin/core/neighbours.hpp"
#include "regolith_twin/core/walls.hpp"
#include "test_support.hpp"

namespace {

using rt::Quat;
using rt::Vec3;

struct Entry {
  int grain, body, shape;
  double sqrt_mstar;
  bool operator==(const Entry& o) const {
    return grain == o.grain && body == o.body && shape == o.shape && sqrt_mstar == o.sqrt_mstar;
  }
};

// Reference: every grain against every body, as the engine did before the
// cell search.
std::vector<Entry> brute_force(const rt::Model& m, const rt::State& s) {
  std::vector<Entry> out;
  const int nb = static_cast<int>(m.bodies.size());
  for (int i = 0; i < m.n_grains; ++i) {
    const double ri = m.grain_radius[i];
    for (int b = 0; b < nb; ++b) {
      const rt::BodyModel& bm = m.bodies[b];
      const rt::BodyState& bs = s.bodies[b];
      const double inv = m.grain_inv_mass[i] + bm.inv_mass();
      if (inv == 0) continue;
      const Vec3 d = s.pos[i] - bs.pos;
      const double reach = bm.bound_radius + ri + m.skin;
      if (d.squaredNorm() > reach * reach) continue;
      const Vec3 p = bs.q.conjugate() * d;
      for (int k = 0; k < static_cast<int>(bm.shapes.size()); ++k)
        if (rt::shape_gap(bm, bm.shapes[k], p, ri).overlap > -m.skin) out.push_back({i, b, k, std::sqrt(1.0 / inv)});
    }
  }
  return out;
}

std::vector<Entry> engine_list(const rt::State& s) {
  std::vector<Entry> out;
  const rt::BodyGrainList& l = s.body_grains;
  for (int k = 0; k < l.size(); ++k) out.push_back({l.grain[k], l.body[k], l.shape[k], l.sqrt_mstar[k]});
  return out;
}

rt::Shape shape(rt::ShapeType t, const Vec3& size, const Vec3& pos = Vec3::Zero(), const Quat& rot = Quat::Identity()) {
  rt::Shape s;
  s.type = t;
  s.size = size;
  s.pos = pos;
  s.rot = rot;
  return s;
}

rt::BodyModel body(const std::string& name, std::vector<rt::Shape> shapes, bool fixed) {
  rt::BodyModel b;
  b.name = name;
  b.mass = 2.0;
  b.inertia = Vec3(0.01, 0.02, 0.025);
  b.fixed = fixed;
  b.material = 1;
  b.shapes = std::move(shapes);
  return b;
}

Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0, 1);
  Quat q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q;
}

// A bed of n grains of varied radii in [0, 0.3] x [0, 0.3] x [0, 0.2] m, a
// few glued, a few ejected far away; four bodies of every grain shape type.
struct Scene {
  rt::Model m;
  rt::State s;
};

Scene make_scene(int n, std::mt19937_64& rng, double skin) {
  Scene sc;
  rt::Model& m = sc.m;
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5),
                 rt::test::simple_material("structure", 2430, 0.6, 0.6, 0.5)};
  m.materials[1].structure = true;
  m.kn = 1e5;
  m.dt = 1e-6;
  m.skin = skin;
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < n; ++i) rt::add_grain(m, 0.003 + 0.003 * u(rng), 0, u(rng) < 0.05);
  const Quat tilt(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()));
  m.bodies.push_back(body("box", {shape(rt::ShapeType::Box, Vec3(0.06, 0.04, 0.02))}, false));
  m.bodies.push_back(body("rover",
                          {shape(rt::ShapeType::Box, Vec3(0.05, 0.03, 0.01)),
                           shape(rt::ShapeType::Cylinder, Vec3(0.02, 0.02, 0.01), Vec3(0.05, 0.04, -0.01), tilt),
                           shape(rt::ShapeType::Sphere, Vec3::Constant(0.015), Vec3(-0.05, 0.03, -0.01))},
                          false));
  m.bodies.push_back(body("boulder", {shape(rt::ShapeType::Ellipsoid, Vec3(0.08, 0.05, 0.03))}, true));
  m.bodies.push_back(body("slab", {shape(rt::ShapeType::Box, Vec3(0.4, 0.4, 0.01))}, true));
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  for (int i = 0; i < n; ++i) {
    sc.s.pos[i] = Vec3(0.3 * u(rng), 0.3 * u(rng), 0.2 * u(rng));
    if (u(rng) < 0.01) sc.s.pos[i] += Vec3(40 * (u(rng) - 0.5), 40 * (u(rng) - 0.5), 100 * u(rng));  // ejecta
  }
  return sc;
}

// A pose near the bed: inside, across its faces, or well outside; now and
// then beside an ejected grain.
void place_bodies(Scene& sc, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  for (size_t b = 0; b < sc.m.bodies.size(); ++b) {
    rt::BodyState& bs = sc.s.bodies[b];
    if (u(rng) < 0.1) {
      const int i = int(u(rng) * sc.m.n_grains);
      bs.pos = sc.s.pos[i] + 0.05 * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    } else {
      bs.pos = Vec3(-0.15 + 0.6 * u(rng), -0.15 + 0.6 * u(rng), -0.1 + 0.4 * u(rng));
    }
    bs.q = random_rotation(rng);
  }
}

TEST(BodySearch, CellSearchGivesTheBruteForceList) {
  std::mt19937_64 rng(17);
  long entries = 0, outside = 0;
  for (int round = 0; round < 6; ++round) {
    Scene sc = make_scene(round % 2 ? 3000 : 1200, rng, round < 3 ? 0.0 : 0.004 * (round - 1));
    for (int trial = 0; trial < 40; ++trial) {
      place_bodies(sc, rng);
      rt::build_neighbour_lists(sc.m, sc.s);  // cells of the current positions
      const std::vector<Entry> ref = brute_force(sc.m, sc.s);
      EXPECT_EQ(engine_list(sc.s), ref) << "full build, round " << round << " trial " << trial;
      entries += long(ref.size());
      // Bodies and grains move; the body list alone is rebuilt.
      std::normal_distribution<double> g(0, 0.002);
      for (Vec3& p : sc.s.pos) p += Vec3(g(rng), g(rng), g(rng));
      place_bodies(sc, rng);
      for (const rt::BodyState& bs : sc.s.bodies) outside += bs.pos.minCoeff() < 0 || bs.pos.x() > 0.3 || bs.pos.y() > 0.3;
      rt::build_body_list(sc.m, sc.s);
      EXPECT_EQ(engine_list(sc.s), brute_force(sc.m, sc.s)) << "body-only build, round " << round << " trial " << trial;
    }
  }
  EXPECT_GT(entries, 10000);
  EXPECT_GT(outside, 100);
}

TEST(BodySearch, NoGrainsAndAllFarAway) {
  std::mt19937_64 rng(3);
  Scene sc = make_scene(0, rng, 0.003);
  place_bodies(sc, rng);
  rt::build_neighbour_lists(sc.m, sc.s);
  EXPECT_EQ(sc.s.body_grains.size(), 0);
  // Two grains 1 km apart, each touched by a body.
  Scene two = make_scene(2, rng, 0.003);
  two.s.pos[0] = Vec3(0, 0, 0);
  two.s.pos[1] = Vec3(1000, -1000, 500);
  two.m.grain_hold.assign(2, 0);
  two.m.grain_inv_mass.assign(2, 1.0);
  two.s.bodies[0].pos = two.s.pos[1] + Vec3(0, 0, 0.02);
  two.s.bodies[1].pos = two.s.pos[0] - Vec3(0, 0, 0.01);
  two.s.bodies[2].pos = Vec3(500, -500, 250);
  two.s.bodies[3].pos = Vec3(-1e6, 0, 0);
  rt::build_neighbour_lists(two.m, two.s);
  const std::vector<Entry> ref = brute_force(two.m, two.s);
  EXPECT_EQ(engine_list(two.s), ref);
  EXPECT_GE(ref.size(), 2u);
  rt::build_body_list(two.m, two.s);
  EXPECT_EQ(engine_list(two.s), ref);
}

// Build times on a bed of about 60 000 grains with one lander-sized body, and
// with 32 small boulders on its surface (reported, not checked): run with
// --gtest_also_run_disabled_tests.
void time_bed(int n_bodies) {
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5),
                 rt::test::simple_material("structure", 2430, 0.6, 0.6, 0.5)};
  m.materials[1].structure = true;
  m.kn = 1e5;
  m.dt = 1e-6;
  const int side = 39;  // 39 x 39 x 40 = 60 840 grains on a lattice of spacing 2.1 r
  const double r = 0.005, a = 2.1 * r;
  for (int k = 0; k < side * side * 40; ++k) rt::add_grain(m, r, 0);
  if (n_bodies == 1)
    m.bodies.push_back(body("lander", {shape(rt::ShapeType::Box, Vec3(0.145, 0.1375, 0.0975))}, false));
  else
    for (int b = 0; b < n_bodies; ++b)
      m.bodies.push_back(body("boulder", {shape(rt::ShapeType::Ellipsoid, Vec3(0.02, 0.015, 0.01))}, false));
  rt::Model bare = m;
  bare.bodies.clear();
  rt::finalize_model(m);
  rt::finalize_model(bare);
  rt::State s = rt::make_state(m), sb = rt::make_state(bare);
  int k = 0;
  for (int z = 0; z < 40; ++z)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) s.pos[k++] = Vec3(x * a, y * a, z * a);
  sb.pos = s.pos;
  const double top = 39 * a + r;
  if (n_bodies == 1) {
    s.bodies[0].pos = Vec3(side * a / 2, side * a / 2, top + 0.0975 - 0.002);  // pressed into the bed's top
    s.bodies[0].q = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  } else {
    for (int b = 0; b < n_bodies; ++b)
      s.bodies[b].pos = Vec3((0.5 + b % 8) * side * a / 8, (0.5 + b / 8) * side * a / 4, top + 0.008);
  }
  using Clock = std::chrono::steady_clock;
  auto best_of = [](int reps, auto&& f) {
    double best = 1e30;
    for (int r = 0; r < reps; ++r) {
      const auto t0 = Clock::now();
      f();
      best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    return best;
  };
  size_t n_ref = 0;
  const double t_ref = best_of(30, [&] { n_ref = brute_force(m, s).size(); });
  const double t_body = best_of(30, [&] { rt::build_body_list(m, s); });
  const double t_full = best_of(15, [&] { rt::build_neighbour_lists(m, s); });
  const double t_bare = best_of(15, [&] { rt::build_neighbour_lists(bare, sb); });
  EXPECT_EQ(engine_list(s), brute_force(m, s));
  std::printf("%d grains, %d bodies, %zu grain-body entries (best of 15-30 runs)\n", m.n_grains, n_bodies, n_ref);
  std::printf("  every grain against every body (the former search): %.3f ms\n", t_ref);
  std::printf("  build_body_list (bin again, cell search, carry, partition): %.3f ms\n", t_body);
  std::printf("  build_neighbour_lists with the bodies %.3f ms, without %.3f ms (difference %.3f ms)\n", t_full, t_bare,
              t_full - t_bare);
}

TEST(BodySearch, DISABLED_Timing60k) {
  time_bed(1);
  time_bed(32);
}

}  // namespace
