// Sleeping of quiescent regions (docs/model.md §16): a settled bed falls
// asleep and stays where it was; a grain dropped on it wakes the cells it
// reaches and the chain beyond; a body resting on a sleeping bed does not
// sink; results are the same for any thread count and across a resume.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/core/sleep.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/generate.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kR = 0.004;  // mean grain radius, m
constexpr double kL = 0.1;    // box side, m

struct Scene {
  rt::Model m;
  rt::State s;
};

// 1,200 grains poured into a 0.1 m box under Earth gravity and settled
// (velocities quenched every 10 ms, then 0.1 s free), built once.
const Scene& settled_bed() {
  static const Scene bed = [] {
    Scene sc;
    rt::Model& m = sc.m;
    rt::test::grain_and_wall_in_open_box(m, kL);
    std::mt19937_64 rng(5);
    rt::RadiusDist d;
    d.mean = kR;
    d.sigma = 0.05;
    rt::Region box;
    box.lo = Vec3::Zero();
    box.hi = Vec3(kL, kL, 1.0);
    const int n = 1200;
    const std::vector<Vec3> sites = rt::lattice_sites(box, 2.2 * d.max(), d.max(), 0.0, n, rng);
    const std::vector<double> radii = rt::draw_radii(d, n, rng);
    for (int i = 0; i < n; ++i) rt::add_grain(m, radii[i], 0);
    const double m_p = 4.0 / 3.0 * M_PI * std::pow(kR, 3) * 2430;
    m.kn = rt::kn_rule(m_p, 1.0, 0.01 * kR);
    m.dt = rt::dt_rule(m_p, m.kn, 20);
    rt::finalize_model(m);
    sc.s = rt::make_state(m);
    for (int i = 0; i < n; ++i) sc.s.pos[i] = sites[i];
    const int quench = int(0.01 / m.dt);
    for (int k = 0; k < int(0.4 / m.dt); ++k) {
      rt::step(m, sc.s);
      if (k % quench == 0 && k < int(0.3 / m.dt))
        for (int i = 0; i < n; ++i) sc.s.vel[i] = sc.s.omega[i] = Vec3::Zero();
    }
    return sc;
  }();
  return bed;
}

double top(const rt::Model& m, const rt::State& s, int n) {
  double t = -1e300;
  for (int i = 0; i < n; ++i) t = std::max(t, s.pos[i].z() + m.grain_radius[i]);
  return t;
}

// Mean height of the grains whose centre lies in the top 2 radii of the bed.
double surface(const rt::Model& m, const rt::State& s, int n, double top0) {
  double sum = 0;
  int k = 0;
  for (int i = 0; i < n; ++i)
    if (s.pos[i].z() > top0 - 3 * kR) {
      sum += s.pos[i].z();
      ++k;
    }
  return k ? sum / k : 0;
}

uint64_t state_hash(const rt::State& s) {
  uint64_t h = rt::fnv1a(s.pos.data(), s.pos.size() * sizeof(Vec3));
  h = rt::fnv1a(s.vel.data(), s.vel.size() * sizeof(Vec3), h);
  return rt::fnv1a(s.sleep.asleep.data(), s.sleep.asleep.size(), h);
}

void run(const rt::Model& m, rt::State& s, double seconds) {
  const long steps = long(seconds / m.dt);
  for (long k = 0; k < steps; ++k) rt::step(m, s);
}

TEST(SleepTest, SettledBedSleepsAndStaysPut) {
  Scene sc = settled_bed();
  const int n = sc.m.n_grains;
  const double top0 = top(sc.m, sc.s, n), surf0 = surface(sc.m, sc.s, n, top0);
  sc.m.sleep.enabled = true;
  run(sc.m, sc.s, 0.3);
  const long asleep = rt::sleeping_grains(sc.s);
  EXPECT_GT(asleep, 0.8 * n) << "a settled bed falls asleep";
  const double surf1 = surface(sc.m, sc.s, n, top0);
  EXPECT_LT(std::fabs(surf1 - surf0), 0.1 * kR) << "the surface of a sleeping bed neither creeps nor sinks";
  // Sleeping grains touch something (nothing sleeps in mid-air) and are at rest.
  for (int i = 0; i < n; ++i)
    if (sc.s.sleep.asleep[i]) ASSERT_EQ(sc.s.vel[i].squaredNorm(), 0.0);
  RecordProperty("asleep_of_1200", rt::test::figure(double(asleep)));
  RecordProperty("surface_shift_over_r", rt::test::figure((surf1 - surf0) / kR));
}

TEST(SleepTest, FloatingGrainsDoNotSleep) {
  // Grains at rest in mid-air touch nothing: they fall, they do not sleep.
  rt::Model m;
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5)};
  for (int i = 0; i < 8; ++i) rt::add_grain(m, kR, 0);
  m.kn = 1e4;
  m.dt = 1e-5;
  m.sleep.enabled = true;
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  for (int i = 0; i < 8; ++i) s.pos[i] = Vec3(0.1 * i, 0, 1.0);
  run(m, s, 0.05);
  EXPECT_EQ(rt::sleeping_grains(s), 0);
  EXPECT_NEAR(s.pos[0].z(), 1.0 - 0.5 * 9.81 * s.time * s.time, 1e-9);
}

TEST(SleepTest, DroppedGrainWakesItsCellsAndTheChain) {
  Scene sc = settled_bed();
  rt::Model& m = sc.m;
  const int n = m.n_grains;
  const double top0 = top(m, sc.s, n);
  m.sleep.enabled = true;
  run(m, sc.s, 0.05);
  const long asleep0 = rt::sleeping_grains(sc.s);
  ASSERT_GT(asleep0, 0.8 * n);
  // A grain of twice the radius at 1 m/s onto the middle of the sleeping bed.
  Scene ref = sc;  // the same bed with sleeping off, for comparison
  const Vec3 drop(0.5 * kL, 0.5 * kL, top0 + 3 * kR);
  for (Scene* x : {&sc, &ref}) {
    const int g = rt::add_grain(x->m, x->s, 2 * kR, 0, drop, Vec3(0, 0, -1), Vec3::Zero());
    ASSERT_EQ(g, n);
  }
  ref.m.sleep.enabled = false;
  std::vector<uint8_t> ever_woken(n, 0);
  double lowest = 1e300, lowest_ref = 1e300;
  const long steps = long(0.03 / m.dt);
  for (long k = 0; k < steps; ++k) {
    rt::step(sc.m, sc.s);
    rt::step(ref.m, ref.s);
    for (int i = 0; i < n; ++i) ever_woken[i] |= !sc.s.sleep.asleep[i];
    lowest = std::min(lowest, sc.s.pos[n].z());
    lowest_ref = std::min(lowest_ref, ref.s.pos[n].z());
  }
  // Every grain within two grain diameters of the impact point woke, and so
  // did grains beyond the cells next to it (the chain the impact moves).
  const double cell = rt::sleep_thresholds(m).cell;
  int near = 0, near_woken = 0, far_woken = 0;
  const Vec3 hit(drop.x(), drop.y(), top0);
  for (int i = 0; i < n; ++i) {
    const double d = (sc.s.pos[i] - hit).norm();
    if (d < 4 * kR) {
      ++near;
      near_woken += ever_woken[i];
    }
    if (d > 2.5 * cell) far_woken += ever_woken[i];
  }
  EXPECT_GT(near, 0);
  EXPECT_EQ(near_woken, near);
  EXPECT_GT(far_woken, 0) << "the wake travels beyond the impact cell's neighbours";
  // The grain is stopped by the bed as by the bed left awake: its deepest
  // point within a grain radius of the reference run's.
  EXPECT_NEAR(lowest, lowest_ref, kR);
  RecordProperty("deepest_vs_reference_over_r", rt::test::figure((lowest - lowest_ref) / kR));
  RecordProperty("far_woken", rt::test::figure(far_woken));
}

TEST(SleepTest, RestingBodyDoesNotSinkIntoSleepingBed) {
  // A 30 g block set down on the bed and left to come to rest (bed awake), then
  // run on with sleeping off and on: with sleeping on, the grains under it
  // fall asleep and the block stays where it rests.
  const Scene& bed = settled_bed();
  const int n = bed.m.n_grains;
  Scene sc = bed;
  rt::Model& m = sc.m;
  m.materials.push_back(rt::test::simple_material("body", 2000, 0.5, 0.5, 0.5));
  m.materials.back().structure = true;
  rt::BodyModel b;
  b.name = "block";
  b.mass = 0.03;
  const Vec3 ext(0.05, 0.05, 0.02);
  b.inertia = Vec3(ext.y() * ext.y() + ext.z() * ext.z(), ext.x() * ext.x() + ext.z() * ext.z(),
                   ext.x() * ext.x() + ext.y() * ext.y()) *
              (b.mass / 12);
  b.material = 2;
  rt::Shape box;
  box.type = rt::ShapeType::Box;
  box.size = ext / 2;
  b.shapes = {box};
  m.bodies.push_back(b);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos = bed.s.pos;
  s.vel = bed.s.vel;
  s.omega = bed.s.omega;
  // Highest grain top under the block's footprint.
  double under = 0;
  for (int i = 0; i < n; ++i)
    if (std::fabs(s.pos[i].x() - 0.5 * kL) < 0.5 * ext.x() + kR && std::fabs(s.pos[i].y() - 0.5 * kL) < 0.5 * ext.y() + kR)
      under = std::max(under, s.pos[i].z() + m.grain_radius[i]);
  s.bodies[0].pos = Vec3(0.5 * kL, 0.5 * kL, under + 0.5 * ext.z() + 1e-4);
  run(m, s, 0.6);  // sets down, comes to rest
  ASSERT_LT(s.bodies[0].vel.norm(), 0.01);
  const double z0 = s.bodies[0].pos.z();
  double z_end[2];
  long asleep_end = 0;
  int carrying = 0, carrying_asleep = 0;
  for (int on = 0; on < 2; ++on) {
    rt::Model mm = m;
    rt::State ss = s;
    mm.sleep.enabled = on == 1;
    run(mm, ss, 0.3);
    z_end[on] = ss.bodies[0].pos.z();
    if (on) {
      asleep_end = rt::sleeping_grains(ss);
      // The grains that carry the block: touching it from below.
      const double bottom = ss.bodies[0].pos.z() - 0.5 * ext.z();
      for (int k = 0; k < ss.body_grains.size(); ++k)
        if (ss.body_grains.touching[k] && ss.pos[ss.body_grains.grain[k]].z() < bottom) {
          ++carrying;
          carrying_asleep += ss.sleep.asleep[ss.body_grains.grain[k]];
        }
    }
  }
  // Not vacuous: the bed, and grains that carry the block, sleep.
  EXPECT_GT(asleep_end, n / 2) << "the bed under the resting block sleeps";
  EXPECT_GE(carrying_asleep, carrying / 2) << "the grains that carry the block sleep";
  EXPECT_LT(std::fabs(z_end[1] - z0), 0.1 * kR) << "the block does not sink into the sleeping bed";
  EXPECT_LT(std::fabs(z_end[1] - z_end[0]), 0.1 * kR) << "the block rests where it rests on the bed left awake";
  RecordProperty("block_sink_over_r", rt::test::figure((z_end[1] - z0) / kR));
  RecordProperty("block_vs_awake_over_r", rt::test::figure((z_end[1] - z_end[0]) / kR));
  RecordProperty("asleep_of_1200", rt::test::figure(double(asleep_end)));
  RecordProperty("carrying_asleep", std::to_string(carrying_asleep) + " of " + std::to_string(carrying));
}

TEST(SleepTest, SameResultForAnyThreadCountAndAcrossResume) {
  const Scene& bed = settled_bed();
  const int n = bed.m.n_grains;
  const double top0 = top(bed.m, bed.s, n);
  auto start = [&] {
    Scene sc = bed;
    sc.m.sleep.enabled = true;
    sc.m.parallel_min_grains = 1;  // the threaded loops run even on this small bed
    rt::add_grain(sc.m, sc.s, 2 * kR, 0, Vec3(0.3 * kL, 0.6 * kL, top0 + 0.02), Vec3(0.2, 0, -1), Vec3::Zero());
    return sc;
  };
  const long k1 = long(0.02 / bed.m.dt), k2 = long(0.04 / bed.m.dt);
  auto steps = [](const rt::Model& m, rt::State& s, long k) {
    for (long q = 0; q < k; ++q) rt::step(m, s);
  };
  uint64_t h[2];
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    Scene sc = start();
    steps(sc.m, sc.s, k1 + k2);
    h[threads - 1] = state_hash(sc.s);
  }
  omp_set_num_threads(2);
  EXPECT_EQ(h[0], h[1]) << "1 and 2 threads";
  Scene a = start();
  steps(a.m, a.s, k1);
  const long woke = a.s.sleep.woke;
  const std::string path = "/tmp/sleep_test_" + std::to_string(::getpid()) + ".ckpt";
  rt::save_checkpoint(path, a.m, a.s);
  rt::State b = rt::load_checkpoint(path, a.m);
  std::remove(path.c_str());
  EXPECT_EQ(b.sleep.asleep, a.s.sleep.asleep);
  EXPECT_EQ(b.sleep.woke, woke);
  steps(a.m, b, k2);
  EXPECT_EQ(state_hash(b), h[0]) << "resumed from a checkpoint";
  EXPECT_GT(woke, 0);
}

}  // namespace
