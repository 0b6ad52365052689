// Grain generation (docs/scenes.md E.1): the random fill places every grain
// inside its region, clear of the others by the gap, in the same places for
// the same seed, sorted bottom-up; a region too small for the count is
// reported; the scenario reads `arrangement: random` and refuses the
// lattice's keys with it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/io/scenario.hpp"

namespace {

using rt::Vec3;

rt::Region cylinder(double radius, double z0, double z1) {
  rt::Region r;
  r.shape = rt::RegionShape::Cylinder;
  r.center = Vec3::Zero();
  r.radius = radius;
  r.lo = Vec3(-radius, -radius, z0);
  r.hi = Vec3(radius, radius, z1);
  return r;
}

TEST(RandomFill, GrainsInsideAndApart) {
  std::mt19937_64 rng(5);
  rt::RadiusDist d{0.01, 0.33, 1.0};
  const std::vector<double> radii = rt::draw_radii(d, 3000, rng);
  const rt::Region region = cylinder(0.25, 0.0, 1.0);
  const double gap = 0.001;
  const rt::RandomFill f = rt::random_sites(region, radii, 0.0, gap, 20000, rng);
  ASSERT_EQ(f.sites.size(), radii.size());
  ASSERT_EQ(f.radii.size(), radii.size());
  // The radii are the drawn ones, permuted.
  std::vector<double> a = radii, b = f.radii;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
  double min_clear = 1e9;
  for (size_t i = 0; i < f.sites.size(); ++i) {
    const Vec3& p = f.sites[i];
    const double r = f.radii[i];
    ASSERT_LE(std::hypot(p.x(), p.y()) + r, 0.25 + 1e-12);
    ASSERT_GE(p.z() - r, -1e-12);
    ASSERT_LE(p.z() + r, 1.0 + 1e-12);
    for (size_t j = 0; j < i; ++j) min_clear = std::min(min_clear, (f.sites[j] - p).norm() - r - f.radii[j]);
  }
  EXPECT_GE(min_clear, gap - 1e-12);
  EXPECT_LT(min_clear, 0.01);  // random, not a spread-out lattice
  // Bottom-up: the layer (2 r_max + gap thick) never decreases along the list.
  const double layer = 2 * *std::max_element(radii.begin(), radii.end()) + gap;
  for (size_t i = 1; i < f.sites.size(); ++i)
    ASSERT_LE(int(f.sites[i - 1].z() / layer), int(f.sites[i].z() / layer));
  // Uniform: the mean height is mid-region and a quarter of the grains are in each quarter of the height.
  int low = 0;
  double zsum = 0;
  for (const Vec3& p : f.sites) {
    zsum += p.z();
    low += p.z() < 0.25;
  }
  EXPECT_NEAR(zsum / f.sites.size(), 0.5, 0.02);
  EXPECT_NEAR(double(low) / f.sites.size(), 0.24, 0.03);
}

TEST(RandomFill, SameSeedSamePlacesAndFullRegionsReported) {
  rt::RadiusDist d{0.005, 0.0, 1.0};
  rt::Region box;
  box.lo = Vec3(0, 0, 0);
  box.hi = Vec3(0.1, 0.1, 0.1);
  auto fill = [&](uint64_t seed, int n) {
    std::mt19937_64 rng(seed);
    return rt::random_sites(box, rt::draw_radii(d, n, rng), 0.0, 0.0, 2000, rng);
  };
  const rt::RandomFill a = fill(9, 500), b = fill(9, 500), c = fill(10, 500);
  ASSERT_EQ(a.sites.size(), 500u);
  EXPECT_EQ(a.sites, b.sites);
  EXPECT_NE(a.sites, c.sites);
  // 0.1 m cube: 5,000 beads of 1 cm would be a solid fraction of 2.6 (impossible).
  EXPECT_LT(fill(9, 5000).sites.size(), 5000u);
}

TEST(RandomFill, ScenarioKeys) {
  const std::string base = R"(name: fill
seed: 3
gravity: [0, 0, -9.81]
materials: {g: {preset: moderate}}
contact: {model: linear, kn: 1000, dt: 1e-4}
walls: [{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: g}]
grains:
  - {name: bed, material: g, radius: {mean: 0.01, sigma: 0.2}, fill: {shape: cylinder, center: [0, 0, 0], radius: 0.2, z: [0, 0.5], count: 400, arrangement: random}}
stages: [{name: s, duration: 0.001}]
)";
  const std::string path = ::testing::TempDir() + "/fill_test.yaml";
  std::ofstream(path) << base;
  const rt::Scenario sc = rt::load_scenario(path);
  ASSERT_EQ(sc.model.n_grains, 400);
  for (int i = 0; i < 400; ++i) {
    for (int j = 0; j < i; ++j)
      ASSERT_GE((sc.initial.pos[i] - sc.initial.pos[j]).norm(),
                sc.model.grain_radius[i] + sc.model.grain_radius[j] + 0.001 - 1e-12);  // default gap 0.1 r_mean
  }
  auto refused = [&](const std::vector<std::string>& set, const std::string& what) {
    try {
      rt::load_scenario(path, set);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused({"grains.0.fill.spacing=0.03"}, "grains[0].fill.spacing");
  refused({"grains.0.fill.arrangement=hexagonal"}, "grains[0].fill.arrangement");
  refused({"grains.0.fill.arrangement=lattice", "grains.0.fill.gap=0.001"}, "grains[0].fill.gap");
  refused({"grains.0.fill.count=40000"}, "do not fit at random");
}

}  // namespace
