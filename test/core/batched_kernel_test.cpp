// The batched grain–grain kernel (forces.cpp, used whenever no contact log
// is kept) must reproduce the one-pair-at-a-time kernel bit for bit: same
// springs, forces, overlaps and trajectories. One grain material (law
// constants shared by the whole block) or two (gathered per pair), walls,
// impacts, contacts that end and list rebuilds; linear and Hertz–Mindlin
// laws; without and with rolling and twisting resistance (with two
// materials, some pair types have rolling resistance only).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr int kGrains = 3000;

struct Scene {
  rt::Model m;
  rt::State s;
};

Scene make_scene(rt::ContactModel law, bool two_materials = true, bool resist = false) {
  Scene sc;
  rt::Model& m = sc.m;
  m.contact_model = law;
  rt::Material a = rt::test::simple_material("a", 2500, 0.5, 0.5, 0.5);
  rt::Material b = rt::test::simple_material("b", 2000, 0.3, 0.7, 0.3);
  rt::Material wall = rt::test::simple_material("wall", 2500, 0.6, 0.5, 0.4);
  wall.structure = true;
  for (rt::Material* mat : {&a, &b, &wall}) {
    mat->young = 1e7;
    mat->poisson = 0.25;
  }
  if (resist) {  // a–a and a–b pairs: rolling and twisting; b–b pairs: rolling only
    a.mu_r = 1.05;
    a.mu_t = 1.3;
    a.beta = 0.2;
    b.mu_r = 0.3;
    b.mu_t = 0;
    b.beta = 0.5;
  } else {
    for (rt::Material* mat : {&a, &b, &wall}) mat->mu_r = mat->mu_t = 0;
  }
  m.materials = {a, b, wall};
  const double L = 0.1;
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 2));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitX(), 2));
  m.walls.push_back(rt::make_plane(Vec3(L, 0, 0), -Vec3::UnitX(), 2));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitY(), 2));
  m.walls.push_back(rt::make_plane(Vec3(0, L, 0), -Vec3::UnitY(), 2));

  std::mt19937_64 rng(7);
  rt::RadiusDist d;
  d.mean = 0.003;
  d.sigma = 0.1;
  rt::Region box;
  box.lo = Vec3::Zero();
  box.hi = Vec3(L, L, 1.0);
  const std::vector<Vec3> sites = rt::lattice_sites(box, 2.0001 * d.max(), d.max(), 0.0, kGrains, rng);
  const std::vector<double> radii = rt::draw_radii(d, kGrains, rng);
  for (int i = 0; i < kGrains; ++i) rt::add_grain(m, radii[i], two_materials && i % 3 == 0 ? 1 : 0);
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(d.mean, 3) * a.density;
  m.kn = rt::kn_rule(m_p, 1.0, 0.01 * d.mean * (1 - d.sigma));
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  m.partitions = 4;
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  std::normal_distribution<double> v(0.0, 0.2);
  for (int i = 0; i < kGrains; ++i) {
    sc.s.pos[i] = sites[i];
    sc.s.vel[i] = Vec3(v(rng), v(rng), v(rng) - 1.0);
    sc.s.omega[i] = Vec3(v(rng), v(rng), v(rng)) * 50.0;
  }
  return sc;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Runs the scene with the batched and with the scalar kernel side by side and
// compares every evolving quantity after each block of steps.
void compare_kernels(rt::ContactModel law, bool two_materials, int steps, bool resist = false) {
  Scene batched = make_scene(law, two_materials, resist), scalar = make_scene(law, two_materials, resist);
  ASSERT_EQ(batched.m.any_resistance, resist);
  ASSERT_EQ(batched.m.single_grain_material, two_materials ? -1 : 0);
  scalar.s.scalar_kernel = true;
  long contacts = 0, capped = 0, rolling = 0, twisting = 0;
  for (int k = 1; k <= steps; ++k) {
    rt::step(batched.m, batched.s);
    rt::step(scalar.m, scalar.s);
    if (k % 250 != 0) continue;
    const std::string at = "after " + std::to_string(k) + " steps";
    ASSERT_TRUE(same_bits(batched.s.force, scalar.s.force)) << at << ": forces differ";
    ASSERT_TRUE(same_bits(batched.s.torque, scalar.s.torque)) << at << ": torques differ";
    ASSERT_TRUE(same_bits(batched.s.pos, scalar.s.pos)) << at << ": positions differ";
    ASSERT_TRUE(same_bits(batched.s.vel, scalar.s.vel)) << at << ": velocities differ";
    ASSERT_TRUE(same_bits(batched.s.omega, scalar.s.omega)) << at << ": spins differ";
    ASSERT_TRUE(same_bits(batched.s.pairs.partner, scalar.s.pairs.partner)) << at << ": pair lists differ";
    ASSERT_TRUE(same_bits(batched.s.pairs.spring_t, scalar.s.pairs.spring_t)) << at << ": springs differ";
    ASSERT_TRUE(same_bits(batched.s.pairs.spring_r, scalar.s.pairs.spring_r)) << at << ": rolling springs differ";
    ASSERT_TRUE(same_bits(batched.s.pairs.spring_w, scalar.s.pairs.spring_w)) << at << ": twisting springs differ";
    ASSERT_TRUE(same_bits(batched.s.pairs.touching, scalar.s.pairs.touching)) << at << ": contact flags differ";
    ASSERT_EQ(batched.s.stats.contacts, scalar.s.stats.contacts) << at;
    ASSERT_EQ(batched.s.stats.max_overlap_ratio, scalar.s.stats.max_overlap_ratio) << at;
    ASSERT_EQ(batched.s.stats.max_overlap_grain, scalar.s.stats.max_overlap_grain) << at;
    contacts += batched.s.stats.contacts;
    // Contacts with a live tangential spring.
    const rt::PairList& pl = batched.s.pairs;
    for (int e = 0; e < pl.size(); ++e) {
      capped += pl.touching[e] && pl.spring_t[e].squaredNorm() > 0;
      rolling += pl.touching[e] && pl.spring_r[e].squaredNorm() > 0;
      twisting += pl.touching[e] && pl.spring_w[e] != 0;
    }
  }
  EXPECT_GT(contacts, 1000) << "too few contacts to exercise the kernel";
  EXPECT_GT(capped, 100);
  if (resist) {
    EXPECT_GT(rolling, 100);
    EXPECT_GT(twisting, 100);
  }
  EXPECT_GT(batched.s.rebuilds, 5);
}

}  // namespace

TEST(BatchedKernel, LinearOneMaterialMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::Linear, false, 3000);
}

TEST(BatchedKernel, LinearTwoMaterialsMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::Linear, true, 3000);
}

TEST(BatchedKernel, HertzMindlinTwoMaterialsMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::HertzMindlin, true, 3000);
}

TEST(BatchedKernel, LinearResistanceOneMaterialMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::Linear, false, 3000, true);
}

TEST(BatchedKernel, LinearResistanceTwoMaterialsMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::Linear, true, 3000, true);
}

TEST(BatchedKernel, HertzMindlinResistanceTwoMaterialsMatchesScalarBitForBit) {
  compare_kernels(rt::ContactModel::HertzMindlin, true, 3000, true);
}

TEST(BatchedKernel, TwoThreadsMatchOneThread) {
  Scene one = make_scene(rt::ContactModel::Linear), two = make_scene(rt::ContactModel::Linear);
  ASSERT_GE(one.m.n_grains, one.m.parallel_min_grains);
  for (int k = 0; k < 1000; ++k) {
    omp_set_num_threads(1);
    rt::step(one.m, one.s);
    omp_set_num_threads(2);
    rt::step(two.m, two.s);
  }
  EXPECT_TRUE(same_bits(one.s.pos, two.s.pos));
  EXPECT_TRUE(same_bits(one.s.vel, two.s.vel));
  EXPECT_TRUE(same_bits(one.s.pairs.spring_t, two.s.pairs.spring_t));
}
