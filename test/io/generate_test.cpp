// Grain generation (docs/scenes.md E.1): the random fill places every grain
// inside its region, clear of the others by the gap, in the same places for
// the same seed, sorted bottom-up; a region too small for the count is
// reported; the scenario reads `arrangement: random` and refuses the
// lattice's keys with it. A graded fill's grains follow its knobs (each
// radius is a drawn one times the grading's scale at its place), a fill to a
// solid fraction reaches it, and a grading that scales nothing changes no site.
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

rt::Grading mascot_grading() {
  rt::Grading g;
  g.surface = 0.30;
  g.base = 0.0;
  g.compaction = 0.5;
  g.center_x = 0.05;
  g.center_y = -0.02;
  g.fine_depth = 0.06;
  g.fine_radius = 0.15;
  g.depth_rate = 0.2;
  g.radial_rate = 0.1;
  g.max_scale = 3;
  g.mean_diameter = 0.02;
  return g;
}

TEST(GradedFill, ScaleFollowsItsKnobs) {
  const rt::Grading g = mascot_grading();
  // Generated z = 0.6 maps to the surface (0.5 * 0.6); 0.48 to 0.24, the fine layer's bottom.
  EXPECT_DOUBLE_EQ(g.scale(Vec3(0.05, -0.02, 0.6)), 1.0);
  EXPECT_DOUBLE_EQ(g.scale(Vec3(0.05, -0.02, 0.48)), 1.0);
  EXPECT_DOUBLE_EQ(g.scale(Vec3(0.15, -0.02, 0.48)), 1.0);  // 0.10 from the axis: inside the fine zone
  // 0.10 m deeper than the fine layer (generated 0.2 m lower): the diameter grows by 0.2 * 0.10 = 0.02 m.
  EXPECT_NEAR(g.scale(Vec3(0.05, -0.02, 0.28)), 2.0, 1e-12);
  // 0.05 m beyond the fine zone: 0.1 * 0.05 = 0.005 m, a quarter of the diameter.
  EXPECT_NEAR(g.scale(Vec3(0.25, -0.02, 0.48)), 1.25, 1e-12);
  // Both add; the cap holds.
  EXPECT_NEAR(g.scale(Vec3(0.25, -0.02, 0.28)), 2.25, 1e-12);
  EXPECT_DOUBLE_EQ(g.scale(Vec3(0.05, -0.02, 0.0)), 3.0);
}

TEST(GradedFill, GrainsAreDrawnRadiiTimesTheScaleAtTheirPlace) {
  const rt::Grading g = mascot_grading();
  const rt::Region region = cylinder(0.35, 0.0, 0.62);
  const rt::RadiusDist d{0.01, 0.3, 1.0};
  std::mt19937_64 rng(11);
  const double gap = 0.0005;
  const rt::RandomFill f = rt::random_fraction(region, d, 0.12, 0.0, gap, 20000, rng, &g);
  ASSERT_GT(f.sites.size(), 500u);
  double volume = 0, unscaled_sum = 0, fine = 0, coarse = 0;
  int n_fine = 0, n_coarse = 0;
  for (size_t i = 0; i < f.sites.size(); ++i) {
    const Vec3& p = f.sites[i];
    const double r = f.radii[i], s = g.scale(p);
    volume += 4.0 / 3.0 * M_PI * r * r * r;
    // The drawn radius is within the distribution's cut.
    ASSERT_GE(r / s, 0.007 - 1e-12);
    ASSERT_LE(r / s, 0.013 + 1e-12);
    unscaled_sum += r / s;
    ASSERT_LE(std::hypot(p.x(), p.y()) + r, 0.35 + 1e-12);
    ASSERT_GE(p.z() - r, -1e-12);
    ASSERT_LE(p.z() + r, 0.62 + 1e-12);
    if (s == 1.0) {
      fine += r;
      ++n_fine;
    } else if (s == 3.0) {
      coarse += r;
      ++n_coarse;
    }
  }
  for (size_t i = 0; i < f.sites.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      ASSERT_GE((f.sites[i] - f.sites[j]).norm(), f.radii[i] + f.radii[j] + gap - 1e-12);
  // The drawn radii keep their mean; the fine zone has the distribution's sizes, the capped region three times them.
  EXPECT_NEAR(unscaled_sum / f.sites.size(), 0.01, 3e-4);
  ASSERT_GT(n_fine, 20);
  ASSERT_GT(n_coarse, 20);
  EXPECT_NEAR(fine / n_fine, 0.01, 6e-4);
  EXPECT_NEAR(coarse / n_coarse, 0.03, 2e-3);
  // The solid fraction is reached by the last grain and not passed by more than it.
  const double target = 0.12 * rt::region_volume(region);
  EXPECT_GE(volume, target);
  EXPECT_LT(volume, target + 4.0 / 3.0 * M_PI * std::pow(0.039, 3));
}

// The grains' number density falls as 1/scale^3 where they grow, so that the
// solid fraction is the same in the fine and the coarse part of a fill (a bed
// poured from it then settles to the same height everywhere). Box 0.4 x 0.4 x
// 0.6 m, grains of 5 mm: twice that size below z = 0.25 m, drawn size above
// 0.3 m; the fractions are compared in interior boxes kept 2 cm from the sides
// (without the 1/scale^3 the coarse part would hold about 8 times the fraction).
TEST(GradedFill, SolidFractionIsUniformWhereGrainsGrow) {
  rt::Grading g;
  g.surface = 0.6;
  g.fine_depth = 0.3;
  g.depth_rate = 1.0;
  g.max_scale = 2;
  g.mean_diameter = 0.01;
  rt::Region box;
  box.lo = Vec3(0, 0, 0);
  box.hi = Vec3(0.4, 0.4, 0.6);
  std::mt19937_64 rng(21);
  const rt::RandomFill f = rt::random_fraction(box, rt::RadiusDist{0.005, 0.2, 1.0}, 0.15, 0.0, 0.0002, 20000, rng, &g);
  double v_fine = 0, v_coarse = 0;
  int n_fine = 0, n_coarse = 0;
  for (size_t i = 0; i < f.sites.size(); ++i) {
    const Vec3& p = f.sites[i];
    if (p.x() < 0.02 || p.x() > 0.38 || p.y() < 0.02 || p.y() > 0.38) continue;
    const double v = 4.0 / 3.0 * M_PI * std::pow(f.radii[i], 3);
    if (p.z() >= 0.32 && p.z() <= 0.58) {
      v_fine += v;
      ++n_fine;
    } else if (p.z() >= 0.02 && p.z() <= 0.25) {
      v_coarse += v;
      ++n_coarse;
    }
  }
  const double a = 0.36 * 0.36;
  ASSERT_GT(n_coarse, 300);
  EXPECT_GT(n_fine, 6 * n_coarse);  // about 8 times as many per volume
  // Inside, both a little above the whole box's 0.15 (no centre lies within a radius of its sides).
  const double fine = v_fine / (a * 0.26), coarse = v_coarse / (a * 0.23);
  EXPECT_NEAR(fine, 0.155, 0.01);
  EXPECT_NEAR(coarse / fine, 1.0, 0.08);
}

TEST(GradedFill, AGradingThatScalesNothingChangesNoSite) {
  rt::Grading g = mascot_grading();
  g.max_scale = 1.0;
  const rt::RadiusDist d{0.01, 0.3, 1.0};
  const rt::Region region = cylinder(0.25, 0.0, 0.5);
  std::mt19937_64 a(4), b(4);
  const rt::RandomFill plain = rt::random_sites(region, rt::draw_radii(d, 2000, a), 0.0, 0.001, 20000, a);
  const rt::RandomFill graded = rt::random_sites(region, rt::draw_radii(d, 2000, b), 0.0, 0.001, 20000, b, &g);
  ASSERT_EQ(plain.sites.size(), 2000u);
  EXPECT_EQ(plain.sites, graded.sites);
  EXPECT_EQ(plain.radii, graded.radii);
}

// Fills without grading draw as before grading existed: these sums are those of
// the same fill made by the build before (a change of the random sequence moves
// them at the first digit; 1e-12 leaves room for floating-point contraction).
TEST(RandomFill, UngradedFillsDrawAsBeforeGrading) {
  const rt::Region r = cylinder(0.25, 0.0, 0.5);
  std::mt19937_64 rng(2018);
  const rt::RadiusDist d{0.01, 0.33, 1.0};
  const rt::RandomFill f = rt::random_sites(r, rt::draw_radii(d, 3000, rng), 0.0, 0.001, 20000, rng);
  ASSERT_EQ(f.sites.size(), 3000u);
  Vec3 sum = Vec3::Zero();
  double sr = 0;
  for (size_t i = 0; i < f.sites.size(); ++i) {
    sum += f.sites[i];
    sr += f.radii[i];
  }
  EXPECT_NEAR(sum.x(), 0.16790911646944043, 1e-12);
  EXPECT_NEAR(sum.y(), 0.72640716912785341, 1e-12);
  EXPECT_NEAR(sum.z(), 746.0000539227018, 1e-9);
  EXPECT_NEAR(sr, 29.930168318708819, 1e-12);
  EXPECT_NEAR(f.sites[0].x(), 0.0077812660416528602, 1e-15);
  EXPECT_NEAR(f.sites[0].y(), -0.23539440931717442, 1e-15);
  EXPECT_NEAR(f.sites[0].z(), 0.010689255119449714, 1e-15);
  EXPECT_NEAR(f.radii[0], 0.0073710498516073291, 1e-15);
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
  // Graded and solid-fraction fills.
  std::string fraction = base;
  fraction.replace(fraction.find("count: 400"), 10, "solid_fraction: 0.05");
  const std::string fraction_path = ::testing::TempDir() + "/fill_fraction_test.yaml";
  std::ofstream(fraction_path) << fraction;
  const rt::Scenario sf = rt::load_scenario(
      fraction_path, {"grains.0.fill.grading={surface: 0.2, fine_depth: 0.05, depth_rate: 0.3, max_scale: 2}"});
  double volume = 0;
  for (int i = 0; i < sf.model.n_grains; ++i) volume += 4.0 / 3.0 * M_PI * std::pow(sf.model.grain_radius[i], 3);
  EXPECT_GE(volume, 0.05 * M_PI * 0.2 * 0.2 * 0.5);
  const rt::Scenario sf_plain = rt::load_scenario(fraction_path);
  EXPECT_LT(sf.model.n_grains, 0.9 * sf_plain.model.n_grains);  // the grains below the fine layer are larger
  refused({"grains.0.fill.solid_fraction=0.05"}, "give either count or grains[0].fill.solid_fraction");
  try {
    rt::load_scenario(fraction_path, {"grains.0.fill.solid_fraction=0.34"});
    ADD_FAILURE() << "accepted: a solid fraction of 0.34";
  } catch (const rt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not reached at random"), std::string::npos) << e.what();
  }
  refused({"grains.0.fill.arrangement=lattice", "grains.0.fill.grading={surface: 0.2}"}, "grains[0].fill.grading");
  refused({"grains.0.fill.grading={surface: 0.2, radial_rate: 0.1}"}, "grains[0].fill.grading.fine_radius");
  refused({"grains.0.fill.grading={fine_depth: 0.1}"}, "grains[0].fill.grading.surface");
  refused({"grains.0.fill.grading={surface: 0.2, max_scale: 0.5}"}, "grains[0].fill.grading.max_scale");
}

}  // namespace
