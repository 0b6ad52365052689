// The step allocates no memory once its buffers are sized (state.hpp): after a
// warm-up, thousands of steps of a flowing scene, neighbour-list rebuilds
// included, make no call to operator new. This binary replaces the global
// operator new/delete to count calls.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/scene/generate.hpp"
#include "regolith_twin/scene/scenario.hpp"
#include "test_support.hpp"

namespace {

std::atomic<long> g_allocations{0};

void* counted_alloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}

void* counted_aligned_alloc(std::size_t n, std::align_val_t al) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = std::max(static_cast<std::size_t>(al), sizeof(void*));
  void* p = nullptr;
  if (posix_memalign(&p, a, n ? n : 1) == 0) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t al) { return counted_aligned_alloc(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return counted_aligned_alloc(n, al); }
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  try {
    return counted_aligned_alloc(n, al);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  try {
    return counted_aligned_alloc(n, al);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

namespace {

using rt::Vec3;

// 2000 'moderate' grains (rolling and twisting resistance on) thrown down at
// 1 m/s from a lattice into a cylinder under gravity tilted by 30 degrees: a
// compacting, rebounding, sliding bed with grain and wall contacts.
struct Scene {
  rt::Model m;
  rt::State s;
};

Scene make_scene(int parallel_min_grains) {
  Scene sc;
  rt::Model& m = sc.m;
  rt::Material grain;
  EXPECT_TRUE(rt::material_preset("moderate", grain));
  m.materials.push_back(grain);
  rt::Material wall = grain;
  wall.name = "wall";
  wall.structure = true;
  m.materials.push_back(wall);
  const double R = 0.05;
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.walls.push_back(rt::make_cylinder(Vec3::Zero(), Vec3::UnitZ(), R, 0.3, true, 1));
  m.gravity = 9.81 * Vec3(std::sin(0.5236), 0, -std::cos(0.5236));
  std::mt19937_64 rng(5);
  rt::RadiusDist d;
  d.mean = 0.003;
  d.sigma = 0.1;
  rt::Region cyl;
  cyl.shape = rt::RegionShape::Cylinder;
  cyl.center = Vec3::Zero();
  cyl.radius = R;
  cyl.lo = Vec3(-R, -R, 0);
  cyl.hi = Vec3(R, R, 0.3);
  const int n = 2000;
  const std::vector<Vec3> sites = rt::lattice_sites(cyl, 2.02 * d.max(), d.max(), 0.0, n, rng);
  EXPECT_EQ(int(sites.size()), n);
  const std::vector<double> radii = rt::draw_radii(d, n, rng);
  for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0);
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(d.mean, 3) * grain.density;
  m.kn = rt::kn_rule(m_p, 1.0, 0.01 * d.mean * (1 - d.sigma));
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  m.parallel_min_grains = parallel_min_grains;
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  std::normal_distribution<double> v(0.0, 0.1);
  for (int i = 0; i < n; ++i) {
    sc.s.pos[i] = sites[i];
    sc.s.vel[i] = Vec3(v(rng), v(rng), v(rng) - 1.0);
  }
  return sc;
}

void expect_steps_allocate_nothing(int threads, int parallel_min_grains) {
  omp_set_num_threads(threads);
  Scene sc = make_scene(parallel_min_grains);
  for (int k = 0; k < 300; ++k) rt::step(sc.m, sc.s);  // warm-up (thread pool, first lists)
  constexpr int kWindow = 5000;
  const long rebuilds0 = sc.s.rebuilds;
  long contacts = 0, wall_contacts = 0;
  const long before = g_allocations.load();
  for (int k = 0; k < kWindow; ++k) {
    rt::step(sc.m, sc.s);
    contacts += sc.s.stats.contacts;
    wall_contacts += sc.s.stats.wall_contacts;
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_EQ(allocations, 0) << "operator new called during " << threads << "-thread steps";
  // The window covered list rebuilds and a contact-rich flow.
  EXPECT_GE(sc.s.rebuilds - rebuilds0, 5);
  EXPECT_GT(contacts / kWindow, 100);  // mean live contacts per step
  EXPECT_GT(wall_contacts / kWindow, 15);
}

}  // namespace

TEST(Allocation, CounterSeesOperatorNew) {
  const long before = g_allocations.load();
  std::vector<double>* v = new std::vector<double>(100);
  delete v;
  EXPECT_EQ(g_allocations.load() - before, 2);
}

TEST(Allocation, SerialStepsAllocateNothing) { expect_steps_allocate_nothing(1, 1 << 30); }

TEST(Allocation, ParallelStepsAllocateNothing) { expect_steps_allocate_nothing(2, 0); }
