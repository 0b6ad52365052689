// The step allocates no memory once its buffers are sized (state.hpp): after a
// warm-up, thousands of steps of a flowing scene, neighbour-list rebuilds
// included, make no call to operator new; with rigid bodies (grain–body and
// body–body contacts) neither the engine nor Bullet allocates. This binary
// replaces the global operator new/delete to count calls.
#include <LinearMath/btAlignedAllocator.h>
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

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/io/scenario.hpp"
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

// Bullet's own heap calls (btAlignedAlloc, used by its containers and pool
// fallbacks) bypass operator new: they are counted through Bullet's hook.
std::atomic<long> g_bullet_allocations{0};
void* counted_bullet_alloc(std::size_t n) {
  g_bullet_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void bullet_free(void* p) { std::free(p); }

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
  EXPECT_TRUE(rt::test::preset_with_wall(m, "moderate"));
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
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(d.mean, 3) * m.materials[0].density;
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

void expect_steps_allocate_nothing(int threads, int parallel_min_grains, bool free_flight = false) {
  omp_set_num_threads(threads);
  Scene sc = make_scene(parallel_min_grains);
  sc.m.free_flight.enabled = free_flight;  // the reach build at every rebuild (model.md §18)
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

namespace {


// 1200 'moderate' grains thrown down between four plane walls onto a fixed
// plate body, around a free box sliding and spinning on the plate and a
// second free box that lands on it, under tilted gravity: grain–body
// contacts on all three bodies and body–body contacts (plate–box, box–box).
// Mesh variants (grain–mesh contacts) have one body only, so that no
// body–body query runs (Bullet's convex-hull clipping and concave
// narrow phase allocate; that is the body–body path, not this one):
// kFixedMeshPlate, the plate as a triangle mesh; kFreeMeshBox, box a as a
// triangle mesh, free, held against gravity, the grains raining onto it.
enum MeshVariant { kNoMesh, kFixedMeshPlate, kFreeMeshBox };
Scene make_body_scene(int parallel_min_grains, MeshVariant mesh = kNoMesh) {
  Scene sc;
  rt::Model& m = sc.m;
  rt::Material grain;
  EXPECT_TRUE(rt::material_preset("moderate", grain));
  m.materials.push_back(grain);
  rt::Material structure = rt::test::simple_material("structure", 2000, 0.4, 0.4, 0.6);
  structure.structure = true;
  m.materials.push_back(structure);
  const double L = 0.06;
  m.walls.push_back(rt::make_plane(Vec3(-L, 0, 0), Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3(L, 0, 0), -Vec3::UnitX(), 1));
  m.walls.push_back(rt::make_plane(Vec3(0, -L, 0), Vec3::UnitY(), 1));
  m.walls.push_back(rt::make_plane(Vec3(0, L, 0), -Vec3::UnitY(), 1));
  const Vec3 half_a(0.03, 0.025, 0.015), half_b(0.012, 0.012, 0.01);
  m.bodies.push_back(rt::test::box_body("plate", Vec3(0.1, 0.1, 0.01), 2000, true, 1));
  m.bodies.push_back(rt::test::box_body("box_a", half_a, 2000, false, 1));
  m.bodies.push_back(rt::test::box_body("box_b", half_b, 2000, false, 1));
  if (mesh != kNoMesh) {
    const int keep = mesh == kFixedMeshPlate ? 0 : 1;
    rt::BodyModel b = m.bodies[keep];
    b.meshes = {rt::test::box_mesh(-b.shapes[0].size, b.shapes[0].size, mesh == kFixedMeshPlate ? 8 : 3)};
    b.shapes[0].type = rt::ShapeType::Mesh;
    b.shapes[0].mesh = 0;
    rt::finalize_body(b);  // its surface, for the gaps below
    m.bodies[keep] = b;    // the other bodies go after the grains are placed
  }
  // Box b starts 2 mm above box a and lands on it during the measured window:
  // the body–body point list grows in steady state.
  const Vec3 pos_a(0.0, 0.0, half_a.z() - 5e-5), pos_b = pos_a + Vec3(0.006, 0.003, half_a.z() + half_b.z() + 2e-3);
  std::mt19937_64 rng(7);
  rt::RadiusDist d;
  d.mean = 0.003;
  d.sigma = 0.1;
  rt::Region region;
  region.lo = Vec3(-L, -L, 3e-4);  // the first layer just clear of the plate
  region.hi = Vec3(L, L, 0.15);
  const int n = 1200;
  const std::vector<Vec3> sites = rt::lattice_sites(region, 2.02 * d.max(), d.max(), 0.0, 4 * n, rng);
  std::vector<Vec3> kept;
  for (const Vec3& p : sites) {
    if (int(kept.size()) == n) break;
    const bool clear_a = rt::shape_gap(m.bodies[1], m.bodies[1].shapes[0], p - pos_a, d.max()).overlap < -3e-4;
    const bool clear_b = rt::shape_gap(m.bodies[2], m.bodies[2].shapes[0], p - pos_b, d.max()).overlap < -3e-4;
    if (clear_a && clear_b) kept.push_back(p);
  }
  EXPECT_EQ(int(kept.size()), n);
  if (mesh != kNoMesh) m.bodies = {m.bodies[mesh == kFixedMeshPlate ? 0 : 1]};
  const std::vector<double> radii = rt::draw_radii(d, n, rng);
  for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0);
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(d.mean, 3) * m.materials[0].density;
  m.kn = 2e4;
  m.body_kn = 5e4;
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  m.gravity = Vec3(1.5, 0.5, -9.81);
  m.parallel_min_grains = parallel_min_grains;
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  std::normal_distribution<double> v(0.0, 0.1);
  for (int i = 0; i < n; ++i) {
    sc.s.pos[i] = kept[i];
    sc.s.vel[i] = Vec3(v(rng), v(rng), v(rng) - 0.5);
  }
  if (mesh == kFixedMeshPlate) {
    sc.s.bodies[0].pos = Vec3(0, 0, -0.01);
  } else if (mesh == kFreeMeshBox) {
    // Below the grains, held up against gravity by an applied force (there
    // is no plate): the grains land on it, push it and slide off while it turns.
    sc.s.bodies[0].pos = pos_a - Vec3(0, 0, 0.016);  // just below the grains
    rt::set_body_velocity(m.bodies[0], sc.s.bodies[0], Vec3(0.05, 0.02, 0), Vec3(0, 0, 0.8));
    sc.s.body_applied_force = {-m.bodies[0].mass * m.gravity};
    sc.s.body_applied_torque = {Vec3::Zero()};
  } else {
    sc.s.bodies[0].pos = Vec3(0, 0, -0.01);
    sc.s.bodies[1].pos = pos_a;
    sc.s.bodies[2].pos = pos_b;
    rt::set_body_velocity(m.bodies[1], sc.s.bodies[1], Vec3(0.05, 0.02, 0), Vec3(0, 0, 0.8));
    rt::set_body_velocity(m.bodies[2], sc.s.bodies[2], Vec3(-0.03, 0.01, -0.2), Vec3(0, 0, -1.0));
  }
  return sc;
}

void expect_body_steps_allocate_nothing(int threads, int parallel_min_grains, MeshVariant mesh = kNoMesh) {
  omp_set_num_threads(threads);
  Scene sc = make_body_scene(parallel_min_grains, mesh);
  for (int k = 0; k < 300; ++k) rt::step(sc.m, sc.s);  // warm-up (thread pool, first lists)
  constexpr int kWindow = 3000;
  for (const auto& p : sc.s.body_points) EXPECT_FALSE(p.a == 1 && p.b == 2) << "box b landed during the warm-up";
  const long rebuilds0 = sc.s.rebuilds, body_rebuilds0 = sc.s.body_rebuilds;
  long body_contacts = 0, body_body = 0, box_box = 0;
  btAlignedAllocSetCustom(counted_bullet_alloc, bullet_free);
  const long before = g_allocations.load(), bullet_before = g_bullet_allocations.load();
  for (int k = 0; k < kWindow; ++k) {
    rt::step(sc.m, sc.s);
    body_contacts += sc.s.stats.body_contacts;
    body_body += sc.s.stats.body_body_contacts;
    for (const auto& p : sc.s.body_points) box_box += p.a == 1 && p.b == 2;
  }
  const long allocations = g_allocations.load() - before;
  const long bullet_allocations = g_bullet_allocations.load() - bullet_before;
  EXPECT_EQ(allocations, 0) << "operator new called during " << threads << "-thread steps with bodies";
  EXPECT_EQ(bullet_allocations, 0) << "Bullet allocated during " << threads << "-thread steps with bodies";
  // The window covered list rebuilds and live grain–body and body–body contacts.
  EXPECT_GE(sc.s.rebuilds - rebuilds0, 3);
  EXPECT_GE(sc.s.body_rebuilds - body_rebuilds0, 3);
  // Mean live grain–body contacts per step (the grains raining onto the
  // free mesh box bounce and slide off: about one at a time).
  EXPECT_GT(double(body_contacts) / kWindow, mesh == kFreeMeshBox ? 0.5 : 20.0) << "variant " << mesh;
  if (mesh != kNoMesh) return;
  EXPECT_GE(body_body / kWindow, 4);       // mean body–body points per step
  EXPECT_GT(box_box, kWindow / 2);          // the two free boxes touch through most of the window
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

TEST(Allocation, StepsWithFreeFlightAllocateNothing) { expect_steps_allocate_nothing(2, 0, true); }

TEST(Allocation, SerialStepsWithBodiesAllocateNothing) { expect_body_steps_allocate_nothing(1, 1 << 30); }

TEST(Allocation, ParallelStepsWithBodiesAllocateNothing) { expect_body_steps_allocate_nothing(2, 0); }

TEST(Allocation, StepsWithMeshBodiesAllocateNothing) {
  for (MeshVariant v : {kFixedMeshPlate, kFreeMeshBox}) {
    expect_body_steps_allocate_nothing(1, 1 << 30, v);
    expect_body_steps_allocate_nothing(2, 0, v);
  }
}
