// Geometry of every analytic wall type (docs/model.md §5) at hand-computed points,
// including edges and rims, and the static overlap m g / k_n of a grain
// resting on each of them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "regolith_twin/core/walls.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;
using rt::Wall;
using rt::WallType;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-12;  // m, and for unit normals

void expect_gap(const Wall& w, const Vec3& p, double r, double overlap, const Vec3& n, const std::string& where) {
  const rt::WallGap g = rt::wall_gap(w, p, r);
  EXPECT_NEAR(g.overlap, overlap, kTol) << where;
  EXPECT_NEAR((g.n - n.normalized()).norm(), 0.0, kTol) << where << ": normal " << g.n.transpose() << ", expected "
                                                         << n.normalized().transpose();
  EXPECT_NEAR(g.n.norm(), 1.0, kTol) << where;
}

Wall disk(const Vec3& c, const Vec3& normal, double radius) {
  Wall w;
  w.type = WallType::Disk;
  w.origin = c;
  w.axis = normal.normalized();
  w.radius = radius;
  return w;
}

Wall rectangle(const Vec3& c, const Vec3& normal, const Vec3& u, double hu, double hv) {
  Wall w;
  w.type = WallType::Rectangle;
  w.origin = c;
  w.axis = normal.normalized();
  w.u = u.normalized();
  w.half_u = hu;
  w.half_v = hv;
  return w;
}

Wall cone(const Vec3& base, const Vec3& axis, double r0, double r1, double length, bool inner) {
  Wall w;
  w.type = WallType::Cone;
  w.origin = base;
  w.axis = axis.normalized();
  w.radius = r0;
  w.radius2 = r1;
  w.length = length;
  w.inner = inner;
  return w;
}

Wall shell(const Vec3& c, double radius, bool inner) {
  Wall w;
  w.type = WallType::SphereShell;
  w.origin = c;
  w.radius = radius;
  w.inner = inner;
  return w;
}

}  // namespace

TEST(WallGeometry, Plane) {
  const Wall w = rt::make_plane(Vec3(0, 0, 1), Vec3(0, 0, 2), 0);
  expect_gap(w, Vec3(3, -2, 1.004), 0.005, 0.001, Vec3(0, 0, -1), "above");
  expect_gap(w, Vec3(0, 0, 1.02), 0.005, -0.015, Vec3(0, 0, -1), "apart");
  expect_gap(w, Vec3(0, 0, 0.99), 0.005, 0.015, Vec3(0, 0, -1), "centre behind the plane");
  // Tilted normal (1, 1, 0)/sqrt 2 through the origin.
  const Wall t = rt::make_plane(Vec3::Zero(), Vec3(1, 1, 0), 0);
  expect_gap(t, Vec3(0.003, 0.001, 7), 0.005, 0.005 - 0.004 / std::sqrt(2.0), Vec3(-1, -1, 0), "tilted");
}

TEST(WallGeometry, Disk) {
  const Wall w = disk(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1);
  expect_gap(w, Vec3(0.05, 0.02, 0.003), 0.005, 0.002, Vec3(0, 0, -1), "face, above");
  expect_gap(w, Vec3(0.05, 0.02, -0.003), 0.005, 0.002, Vec3(0, 0, 1), "face, below");
  // Beyond the rim: the closest point is (0.1, 0, 0), 3-4-5 triangle.
  expect_gap(w, Vec3(0.103, 0, 0.004), 0.006, 0.001, Vec3(-0.6, 0, -0.8), "rim");
  expect_gap(w, Vec3(0.103, 0, -0.004), 0.006, 0.001, Vec3(-0.6, 0, 0.8), "rim from below");
  // In the disk's plane, outside: edge-on contact.
  expect_gap(w, Vec3(0, -0.104, 0), 0.005, 0.001, Vec3(0, 1, 0), "edge-on");
  // A tilted disk: centre (1, 2, 3), normal x.
  const Wall t = disk(Vec3(1, 2, 3), Vec3(1, 0, 0), 0.05);
  expect_gap(t, Vec3(1.004, 2.03, 3.02), 0.005, 0.001, Vec3(-1, 0, 0), "tilted face");
}

TEST(WallGeometry, Rectangle) {
  // 0.2 x 0.1 in the plane z = 0; u = x, v = axis x u = y.
  const Wall w = rectangle(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0), 0.1, 0.05);
  expect_gap(w, Vec3(0.09, 0.04, 0.004), 0.005, 0.001, Vec3(0, 0, -1), "face");
  expect_gap(w, Vec3(-0.09, -0.04, -0.004), 0.005, 0.001, Vec3(0, 0, 1), "face, below");
  expect_gap(w, Vec3(0.103, 0.01, 0.004), 0.006, 0.001, Vec3(-0.6, 0, -0.8), "edge along v");
  expect_gap(w, Vec3(0.02, -0.053, 0.004), 0.006, 0.001, Vec3(0, 0.6, -0.8), "edge along u");
  // Corner (0.1, 0.05, 0): offset (0.002, 0.002, 0.001), distance 0.003.
  expect_gap(w, Vec3(0.102, 0.052, 0.001), 0.004, 0.001, Vec3(-2, -2, -1), "corner");
  // Rotated in its plane: u = (1, 1, 0)/sqrt 2; the point lies past the u edge.
  const Wall t = rectangle(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 1, 0), 0.1, 0.01);
  const Vec3 u = Vec3(1, 1, 0).normalized();
  expect_gap(t, 0.103 * u + Vec3(0, 0, 0.004), 0.006, 0.001, -0.6 * u + Vec3(0, 0, -0.8), "rotated edge");
  expect_gap(t, 0.103 * u + Vec3(0, 0, 0.004) + 0.02 * Vec3(-1, 1, 0).normalized(), 0.006, 0.006 - std::sqrt(0.003 * 0.003 + 0.004 * 0.004 + 0.01 * 0.01),
             -0.003 * u - 0.01 * Vec3(-1, 1, 0).normalized() + Vec3(0, 0, -0.004), "rotated corner");
}

TEST(WallGeometry, CylinderFinite) {
  // Axis z from the origin, radius 0.1, length 0.2.
  const Wall in = rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 0, 3), 0.1, 0.2, true, 0);
  expect_gap(in, Vec3(0.096, 0, 0.1), 0.005, 0.001, Vec3(1, 0, 0), "inner side");
  expect_gap(in, Vec3(0, 0.097, 0.05), 0.005, 0.002, Vec3(0, 1, 0), "inner side, y");
  const double s = std::sqrt(0.5);
  expect_gap(in, Vec3(0.0965 * s, -0.0965 * s, 0.15), 0.005, 0.0015, Vec3(s, -s, 0), "inner side, diagonal");
  expect_gap(in, Vec3(0.102, 0, 0.1), 0.005, 0.007, Vec3(1, 0, 0), "inner, centre beyond the surface");
  // Past the top end (z = 0.2) the rim circle is the closest feature.
  const double d = std::sqrt(0.002 * 0.002 + 0.003 * 0.003);
  expect_gap(in, Vec3(0.098, 0, 0.203), 0.005, 0.005 - d, Vec3(0.002, 0, -0.003), "inner rim, top");
  expect_gap(in, Vec3(0, 0.098, -0.003), 0.005, 0.005 - d, Vec3(0, 0.002, 0.003), "inner rim, bottom");

  const Wall out = rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.2, false, 0);
  expect_gap(out, Vec3(0.104, 0, 0.1), 0.005, 0.001, Vec3(-1, 0, 0), "outer side");
  expect_gap(out, Vec3(0.103, 0, 0.204), 0.006, 0.001, Vec3(-0.6, 0, -0.8), "outer rim, top");
  expect_gap(out, Vec3(0, -0.103, -0.004), 0.006, 0.001, Vec3(0, 0.6, 0.8), "outer rim, bottom");
  expect_gap(out, Vec3(0.2, 0, 0.1), 0.005, -0.095, Vec3(-1, 0, 0), "outer, apart");

  // A horizontal cylinder (axis x) starting at (1, 0, 0).
  const Wall h = rt::make_cylinder(Vec3(1, 0, 0), Vec3(1, 0, 0), 0.05, 0.5, true, 0);
  expect_gap(h, Vec3(1.2, 0, -0.046), 0.005, 0.001, Vec3(0, 0, -1), "horizontal inner, bottom");
}

TEST(WallGeometry, CylinderInfinite) {
  const Wall in = rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.0, true, 0);
  expect_gap(in, Vec3(0, -0.096, 5.0), 0.005, 0.001, Vec3(0, -1, 0), "inner, far up the axis");
  expect_gap(in, Vec3(0.096, 0, -7.0), 0.005, 0.001, Vec3(1, 0, 0), "inner, below the base point");
  const Wall out = rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, -1.0, false, 0);
  expect_gap(out, Vec3(0, 0.104, -3.0), 0.005, 0.001, Vec3(0, -1, 0), "outer, below the base point");
  expect_gap(out, Vec3(0.3, 0.4, 2.0), 0.005, 0.005 - 0.4, Vec3(-0.6, -0.8, 0), "outer, apart");
}

TEST(WallGeometry, Cone) {
  // Radius 0.1 at z = 0 narrowing to 0.05 at z = 0.1: meridian rho = 0.1 - z/2,
  // outward normal (rho, z) = (2, 1)/sqrt 5.
  const Vec3 n_out = Vec3(2, 0, 1) / std::sqrt(5.0);
  const Vec3 surf(0.075, 0, 0.05);  // surface point at z = 0.05 on the x side
  const Wall in = cone(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.05, 0.1, true);
  expect_gap(in, surf - 0.004 * n_out, 0.005, 0.001, n_out, "inner side");
  const Wall out = cone(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.05, 0.1, false);
  expect_gap(out, surf + 0.004 * n_out, 0.005, 0.001, -n_out, "outer side");
  // Past the narrow end: the rim (0.05, 0, 0.1) is the closest point.
  expect_gap(out, Vec3(0.053, 0, 0.104), 0.006, 0.001, Vec3(-0.6, 0, -0.8), "outer rim, narrow end");
  expect_gap(in, Vec3(0.047, 0, 0.104), 0.006, 0.001, Vec3(0.6, 0, -0.8), "inner rim, narrow end");
  // Past the wide end: rim (0.1, 0, 0).
  expect_gap(out, Vec3(0.104, 0, -0.003), 0.006, 0.001, Vec3(-0.8, 0, 0.6), "outer rim, wide end");
  // An expanding cone on a tilted axis, rotated about the axis: same numbers.
  const Vec3 a = Vec3(0, 1, 1).normalized(), e = Vec3(1, 0, 0);  // e is perpendicular to a
  const Wall tilted = cone(Vec3(1, 1, 1), a, 0.05, 0.1, 0.1, true);
  // Meridian rho = 0.05 + z/2, outward normal (2, -1)/sqrt 5; surface point at z = 0.05.
  const Vec3 q = Vec3(1, 1, 1) + 0.075 * e + 0.05 * a;
  const Vec3 nt = (2 * e - a) / std::sqrt(5.0);
  expect_gap(tilted, q - 0.004 * nt, 0.005, 0.001, nt, "tilted expanding cone, inner side");
}

TEST(WallGeometry, SphereShell) {
  const Wall in = shell(Vec3(1, 2, 3), 0.1, true);
  expect_gap(in, Vec3(1, 2, 3 - 0.096), 0.005, 0.001, Vec3(0, 0, -1), "inner");
  expect_gap(in, Vec3(1, 2, 3), 0.005, 0.005 - 0.1, Vec3(0, 0, 1), "inner, at the centre");
  const Wall out = shell(Vec3(0, 0, 0), 0.1, false);
  const Vec3 d = Vec3(1, 1, 1).normalized();
  expect_gap(out, 0.104 * d, 0.005, 0.001, -d, "outer");
  expect_gap(out, 0.098 * d, 0.005, 0.007, -d, "outer, centre inside the sphere");
}

namespace {

// A grain touching wall w at point p0 (overlap 0), pressed into it by gravity
// along the wall normal there, settles at the overlap m g / k_n.
void expect_rests(Wall w, const Vec3& p0, const std::string& what) {
  constexpr double r = 0.005, density = 2500, g = 9.81;
  rt::Model m;
  m.materials.push_back(rt::test::simple_material("grain", density, 0.5, 0.5, 0.5));
  rt::Material wm = rt::test::simple_material("wall", density, 0.5, 0.5, 0.5);
  wm.structure = true;
  m.materials.push_back(wm);
  w.law_material = 1;
  m.walls.push_back(w);
  rt::add_grain(m, r, 0);
  const rt::WallGap g0 = rt::wall_gap(w, p0, r);
  ASSERT_NEAR(g0.overlap, 0.0, 1e-12) << what << ": start point does not touch the wall";
  m.gravity = g * g0.n;
  const double mass = 4.0 / 3.0 * kPi * r * r * r * density;
  m.kn = rt::kn_rule(mass, 1.0, 0.01 * r);
  m.dt = rt::dt_rule(mass, m.kn, 30);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  s.pos[0] = p0;
  // Contact half-period ~ 30 steps; eps_n = 0.5 halves the amplitude each bounce.
  for (int k = 0; k < 6000; ++k) rt::step(m, s);
  const double x_eq = mass * g / m.kn;
  const rt::WallGap ge = rt::wall_gap(w, s.pos[0], r);
  EXPECT_NEAR(ge.overlap, x_eq, 1e-6 * x_eq) << what;
  EXPECT_NEAR((ge.n - g0.n).norm(), 0.0, 1e-9) << what;
  EXPECT_LT(s.vel[0].norm(), 1e-9) << what;
  EXPECT_EQ(s.stats.wall_contacts, 1) << what;
}

}  // namespace

TEST(WallRest, EveryWallTypeGivesStaticOverlapMgOverKn) {
  const double r = 0.005;
  expect_rests(rt::make_plane(Vec3(0, 0, 0), Vec3(0, 0, 1), 0), Vec3(0.3, -0.2, r), "plane");
  expect_rests(rt::make_plane(Vec3(0, 0, 0), Vec3(1, 2, 3), 0), r * Vec3(1, 2, 3).normalized(), "tilted plane");
  expect_rests(disk(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.05), Vec3(0.01, 0.02, r), "disk");
  expect_rests(rectangle(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0), 0.1, 0.05), Vec3(0.05, -0.02, r), "rectangle");
  expect_rests(rt::make_cylinder(Vec3(0, 0, 0), Vec3(1, 0, 0), 0.05, 0.3, true, 0), Vec3(0.1, 0, -0.05 + r),
               "finite cylinder, inner");
  expect_rests(rt::make_cylinder(Vec3(0, 0, 0), Vec3(1, 0, 0), 0.05, 0.3, false, 0), Vec3(0.1, 0, 0.05 + r),
               "finite cylinder, outer");
  expect_rests(rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 1, 0), 0.05, 0.0, true, 0), Vec3(0, 3.0, -0.05 + r),
               "infinite cylinder, inner");
  expect_rests(rt::make_cylinder(Vec3(0, 0, 0), Vec3(0, 1, 0), 0.05, 0.0, false, 0), Vec3(0, -2.0, 0.05 + r),
               "infinite cylinder, outer");
  const Vec3 n_out = Vec3(2, 0, 1) / std::sqrt(5.0), surf(0.075, 0, 0.05);
  expect_rests(cone(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.05, 0.1, true), surf - r * n_out, "cone, inner");
  expect_rests(cone(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.1, 0.05, 0.1, false), surf + r * n_out, "cone, outer");
  expect_rests(shell(Vec3(0, 0, 0), 0.1, true), Vec3(0, 0, -0.1 + r), "sphere shell, inner");
  expect_rests(shell(Vec3(0, 0, 0), 0.1, false), Vec3(0, 0, 0.1 + r), "sphere shell, outer");
  // On an edge: a grain resting on the rim of a disk, pressed along the rim normal.
  expect_rests(disk(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.05), Vec3(0.05 + 0.6 * r, 0, 0.8 * r), "disk rim");
}
