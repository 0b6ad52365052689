// The reusable observers against hand counts: ejecta (counted once, with
// volume, not if above the plane at the start, only on sampled steps), the
// region count (count and mass), the active zone (frozen beyond the radius,
// woken as the body comes near, never frozen again; the edge check leaves
// ejecta out), the energy series (initial energy, columns) and the surface
// height map.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <unistd.h>

#include "regolith_twin/observers/active_zone.hpp"
#include "regolith_twin/observers/region_count.hpp"
#include "regolith_twin/observers/surface_map.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

// n grains of radius r on the x axis at x = 0.1 k, z = 0 (no walls, no gravity), and one free sphere body at the origin.
struct Line {
  rt::Model m;
  rt::State s;
};

Line line(int n, double r) {
  Line l;
  l.m.materials.push_back(rt::test::simple_material("g", 2000, 0.5, 0.5, 0.5));
  l.m.gravity.setZero();
  for (int k = 0; k < n; ++k) rt::add_grain(l.m, r, 0);
  rt::BodyModel b;
  b.name = "probe";
  b.mass = 1;
  b.inertia = Vec3::Constant(1e-3);
  rt::Shape sh;
  sh.type = rt::ShapeType::Sphere;
  sh.size = Vec3::Constant(0.01);
  b.shapes.push_back(sh);
  l.m.bodies.push_back(b);
  l.m.kn = 1e3;
  l.m.dt = 1e-4;
  rt::finalize_model(l.m);
  l.s = rt::make_state(l.m);
  for (int k = 0; k < n; ++k) l.s.pos[k] = Vec3(0.1 * k, 0, 0);
  l.s.bodies[0].pos = Vec3(0, 0, 1);
  return l;
}

}  // namespace

TEST(Observers, EjectaCountOnceWithVolumeOnSampledSteps) {
  Line l = line(3, 0.01);
  l.s.pos[2].z() = 0.5;  // above the plane at the start: never counted
  rt::Ejecta e(0.2, 10);
  e.start(l.m, l.s);
  l.s.pos[0].z() = 0.3;
  l.s.step = 5;
  l.s.ticks = 5;  // not a sampled step
  e.after_step(l.m, l.s);
  EXPECT_EQ(e.count(), 0);
  l.s.step = 10;
  l.s.ticks = 10;
  e.after_step(l.m, l.s);
  l.s.step = 20;
  l.s.ticks = 20;
  e.after_step(l.m, l.s);  // still above: counted once
  EXPECT_EQ(e.count(), 1);
  EXPECT_DOUBLE_EQ(e.volume(), 4.0 / 3.0 * M_PI * 1e-6);
  EXPECT_TRUE(e.ejected(0));
  EXPECT_FALSE(e.ejected(1));
  EXPECT_FALSE(e.ejected(2));
  std::vector<double> row;
  e.row(l.m, l.s, row);
  EXPECT_EQ(row, std::vector<double>{1.0});
}

TEST(Observers, RegionCountsGrainsAndMass) {
  Line l = line(5, 0.01);
  rt::RegionCount rc("mid", Vec3(0.05, -1, -1), Vec3(0.25, 1, 1));  // grains at x = 0.1, 0.2
  rc.start(l.m, l.s);
  EXPECT_EQ(rc.grains(), 2);
  EXPECT_DOUBLE_EQ(rc.mass(), l.m.grain_mass[1] + l.m.grain_mass[2]);
  l.s.pos[3].x() = 0.15;
  rc.after_step(l.m, l.s);
  EXPECT_EQ(rc.grains(), 3);
  std::vector<std::string> cols;
  rc.columns(cols);
  EXPECT_EQ(cols, (std::vector<std::string>{"mid_count", "mid_mass"}));
}

TEST(Observers, ActiveZoneFreezesBeyondTheRadiusAndWakesAsTheBodyComes) {
  Line l = line(6, 0.01);  // grains at x = 0 ... 0.5
  for (int k = 0; k < 6; ++k) l.s.vel[k] = Vec3(0, 0, 0.01 * (k + 1));
  rt::Ejecta ejecta(10.0, 1);
  ejecta.start(l.m, l.s);
  rt::ActiveZone z(0, 0.15, 0.06, 1, &ejecta);  // body at x = 0: grains at 0, 0.1 free
  z.prepare(l.m, l.s);
  EXPECT_FALSE(l.s.forces_valid) << "a frozen model needs its lists and forces again";
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(l.m.grain_inv_mass[k] == 0, k >= 2) << k;
    EXPECT_EQ(l.s.vel[k].norm() == 0, k >= 2) << k;
  }
  l.s.bodies[0].pos.x() = 0.01;  // moved less than 2 cm: no update
  l.s.step = 1;
  l.s.ticks = 1;
  z.after_measures(l.m, l.s);
  EXPECT_EQ(l.m.grain_inv_mass[2], 0);
  l.s.bodies[0].pos.x() = 0.3;  // now grains at 0.2, 0.3, 0.4 are inside; 0 and 0.1 stay woken
  z.after_measures(l.m, l.s);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(l.m.grain_inv_mass[k] == 0, k == 5) << k;
  EXPECT_TRUE(l.s.rebuild_requested);
  z.finish(l.m, l.s);
  EXPECT_EQ(z.active_grains(), 5);
  // Free grains beyond 0.15 - 0.06 from x = 0.3: those at 0, 0.1 (speeds 0.01, 0.02) and
  // 0.2, 0.4 (frozen at rest, then woken): the zone's edge and what it left behind.
  EXPECT_DOUBLE_EQ(z.edge_rms(), std::sqrt((0.01 * 0.01 + 0.02 * 0.02) / 4));
}

TEST(Observers, SurfaceMapTakesTheHighestGrainTopPerCell) {
  Line l = line(3, 0.01);
  l.s.pos[0] = Vec3(0.005, 0.005, 0.10);
  l.s.pos[1] = Vec3(0.006, 0.004, 0.20);  // same cell, higher
  l.s.pos[2] = Vec3(-0.015, 0.005, 0.05);
  const std::string path = "/tmp/regolith_surface_test_" + std::to_string(::getpid()) + ".csv";
  rt::write_surface(path, l.m, l.s, 0.02, 0.1, 0.01);
  std::ifstream f(path);
  std::string header, a, b, c;
  std::getline(f, header);
  std::getline(f, a);
  std::getline(f, b);
  EXPECT_EQ(header, "x,y,height");
  EXPECT_EQ(a, "-0.015,0.005,-0.04");  // 0.05 + 0.01 - 0.1
  EXPECT_EQ(b, "0.005,0.005,0.11");    // 0.20 + 0.01 - 0.1
  EXPECT_FALSE(std::getline(f, c));
  std::remove(path.c_str());
}
