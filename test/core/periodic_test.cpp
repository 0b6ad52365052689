// Periodic boundaries (docs/model.md §11): a contact across the boundary and
// a grain crossing it while in contact give the same forces and springs as
// the same pair in open space; momentum is conserved in a periodic box;
// results are bit-identical for any thread count and for either kernel; the
// glued base is imaged; bad boxes are refused.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/step.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDensity = 2500;
constexpr double kR = 1e-3;   // grain radius, m
constexpr double kL = 10e-3;  // box length, m

double grain_mass(double r) { return 4.0 / 3.0 * kPi * r * r * r * kDensity; }

// A model of `n` grains of radius kR (material 0: eps_n, eps_t, mu), no
// gravity; periodic in x and y over [0, kL) when `periodic`.
rt::Model grains(int n, bool periodic, double eps = 0.9, double mu = 0.5) {
  rt::Model m;
  m.materials.push_back(rt::test::simple_material("grain", kDensity, eps, eps, mu));
  m.gravity.setZero();
  for (int i = 0; i < n; ++i) rt::add_grain(m, kR, 0);
  m.kn = 2.0;  // a contact of ~5 ms between two grains
  m.dt = rt::dt_rule(grain_mass(kR), m.kn, 50);
  m.skin = 0.5e-3;
  if (periodic) {
    m.periodic.x = m.periodic.y = true;
    m.periodic.length = Vec3(kL, kL, 0);
  }
  return m;
}

// Grains i and j touch across the x boundary (the contact point at x = 0),
// move together along y across the y boundary during the contact, approach
// along x and slide along z: the pair's springs cross both boundaries. In
// open space the same pair sits at x = -0.999 mm and +0.999 mm.
struct Pair {
  rt::Model m;
  rt::State s;
};

Pair crossing_pair(bool periodic) {
  Pair p;
  p.m = grains(2, periodic);
  rt::finalize_model(p.m);
  p.s = rt::make_state(p.m);
  const double xi = periodic ? kL - 0.999e-3 : -0.999e-3;
  p.s.pos[0] = Vec3(xi, kL - 0.5e-3, 5e-3);
  p.s.pos[1] = Vec3(0.999e-3, kL - 0.5e-3, 5e-3);
  p.s.vel[0] = Vec3(0.01, 1.0, 0.05);
  p.s.vel[1] = Vec3(-0.01, 1.0, -0.05);
  return p;
}

double relative(const Vec3& a, const Vec3& b) { return (a - b).norm() / std::max(b.norm(), 1e-300); }

TEST(Periodic, ContactAcrossTheBoundaryKeepsItsSpringsAndForces) {
  Pair open = crossing_pair(false), box = crossing_pair(true);
  const int steps = 30;  // the contact lasts 37 steps
  int wraps = 0;
  double worst_force = 0, worst_spring = 0, worst_vel = 0;
  double last_y = box.s.pos[0].y();
  for (int k = 0; k < steps; ++k) {
    rt::step(open.m, open.s);
    rt::step(box.m, box.s);
    ASSERT_EQ(open.s.pairs.size(), 1);
    ASSERT_EQ(box.s.pairs.size(), 1);
    ASSERT_TRUE(open.s.pairs.touching[0]) << "step " << k;
    ASSERT_TRUE(box.s.pairs.touching[0]) << "step " << k;
    ASSERT_NE(box.s.pairs.image[0], 0);  // the partner is always an image across x
    worst_force = std::max(worst_force, relative(box.s.force[0], open.s.force[0]));
    worst_spring = std::max(worst_spring, relative(box.s.pairs.spring_t[0], open.s.pairs.spring_t[0]));
    worst_vel = std::max(worst_vel, relative(box.s.vel[1] - box.s.vel[0], open.s.vel[1] - open.s.vel[0]));
    if (box.s.pos[0].y() < last_y) ++wraps;
    last_y = box.s.pos[0].y();
    // Wrapped at the list builds: outside the box by less than the drift between builds.
    for (int i = 0; i < 2; ++i)
      for (int a = 0; a < 2; ++a) {
        EXPECT_GT(box.s.pos[i][a], -box.m.skin);
        EXPECT_LT(box.s.pos[i][a], kL + box.m.skin);
      }
  }
  EXPECT_EQ(wraps, 1);  // crossed y = L once while in contact
  EXPECT_GT(open.s.pairs.spring_t[0].norm(), 1e-7);  // a spring worth keeping
  // The box's separations are formed from wrapped coordinates: rounding only.
  EXPECT_LT(worst_force, 1e-9);
  EXPECT_LT(worst_spring, 1e-9);
  EXPECT_LT(worst_vel, 1e-9);
}

// A periodic box of grains at random (no walls, no gravity): in x and y the
// box closes, z is open.
struct Box {
  rt::Model m;
  rt::State s;
};

Box random_box(int n, double eps, double mu, uint64_t seed) {
  Box b;
  b.m = grains(n, true, eps, mu);
  b.m.kn = 200;
  b.m.dt = rt::dt_rule(grain_mass(kR), b.m.kn, 50);
  b.m.parallel_min_grains = 0;  // parallel whatever the size
  rt::finalize_model(b.m);
  b.s = rt::make_state(b.m);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1), v(-0.05, 0.05);
  // A loose lattice of 4 x 4 x n/16 sites (spacing 2.5 mm), jittered.
  for (int i = 0; i < n; ++i) {
    const int ix = i % 4, iy = (i / 4) % 4, iz = i / 16;
    b.s.pos[i] = Vec3((ix + 0.5) * 2.5e-3 + 0.2e-3 * (u(rng) - 0.5), (iy + 0.5) * 2.5e-3 + 0.2e-3 * (u(rng) - 0.5),
                      iz * 2.1e-3);
    b.s.vel[i] = Vec3(v(rng), v(rng), v(rng));
  }
  return b;
}

TEST(Periodic, BoxConservesMomentum) {
  Box b = random_box(64, 1.0, 0.5, 3);
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (int i = 0; i < b.m.n_grains; ++i) p += b.m.grain_mass[i] * b.s.vel[i];
    return p;
  };
  double scale = 0;
  for (int i = 0; i < b.m.n_grains; ++i) scale += b.m.grain_mass[i] * b.s.vel[i].norm();
  const Vec3 p0 = momentum();
  long contacts = 0, cross = 0;
  for (int k = 0; k < 4000; ++k) {
    rt::step(b.m, b.s);
    contacts += b.s.stats.contacts;
    for (int q = 0; q < b.s.pairs.size(); ++q) cross += b.s.pairs.touching[q] && b.s.pairs.image[q] != 0;
  }
  EXPECT_GT(contacts, 1000);  // they collide
  EXPECT_GT(cross, 100);      // also across the boundaries
  EXPECT_LT((momentum() - p0).norm(), 1e-12 * scale);
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

TEST(Periodic, BitIdenticalForAnyThreadCountAndKernel) {
  std::vector<rt::Vec3> ref_pos, ref_vel;
  for (int run = 0; run < 3; ++run) {
    Box b = random_box(96, 0.8, 0.5, 5);
    if (run == 2) b.s.scalar_kernel = true;
    const int threads = run == 1 ? 2 : 1;
    const int before = omp_get_max_threads();
    omp_set_num_threads(threads);
    for (int k = 0; k < 3000; ++k) rt::step(b.m, b.s);
    omp_set_num_threads(before);
    if (run == 0) {
      ref_pos = b.s.pos;
      ref_vel = b.s.vel;
    } else {
      EXPECT_TRUE(same_bits(b.s.pos, ref_pos)) << "run " << run;
      EXPECT_TRUE(same_bits(b.s.vel, ref_vel)) << "run " << run;
    }
  }
}

TEST(Periodic, GluedGrainsAreImaged) {
  rt::Model m = grains(2, true);
  m.grain_hold[0] = 1;
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(kL - 0.9e-3, 5e-3, 1e-3);  // glued, by the x = L side
  s.pos[1] = Vec3(0.9e-3, 5e-3, 1e-3);       // free, 1.8 mm away through the boundary
  rt::step(m, s);
  EXPECT_GT(s.force[1].x(), 0);  // pushed away from the glued grain's image
  EXPECT_EQ(s.vel[0], Vec3::Zero());
}

TEST(Periodic, BadBoxesAreRefused) {
  auto refused = [](rt::Model m, const std::string& what) {
    try {
      rt::finalize_model(m);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  rt::Model m = grains(2, true);
  m.periodic.length.x() = 2 * (2 * kR + m.skin) * 0.99;
  refused(m, "at least");
  m = grains(2, true);
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitX(), 0));
  refused(m, "cuts a periodic direction");
  m = grains(2, true);
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 0));  // a floor is fine
  EXPECT_NO_THROW(rt::finalize_model(m));
  m = grains(2, true);
  m.sleep.enabled = true;
  refused(m, "sleep");
}

}  // namespace
