// Checkpoints and determinism of scenes with rigid bodies: a bed of grains
// between walls on a fixed plate body, with a free box resting on the plate
// and a second free box on top of it (grain–body and body–body contacts, with
// their spring history, live at once). Saving mid-contact and resuming gives
// bit-identically the state of an uninterrupted run, at 1 and 2 threads; 1, 2
// and 4 threads agree bit for bit; damaged or mismatched files are refused.
// Also: the steps-per-contact line of a body–body pair.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "test_support.hpp"

namespace {

using rt::BodyModel;
using rt::Quat;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

using rt::test::box_body;

struct Scene {
  rt::Model m;
  rt::State s;
};

const Vec3 kHalfA(0.03, 0.025, 0.015), kHalfB(0.012, 0.012, 0.01);

// Grains (3 mm, 'moderate': rolling and twisting resistance) thrown down in a
// 12 x 12 cm box of plane walls onto a fixed plate body (top face z = 0),
// around box A (free, on the plate, sliding and spinning) and box B (free, on A).
// `extra_body` adds a fourth body far away (a scene that differs in its bodies).
Scene make_scene(int grains = 900, bool extra_body = false) {
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
  BodyModel plate = box_body("plate", Vec3(0.1, 0.1, 0.01), 2000, true, 1);
  plate.shapes[0].pos = Vec3(0, 0, 0);
  m.bodies.push_back(plate);
  m.bodies.push_back(box_body("box_a", kHalfA, 2000, false, 1));
  m.bodies.push_back(box_body("box_b", kHalfB, 2000, false, 1));
  if (extra_body) m.bodies.push_back(box_body("far", kHalfB, 2000, false, 1));

  std::mt19937_64 rng(11);
  rt::RadiusDist d;
  d.mean = 0.003;
  d.sigma = 0.1;
  rt::Region region;
  region.lo = Vec3(-L, -L, 3e-4);  // the first layer just clear of the plate
  region.hi = Vec3(L, L, 0.12);
  std::vector<Vec3> sites = rt::lattice_sites(region, 2.02 * d.max(), d.max(), 0.0, 4 * grains, rng);
  // Body poses: the plate's top face at z = 0, A resting on it (slightly
  // pressed in), B on A's top face near one edge, tilted by a small angle.
  const Vec3 pos_plate(0, 0, -0.01);
  const Vec3 pos_a(0.005, -0.004, kHalfA.z() - 5e-5);
  const Quat q_a(Eigen::AngleAxisd(0.2, Vec3::UnitZ()));
  const Vec3 pos_b = pos_a + Vec3(0.008, 0.004, kHalfA.z() + kHalfB.z() - 3e-5);
  const Quat q_b(Eigen::AngleAxisd(-0.4, Vec3::UnitZ()));
  // Keep sites clear of the bodies.
  std::vector<Vec3> kept;
  for (const Vec3& p : sites) {
    if (int(kept.size()) == grains) break;
    bool clear = true;
    const std::pair<Vec3, Quat> poses[2] = {{pos_a, q_a}, {pos_b, q_b}};
    for (int k = 0; k < 2; ++k) {
      const BodyModel& bm = m.bodies[1 + k];
      const rt::ShapeGap g = rt::shape_gap(bm, bm.shapes[0], poses[k].second.conjugate() * (p - poses[k].first),
                                           d.max());
      clear = clear && g.overlap < -0.1 * d.mean;
    }
    if (clear) kept.push_back(p);
  }
  if (int(kept.size()) != grains) {
    ADD_FAILURE() << "only " << kept.size() << " lattice sites clear of the bodies";
    kept.resize(grains, Vec3(0, 0, 1));
  }
  const std::vector<double> radii = rt::draw_radii(d, grains, rng);
  for (int i = 0; i < grains; ++i) rt::add_grain(m, radii[i], 0);
  const double m_p = 4.0 / 3.0 * kPi * std::pow(d.mean, 3) * grain.density;
  m.kn = 2e4;
  m.body_kn = 5e4;
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  m.gravity = Vec3(1.5, 0.5, -9.81);  // tilted: the bodies and the bed keep sliding
  m.parallel_min_grains = 0;           // the force pass runs on every thread
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  std::normal_distribution<double> v(0.0, 0.1);
  for (int i = 0; i < grains; ++i) {
    sc.s.pos[i] = kept[i];
    sc.s.vel[i] = Vec3(v(rng), v(rng), v(rng) - 0.4);
    sc.s.omega[i] = Vec3(v(rng), v(rng), v(rng)) * 20;
  }
  auto place = [&](int b, const Vec3& p, const Quat& q, const Vec3& vel, const Vec3& w) {
    sc.s.bodies[b].pos = p;
    sc.s.bodies[b].q = q;
    rt::set_body_velocity(m.bodies[b], sc.s.bodies[b], vel, w);
  };
  place(0, pos_plate, Quat::Identity(), Vec3::Zero(), Vec3::Zero());
  place(1, pos_a, q_a, Vec3(0.05, 0.02, 0), Vec3(0, 0, 0.8));
  place(2, pos_b, q_b, Vec3(-0.03, 0.01, 0), Vec3(0.0, 0.0, -1.0));
  if (extra_body) place(3, Vec3(0.5, 0.5, 0.5), Quat::Identity(), Vec3::Zero(), Vec3::Zero());
  return sc;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }
bool same_bits(const Quat& a, const Quat& b) { return std::memcmp(a.coeffs().data(), b.coeffs().data(), 32) == 0; }

void expect_identical(const rt::State& a, const rt::State& b, const std::string& what) {
  EXPECT_EQ(a.step, b.step) << what;
  EXPECT_TRUE(same_bits(a.pos, b.pos)) << what << ": grain positions differ";
  EXPECT_TRUE(same_bits(a.vel, b.vel)) << what << ": grain velocities differ";
  EXPECT_TRUE(same_bits(a.omega, b.omega)) << what << ": grain spins differ";
  EXPECT_TRUE(same_bits(a.force, b.force)) << what << ": grain forces differ";
  ASSERT_EQ(a.bodies.size(), b.bodies.size()) << what;
  for (size_t k = 0; k < a.bodies.size(); ++k) {
    const rt::BodyState &x = a.bodies[k], &y = b.bodies[k];
    EXPECT_TRUE(same_bits(x.pos, y.pos)) << what << ": body " << k << " position differs";
    EXPECT_TRUE(same_bits(x.vel, y.vel)) << what << ": body " << k << " velocity differs";
    EXPECT_TRUE(same_bits(x.q, y.q)) << what << ": body " << k << " orientation differs";
    EXPECT_TRUE(same_bits(x.ang_mom, y.ang_mom)) << what << ": body " << k << " angular momentum differs";
    EXPECT_TRUE(same_bits(x.omega, y.omega)) << what << ": body " << k << " angular velocity differs";
    EXPECT_TRUE(same_bits(x.force, y.force)) << what << ": body " << k << " force differs";
    EXPECT_TRUE(same_bits(x.torque, y.torque)) << what << ": body " << k << " torque differs";
  }
  EXPECT_TRUE(same_bits(a.body_grains.spring_t, b.body_grains.spring_t)) << what << ": grain–body springs differ";
  ASSERT_EQ(a.body_points.size(), b.body_points.size()) << what << ": body–body point counts differ";
  for (size_t k = 0; k < a.body_points.size(); ++k) {
    EXPECT_TRUE(same_bits(a.body_points[k].spring_t, b.body_points[k].spring_t))
        << what << ": body–body spring " << k << " differs";
    EXPECT_TRUE(same_bits(a.body_points[k].local_a, b.body_points[k].local_a))
        << what << ": body–body point " << k << " differs";
  }
}

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "rt_ckpt_bodies_" + std::to_string(::getpid()) + "_" + name;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_all(const std::string& path, const std::string& data) {
  std::ofstream out(path, std::ios::binary);
  out.write(data.data(), std::streamsize(data.size()));
}

// Live contacts of a state: grain–body springs (touching, non-zero) and
// body–body points with a non-zero spring.
struct Live {
  long grain_body = 0, body_body = 0, body_body_spring = 0, free_pair = 0;
};
Live live_contacts(const rt::State& s) {
  Live l;
  for (int k = 0; k < s.body_grains.size(); ++k)
    l.grain_body += s.body_grains.touching[k] && s.body_grains.spring_t[k].norm() > 0;
  for (const auto& p : s.body_points) {
    ++l.body_body;
    l.body_body_spring += p.spring_t.norm() > 0;
    l.free_pair += p.a == 1 && p.b == 2;
  }
  return l;
}

constexpr int kBefore = 600, kAfter = 400;

void expect_resumes_bit_identically(int threads) {
  omp_set_num_threads(threads);
  Scene sc = make_scene();
  for (int k = 0; k < kBefore; ++k) rt::step(sc.m, sc.s);
  const Live live = live_contacts(sc.s);
  EXPECT_GT(live.grain_body, 20) << "grain–body springs live at the checkpoint";
  EXPECT_GE(live.body_body, 4) << "body–body points at the checkpoint";
  EXPECT_GE(live.body_body_spring, 4) << "body–body springs live at the checkpoint";
  EXPECT_GE(live.free_pair, 1) << "the two free boxes touch at the checkpoint";
  const std::string path = temp_path("resume_" + std::to_string(threads) + ".ckpt");
  rt::save_checkpoint(path, sc.m, sc.s);
  for (int k = 0; k < kAfter; ++k) rt::step(sc.m, sc.s);  // state A: never stopped

  Scene fresh = make_scene();  // a new process: the same model, a state from the file
  rt::State b = rt::load_checkpoint(path, fresh.m);
  EXPECT_EQ(b.step, kBefore);
  for (int k = 0; k < kAfter; ++k) rt::step(fresh.m, b);  // state B
  expect_identical(sc.s, b, "resumed from a checkpoint on " + std::to_string(threads) + " thread(s)");
  // The run moved the bodies after the checkpoint.
  EXPECT_GT(live_contacts(sc.s).body_body, 0);
  std::remove(path.c_str());
}

}  // namespace

TEST(CheckpointBodies, ResumingIsBitIdenticalOnOneThread) { expect_resumes_bit_identically(1); }

TEST(CheckpointBodies, ResumingIsBitIdenticalOnTwoThreads) { expect_resumes_bit_identically(2); }

TEST(CheckpointBodies, DamagedFilesAreRefused) {
  omp_set_num_threads(1);
  Scene sc = make_scene(200);
  for (int k = 0; k < 50; ++k) rt::step(sc.m, sc.s);
  const std::string path = temp_path("damaged.ckpt");
  rt::save_checkpoint(path, sc.m, sc.s);
  const std::string good = read_all(path);
  ASSERT_GT(good.size(), 1000u);
  EXPECT_NO_THROW(rt::load_checkpoint(path, sc.m));

  auto refusal = [&](const std::string& data) -> std::string {
    write_all(path, data);
    try {
      rt::load_checkpoint(path, sc.m);
    } catch (const rt::InputError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  // Truncated: anywhere in the body sections, and inside the header.
  for (size_t keep : {good.size() - 1, good.size() / 2, size_t(100), size_t(10)}) {
    const std::string msg = refusal(good.substr(0, keep));
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated"), std::string::npos) << "keeping " << keep << " bytes: " << msg;
  }
  // One flipped bit in the body section (the last bytes before the checksum hold the body–body points).
  for (size_t at : {good.size() - 20, good.size() / 2, size_t(20)}) {
    std::string bad = good;
    bad[at] = char(bad[at] ^ 0x10);
    const std::string msg = refusal(bad);
    EXPECT_NE(msg.find("corrupted"), std::string::npos) << "flip at " << at << ": " << msg;
  }
  std::remove(path.c_str());
}

// A file that passes its checksum but holds a state no step could take (a
// non-finite number, an index out of range, a list out of order) is refused
// with its path and what is wrong, never loaded (a NaN position used to
// reach the cell grid, an out-of-range row the force pass).
TEST(CheckpointBodies, ValidFilesWithUnusableStatesAreRefused) {
  omp_set_num_threads(1);
  Scene sc = make_scene(200);
  for (int k = 0; k < 300; ++k) rt::step(sc.m, sc.s);
  const rt::State& good = sc.s;
  ASSERT_GT(good.pairs.size(), 10);
  ASSERT_GT(good.wall_pairs.size(), 1);
  ASSERT_GT(good.body_grains.size(), 1);
  ASSERT_FALSE(good.body_points.empty());
  const std::string path = temp_path("unusable.ckpt");
  rt::save_checkpoint(path, sc.m, good);
  EXPECT_NO_THROW(rt::load_checkpoint(path, sc.m));
  const double nan = std::nan(""), inf = HUGE_VAL;
  int row = 0;  // a grain with at least two partners
  while (good.pairs.row_start[row + 1] - good.pairs.row_start[row] < 2) ++row;
  const int k0 = good.pairs.row_start[row];
  size_t w0 = 0;  // two wall entries of different grains
  while (good.wall_pairs.grain[w0] == good.wall_pairs.grain[w0 + 1]) ++w0;
  struct Case {
    const char* expect;
    std::function<void(rt::State&)> damage;
  };
  const std::vector<Case> cases = {
      {"grain 7 has a non-finite position", [&](rt::State& s) { s.pos[7].y() = nan; }},
      {"grain 3 has a non-finite velocity", [&](rt::State& s) { s.vel[3].z() = inf; }},
      {"grain 5 has a non-finite angular velocity", [&](rt::State& s) { s.omega[5].x() = -inf; }},
      {"clock or step counters", [&](rt::State& s) { s.time = nan; }},
      {"pair list rows", [&](rt::State& s) { s.pairs.row_start.back() += 1000; }},
      {"pair list rows are not in order", [&](rt::State& s) { s.pairs.row_start[row + 1] = s.pairs.row_start[row] - 1; }},
      {"out of order", [&](rt::State& s) { std::swap(s.pairs.partner[k0], s.pairs.partner[k0 + 1]); }},
      {"does not exist", [&](rt::State& s) { s.pairs.partner[k0] = 1 << 30; }},
      {"pair list holds a non-finite spring", [&](rt::State& s) { s.pairs.spring_t[k0].x() = nan; }},
      {"invalid contact flag", [&](rt::State& s) { s.pairs.touching[k0] = 7; }},
      {"wall list refers to a grain or wall", [&](rt::State& s) { s.wall_pairs.wall[0] = 99; }},
      {"wall list is not in order", [&](rt::State& s) { std::swap(s.wall_pairs.grain[w0], s.wall_pairs.grain[w0 + 1]); }},
      {"body 1 ('box_a') has a non-finite", [&](rt::State& s) { s.bodies[1].vel.x() = nan; }},
      {"body 2 ('box_b') has an orientation", [&](rt::State& s) { s.bodies[2].q.coeffs() *= 1.5; }},
      {"grain–body list is not in order",
       [&](rt::State& s) { std::swap(s.body_grains.grain[0], s.body_grains.grain.back()); }},
      {"invalid reduced mass", [&](rt::State& s) { s.body_grains.sqrt_mstar[0] = -1; }},
      {"body contact 0 holds a non-finite value", [&](rt::State& s) { s.body_points[0].point.z() = nan; }},
      // Finite but beyond what the step, the neighbour grid or ROS time can hold
      // (the node aborted on a time of 1e300: ros::Time cannot hold it).
      {"time 1e+300 s, allowed [0, 1e9]",
       [&](rt::State& s) { s.time = 1e300; }},
      {"time -1 s", [&](rt::State& s) { s.time = -1; }},
      {"grain 4 has a position beyond 1e6 m", [&](rt::State& s) { s.pos[4].x() = 1e300; }},
      {"grain 6 has a position beyond 1e6 m or a speed beyond", [&](rt::State& s) { s.vel[6].x() = -2e6; }},
      {"body 1 has a position beyond 1e6 m", [&](rt::State& s) { s.bodies[1].pos.z() = 1e7; }},
  };
  for (const Case& c : cases) {
    rt::State bad = good;
    c.damage(bad);
    rt::save_checkpoint(path, sc.m, bad);  // a valid file (checksum and all) of a bad state
    std::string msg = "(accepted)";
    try {
      rt::load_checkpoint(path, sc.m);
    } catch (const rt::InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find(path), std::string::npos) << c.expect << ": " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
  }
  std::remove(path.c_str());
}

TEST(CheckpointBodies, ADifferentNumberOfBodiesIsRefused) {
  omp_set_num_threads(1);
  Scene sc = make_scene(200);
  for (int k = 0; k < 20; ++k) rt::step(sc.m, sc.s);
  const std::string path = temp_path("bodies.ckpt");
  rt::save_checkpoint(path, sc.m, sc.s);
  const Scene other = make_scene(200, true);
  try {
    rt::load_checkpoint(path, other.m);
    ADD_FAILURE() << "a checkpoint of 3 bodies was loaded into a scene of 4";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3 bodies, the scenario has 4"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

TEST(CheckpointBodies, PrimingDoesNotAdvanceBodyContactHistory) {
  // A state whose forces are invalidated (a stage changes the stiffness, a
  // checkpoint without live lists) is primed: the body–body springs it
  // carries must come out of the priming pass unchanged.
  omp_set_num_threads(1);
  Scene sc = make_scene(200);
  for (int k = 0; k < 300; ++k) rt::step(sc.m, sc.s);
  const std::vector<rt::BodyPointContact> before = sc.s.body_points;
  ASSERT_GE(before.size(), 4u);
  long springs = 0;
  for (const auto& p : before) springs += p.spring_t.norm() > 0;
  ASSERT_GT(springs, 0);
  const auto grain_body_springs = sc.s.body_grains.spring_t;
  const auto grain_body_touching = sc.s.body_grains.touching;
  // The free boxes moved since the last force pass (a restored or edited
  // state): every point is found again at a new place on the plate.
  for (int b : {1, 2}) sc.s.bodies[b].pos += Vec3(2e-5, -1e-5, 0);
  sc.s.forces_valid = false;
  rt::prime(sc.m, sc.s);
  ASSERT_EQ(sc.s.body_points.size(), before.size());
  for (size_t k = 0; k < before.size(); ++k) {
    EXPECT_TRUE(same_bits(sc.s.body_points[k].spring_t, before[k].spring_t)) << "point " << k;
    EXPECT_NEAR((sc.s.body_points[k].local_b - before[k].local_b).norm(), 0.0, 1e-12) << "point " << k;
  }
  EXPECT_TRUE(same_bits(sc.s.body_grains.spring_t, grain_body_springs));
  EXPECT_TRUE(same_bits(sc.s.body_grains.touching, grain_body_touching));
}

TEST(CheckpointBodies, OneTwoAndFourThreadsAgreeAfter2000Steps) {
  constexpr int kSteps = 2000;
  std::vector<rt::State> runs;
  for (int threads : {1, 2, 4}) {
    omp_set_num_threads(threads);
    Scene sc = make_scene();
    for (int k = 0; k < kSteps; ++k) rt::step(sc.m, sc.s);
    if (threads == 1) {
      const Live live = live_contacts(sc.s);
      EXPECT_GT(live.grain_body, 20);
      EXPECT_GE(live.body_body, 4);
      EXPECT_GT(sc.s.stats.contacts, 100);
      EXPECT_GT(sc.s.rebuilds, 3);
    }
    runs.push_back(std::move(sc.s));
  }
  expect_identical(runs[0], runs[1], "1 thread vs 2 threads");
  expect_identical(runs[0], runs[2], "1 thread vs 4 threads");
}

TEST(CheckpointBodies, BodyPairsAreInTheResolutionReport) {
  Scene sc = make_scene(50);
  const rt::Model& m = sc.m;
  const std::vector<rt::PairResolution> report = rt::pair_resolution(m, 1.0);
  auto find = [&](const std::string& label) -> const rt::PairResolution* {
    for (const auto& r : report)
      if (r.label == label) return &r;
    return nullptr;
  };
  const double eps = m.law(1, 1).eps_n, l2 = std::log(eps) * std::log(eps) + kPi * kPi;
  // A free box on the fixed plate: m* is the box's mass.
  const rt::PairResolution* plate_a = find("body-body (plate/box_a)");
  ASSERT_NE(plate_a, nullptr);
  const double tc_a = std::sqrt(m.bodies[1].mass * l2 / m.body_kn);
  EXPECT_NEAR(plate_a->contact_time, tc_a, 1e-12 * tc_a);
  EXPECT_NEAR(plate_a->steps, tc_a / m.dt, 1e-9 * tc_a / m.dt);
  // Two free boxes: the reduced mass.
  const rt::PairResolution* a_b = find("body-body (box_a/box_b)");
  ASSERT_NE(a_b, nullptr);
  const double ms = m.bodies[1].mass * m.bodies[2].mass / (m.bodies[1].mass + m.bodies[2].mass);
  EXPECT_NEAR(a_b->contact_time, std::sqrt(ms * l2 / m.body_kn), 1e-12);
  EXPECT_NE(find("body-body (plate/box_b)"), nullptr);
  EXPECT_NE(find("grain-body (moderate/box_a)"), nullptr);
  long body_lines = 0;
  for (const auto& r : report) body_lines += r.label.rfind("body-body", 0) == 0;
  EXPECT_EQ(body_lines, 3);  // two fixed bodies would make no line; here one is fixed
}

TEST(CheckpointBodies, ResolutionReportOfATwoBodyScenario) {
  const std::string yaml = R"(
name: two_bodies
gravity: [0, 0, -9.81]
materials:
  hull: {density: 2000, eps_n: 0.5, eps_t: 0.5, mu_s: 0.5}
bodies:
  - name: floor
    fixed: true
    material: hull
    shapes: [{type: box, size: [1, 1, 0.1]}]
    position: [0, 0, -0.05]
  - name: crate
    mass: 2.0
    inertia: [0.0133, 0.0133, 0.0133]
    material: hull
    shapes: [{type: box, size: [0.2, 0.2, 0.2]}]
    position: [0, 0, 0.1]
contact: {kn: 1.0e5, body_kn: 4.0e5, dt: 1.0e-5}
stages: [{name: rest, duration: 0.01}]
)";
  rt::Scenario sc;
  try {
    sc = rt::parse_scenario_text(yaml, "two.yaml");
  } catch (const rt::InputError& e) {
    FAIL() << e.what();
  }
  EXPECT_EQ(sc.model.body_kn, 4e5);
  bool found = false;
  for (const auto& r : sc.resolution)
    if (r.label == "body-body (floor/crate)") {
      found = true;
      const double tc = std::sqrt(2.0 * (std::log(0.5) * std::log(0.5) + kPi * kPi) / 4e5);
      EXPECT_NEAR(r.contact_time, tc, 1e-12 * tc);
      EXPECT_NEAR(r.steps, tc / 1e-5, 1e-9 * tc / 1e-5);
    }
  EXPECT_TRUE(found) << "no body-body line in the resolution report";

  // Absent: the scene k_n. Out of range: refused naming the file, key and range.
  std::string plain = yaml;
  plain.replace(plain.find(", body_kn: 4.0e5"), std::strlen(", body_kn: 4.0e5"), "");
  EXPECT_EQ(rt::parse_scenario_text(plain, "two.yaml").model.body_kn, 0.0);
  for (const char* bad : {"0", "-3", "soft"}) {
    std::string text = yaml;
    text.replace(text.find("4.0e5"), 5, bad);
    try {
      rt::parse_scenario_text(text, "two.yaml");
      ADD_FAILURE() << "body_kn: " << bad << " accepted";
    } catch (const rt::InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("two.yaml"), std::string::npos) << msg;
      EXPECT_NE(msg.find("contact.body_kn"), std::string::npos) << msg;
      EXPECT_NE(msg.find("(0, 1e+12]"), std::string::npos) << msg;
    }
  }
}
