// Energy partition of the sampler shot (docs/scenes.md B.4): every spring
// type of bed–bed, projectile–grain and grain–wall contacts against the hand
// formulas of docs/model.md §2 for single static overlaps, kinetic parts
// against ½ m v² and ½ I ω²; and an elastic two-grain collision with
// friction, rolling and twisting resistance (e = 1, no dashpots, caps far
// away) whose parts add up to the projectile's initial kinetic energy to
// 1e-6 throughout the contact.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <unistd.h>

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

double sphere_mass(double r, double rho) { return 4.0 / 3.0 * kPi * r * r * r * rho; }

// Index of the pair-list entry (i, j), i < j; -1 if absent.
int pair_entry(const rt::State& s, int i, int j) {
  for (int k = s.pairs.row_start[i]; k < s.pairs.row_start[i + 1]; ++k)
    if (s.pairs.partner[k] == j) return k;
  return -1;
}

}  // namespace

// Grains A–B (bed–bed), B–P (P the projectile) and C on a plane wall, each
// pair overlapping by a set amount with set springs: each term is the
// formula of docs/model.md §2 with k_t = 2/7 k_n, k_R = k_n (βR)²,
// k_T = 2 k_t (βR)², R = r_i r_j / (r_i + r_j) (the grain radius on a wall).
TEST(EnergyPartition, SpringTermsMatchHandFormulasForStaticOverlaps) {
  const double rho = 2000, kn = 1e4, beta = 0.5;
  rt::Model m;
  rt::Material g = rt::test::simple_material("grain", rho, 0.5, 0.5, 0.8);
  g.mu_r = 0.5;
  g.mu_t = 0.6;
  g.beta = beta;
  m.materials.push_back(g);
  rt::Material w = rt::test::simple_material("wall", rho, 0.5, 0.5, 0.8);
  w.structure = true;
  m.materials.push_back(w);
  m.gravity.setZero();
  m.walls.push_back(rt::make_plane(Vec3(0, 0, -1), Vec3::UnitZ(), 1));
  const double rA = 2.5e-3, rB = 2e-3, rP = 4e-3, rC = 3e-3;
  const double xAB = 1e-4, xBP = 5e-5, xC = 2e-4;
  rt::add_grain(m, rA, 0);  // A
  rt::add_grain(m, rB, 0);  // B
  rt::add_grain(m, rP, 0);  // P, the projectile
  rt::add_grain(m, rC, 0);  // C, on the wall
  m.kn = kn;
  m.dt = 1e-6;
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(0, 0, 0);
  s.pos[1] = Vec3(rA + rB - xAB, 0, 0);
  s.pos[2] = s.pos[1] + Vec3(0, rB + rP - xBP, 0);
  s.pos[3] = Vec3(0.1, 0, -1 + rC - xC);
  s.vel[0] = Vec3(0.1, 0, 0);
  s.omega[0] = Vec3(0, 0, 10);
  s.vel[2] = Vec3(0, -3, 0);
  s.omega[2] = Vec3(5, 0, 0);
  rt::prime(m, s);
  const int kAB = pair_entry(s, 0, 1), kBP = pair_entry(s, 1, 2);
  ASSERT_GE(kAB, 0);
  ASSERT_GE(kBP, 0);
  ASSERT_GT((s.pos[2] - s.pos[0]).norm(), rA + rP);  // A and P are apart
  ASSERT_EQ(s.wall_pairs.size(), 1);
  ASSERT_EQ(s.wall_pairs.grain[0], 3);
  const Vec3 S_AB(0, 3e-5, 0), R_AB(0, 0, 0.02), S_BP(0, 0, 1e-5), R_BP(0.01, 0, 0), S_C(2e-5, 0, 0),
      R_C(0, 0.01, 0);
  const double T_AB = 0.03, T_BP = -0.05, T_C = 0.04;
  s.pairs.spring_t[kAB] = S_AB;
  s.pairs.spring_r[kAB] = R_AB;
  s.pairs.spring_w[kAB] = T_AB;
  s.pairs.spring_t[kBP] = S_BP;
  s.pairs.spring_r[kBP] = R_BP;
  s.pairs.spring_w[kBP] = T_BP;
  s.wall_pairs.spring_t[0] = S_C;
  s.wall_pairs.spring_r[0] = R_C;
  s.wall_pairs.spring_w[0] = T_C;

  const rt::EnergyParts e = rt::energy_parts(m, s, 2);
  const double kt = 2.0 / 7.0 * kn;
  auto expect = [&](const rt::ElasticSplit& got, double x, double R, const Vec3& S, const Vec3& roll, double tw,
                    const char* what) {
    const double br2 = (beta * R) * (beta * R);
    EXPECT_NEAR(got.normal, 0.5 * kn * x * x, 1e-12 * 0.5 * kn * x * x) << what;
    EXPECT_NEAR(got.tangential, 0.5 * kt * S.squaredNorm(), 1e-12 * 0.5 * kt * S.squaredNorm()) << what;
    EXPECT_NEAR(got.rolling, 0.5 * kn * br2 * roll.squaredNorm(), 1e-12 * 0.5 * kn * br2 * roll.squaredNorm())
        << what;
    EXPECT_NEAR(got.twisting, 0.5 * 2 * kt * br2 * tw * tw, 1e-12 * kt * br2 * tw * tw) << what;
  };
  expect(e.bed_bed, xAB, rA * rB / (rA + rB), S_AB, R_AB, T_AB, "bed-bed");
  expect(e.proj_grain, xBP, rB * rP / (rB + rP), S_BP, R_BP, T_BP, "projectile-grain");
  expect(e.grain_wall, xC, rC, S_C, R_C, T_C, "grain-wall");
  // A hand figure, spelled out: the bed–bed rolling term.
  EXPECT_NEAR(e.bed_bed.rolling, 0.5 * 1e4 * std::pow(0.5 * 2.5e-3 * 2e-3 / 4.5e-3, 2) * 4e-4, 1e-20);

  const double mA = sphere_mass(rA, rho), mP = sphere_mass(rP, rho);
  EXPECT_NEAR(e.bed_trans, 0.5 * mA * 0.01, 1e-15);
  EXPECT_NEAR(e.bed_rot, 0.5 * 0.4 * mA * rA * rA * 100, 1e-15);
  EXPECT_NEAR(e.proj_trans, 0.5 * mP * 9, 1e-15);
  EXPECT_NEAR(e.proj_rot, 0.5 * 0.4 * mP * rP * rP * 25, 1e-15);
  // The parts add up to the engine's own bookkeeping.
  const rt::Energy total = rt::energy(m, s);
  EXPECT_NEAR(e.elastic(), total.elastic, 1e-15 * total.elastic);
  EXPECT_NEAR(e.kinetic(), total.kinetic(), 1e-15 * total.kinetic());
  // Without a projectile every grain pair is bed–bed.
  const rt::EnergyParts none = rt::energy_parts(m, s, -1);
  EXPECT_EQ(none.proj_trans, 0);
  EXPECT_NEAR(none.bed_bed.total(), e.bed_bed.total() + e.proj_grain.total(), 1e-18);
}

// A 4 mm projectile with spin hits a 2.5 mm grain at rest off-centre and at
// an angle. e_n = e_t = 1 (no dashpot, also none on rolling and twisting) and
// caps 1000 times the usual ones (no slip until the overlap is nearly gone):
// the sum of all parts stays the projectile's initial kinetic energy to 1e-6
// at every sample of the contact (2000 steps per contact: the leapfrog error,
// of order (π/N)², stays below that). Every spring type takes part. After the
// contact the springs that were still loaded are gone with it (docs/model.md
// §2): the sum never exceeds the initial energy.
TEST(EnergyPartition, ElasticCollisionConservesTheSumOfAllParts) {
  const double rho = 2430, kn = 2e4;
  rt::Model m;
  rt::Material g = rt::test::simple_material("grain", rho, 1.0, 1.0, 1000);
  g.mu_r = 1000;
  g.mu_t = 1000;
  g.beta = 1.0;
  m.materials.push_back(g);
  m.gravity.setZero();
  const double rB = 2.5e-3, rP = 4e-3;
  rt::add_grain(m, rB, 0);  // bed grain
  rt::add_grain(m, rP, 0);  // projectile
  m.kn = kn;
  const double mB = sphere_mass(rB, rho), mP = sphere_mass(rP, rho), mstar = mB * mP / (mB + mP);
  const double tc = kPi * std::sqrt(mstar / kn);
  m.dt = tc / 2000;
  rt::finalize_model(m);
  ASSERT_EQ(m.law(0, 0).cn_coef, 0.0);
  ASSERT_EQ(m.law(0, 0).ct_coef, 0.0);
  ASSERT_TRUE(m.law(0, 0).rolling && m.law(0, 0).twisting);
  rt::State s = rt::make_state(m);
  const double v = 1.0, b = 0.3 * (rB + rP);  // impact parameter along x
  s.pos[0] = Vec3(0, 0, 0);
  s.pos[1] = Vec3(b, 0, std::sqrt(std::pow(rB + rP, 2) - b * b) + 20 * v * m.dt);
  s.vel[1] = Vec3(-0.3, 0.1, -v);
  s.omega[1] = Vec3(40, -60, 90);

  rt::ImpactClock clock(1);
  rt::EnergyPartition ep(&clock, 1, 3 * tc);
  rt::prime(m, s);
  clock.start(m, s);
  ep.start(m, s);
  const double e0 = 0.5 * mP * s.vel[1].squaredNorm() + 0.5 * 0.4 * mP * rP * rP * s.omega[1].squaredNorm();
  EXPECT_NEAR(ep.initial_energy(), e0, 1e-15 * e0);
  while (!ep.window_complete()) {
    rt::step(m, s);
    clock.after_step(m, s);
    ep.after_step(m, s);
    ASSERT_LT(s.step, 20000);
  }
  ASSERT_TRUE(clock.hit());
  const auto& smp = ep.samples();
  ASSERT_GT(smp.size(), 5000u);
  EXPECT_EQ(smp.front().t, 0.0);
  EXPECT_GT(smp.front().proj_grain.normal, 0.0);  // the impact step: the first overlap
  double max_normal = 0;
  for (const rt::EnergyParts& e : smp) max_normal = std::max(max_normal, e.proj_grain.normal);
  double worst = 0, peak_t = 0, peak_r = 0, peak_w = 0, after = 0;
  int in_contact = 0;
  for (const rt::EnergyParts& e : smp) {
    EXPECT_EQ(e.bed_bed.total(), 0.0);
    EXPECT_EQ(e.grain_wall.total(), 0.0);
    if (e.proj_grain.normal > 1e-6 * max_normal) {  // not in the last steps, where the vanishing caps bite
      worst = std::max(worst, std::fabs(e.total() / e0 - 1));
      ++in_contact;
    }
    peak_t = std::max(peak_t, e.proj_grain.tangential / e0);
    peak_r = std::max(peak_r, e.proj_grain.rolling / e0);
    peak_w = std::max(peak_w, e.proj_grain.twisting / e0);
    if (e.proj_grain.normal == 0 && e.t > tc / 2) {
      EXPECT_LE(e.total(), e0 * (1 + 1e-6)) << "t " << e.t;
      after = e.total() / e0;
    }
  }
  RecordProperty("max_relative_error_in_contact", rt::test::figure(worst));
  RecordProperty("energy_after_contact", rt::test::figure(after));
  RecordProperty("peak_tangential", rt::test::figure(peak_t));
  RecordProperty("peak_rolling", rt::test::figure(peak_r));
  RecordProperty("peak_twisting", rt::test::figure(peak_w));
  EXPECT_GT(in_contact, 1500);
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(peak_t, 1e-3);
  EXPECT_GT(peak_r, 1e-3);
  EXPECT_GT(peak_w, 1e-3);
  EXPECT_LT(smp.front().bed_trans, 1e-6 * e0);
  EXPECT_GT(smp.back().bed_trans, 0.1 * e0);
  EXPECT_NEAR(smp.back().t, 3 * tc, m.dt);

  // The file: a header and one row per sample, normalised.
  char path[] = "/tmp/energy_partition_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  ep.write_csv(path);
  std::ifstream f(path);
  std::string header, first;
  std::getline(f, header);
  std::getline(f, first);
  EXPECT_EQ(header.rfind("t,ke_bed_trans,ke_bed_rot,ke_proj_trans,ke_proj_rot,bed_bed_normal", 0), 0u);
  EXPECT_NE(header.find(",total"), std::string::npos);
  EXPECT_EQ(first.rfind("0,", 0), 0u);
  std::remove(path);
  rt::JsonObject j;
  ep.summary(j);
  EXPECT_NE(j.dump().find("\"window_complete\": true"), std::string::npos) << j.dump();
}
