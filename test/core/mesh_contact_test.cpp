// Grain–triangle-mesh contacts (docs/model.md §6.3): a grain on a finely
// tessellated plane against the analytic plane wall (impacts on faces, edges
// and vertices, rolling across triangle edges), one contact per face in a
// concave corner and one per convex edge or corner, no tunnelling through a
// thin plate at 300 m/s at the coarsest accepted resolution, a mesh box on
// grains against the same box as a Box shape, and checkpoints of the contact
// history.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/mesh_contact.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "test_support.hpp"

namespace {

using rt::BodyModel;
using rt::Shape;
using rt::ShapeType;
using rt::TriangleMesh;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

// The square [-half, half]^2 of the plane z = 0 in n x n cells, each cut
// along its diagonal into two triangles wound counter-clockwise seen from +z.
// With `stl`, every triangle has its own three vertices, as in an STL file,
// shifted in the plane by up to 1e-13 m (welded at finalize).
TriangleMesh plane_mesh(int n, double half, bool stl) {
  TriangleMesh m;
  const double h = 2 * half / n;
  auto vertex = [&](int i, int j) { return Vec3(-half + h * i, -half + h * j, 0.0); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(vertex(i, j));
  auto id = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  if (!stl) return m;
  TriangleMesh d;
  int k = 0;
  for (const auto& t : m.triangles) {
    std::array<int, 3> nt;
    for (int c = 0; c < 3; ++c) {
      const double jx = 1e-13 * std::sin(1.7 * k + 0.3), jy = 1e-13 * std::cos(2.3 * k);
      d.vertices.push_back(m.vertices[t[c]] + Vec3(jx, jy, 0));
      nt[c] = k++;
    }
    d.triangles.push_back(nt);
  }
  return d;
}

Shape mesh_shape() {
  Shape s;
  s.type = ShapeType::Mesh;
  s.mesh = 0;
  s.link = "mesh";
  return s;
}

// Grain material 0 and structure material 1 (restitution eps_n).
void add_materials(rt::Model& m, double eps_n, double mu) {
  m.materials = {rt::test::simple_material("grain", 2430, 0.5, 0.5, mu),
                 rt::test::simple_material("structure", 2430, eps_n, 0.5, mu)};
  m.materials[1].structure = true;
}

void add_fixed_mesh(rt::Model& m, const TriangleMesh& mesh) {
  BodyModel b;
  b.name = "mesh";
  b.fixed = true;
  b.material = 1;
  b.meshes = {mesh};
  b.shapes = {mesh_shape()};
  m.bodies.push_back(b);
}

void add_plane_wall(rt::Model& m) {
  rt::Wall w;
  w.type = rt::WallType::Plane;
  w.name = "floor";
  w.law_material = 1;
  m.walls.push_back(w);
}

// One grain of radius r over the plane z = 0: the plane as a wall, or as a
// fixed body made of the given mesh.
rt::Model plane_scene(const TriangleMesh* mesh, double r, double eps_n, double mu, const Vec3& g, double n_steps) {
  rt::Model m;
  add_materials(m, eps_n, mu);
  m.gravity = g;
  const double mass = 4.0 / 3.0 * kPi * r * r * r * 2430;
  m.kn = rt::kn_rule(mass, 1.0, 0.01 * r);
  m.dt = rt::dt_rule(mass, m.kn, n_steps);
  rt::add_grain(m, r, 0);
  if (mesh)
    add_fixed_mesh(m, *mesh);
  else
    add_plane_wall(m);
  rt::finalize_model(m);
  return m;
}

// Grain dropped at v onto (x, y) of the plane from a height that puts the
// first overlap at the given phase of a step; returns the restitution and
// the largest number of contacts seen at once.
struct Impact {
  double eps;
  long max_contacts;
};
Impact drop(const rt::Model& m, const Vec3& xy, double v, double phase) {
  rt::State s = rt::make_state(m);
  const double r = m.grain_radius[0];
  s.pos[0] = Vec3(xy.x(), xy.y(), r + (3.0 + phase) * v * m.dt);
  s.vel[0] = Vec3(0, 0, -v);
  Impact out{0, 0};
  for (int k = 0; k < 100000; ++k) {
    rt::step(m, s);
    out.max_contacts = std::max(out.max_contacts, s.stats.body_contacts + s.stats.wall_contacts);
    if (s.pos[0].z() > r + 5 * v * m.dt && s.vel[0].z() > 0) break;
  }
  out.eps = s.vel[0].z() / v;
  return out;
}

}  // namespace

// 1. Normal impacts on a tessellated plane (20 x 20 cells of 2 mm, 800
// triangles, with shared or STL-style repeated vertices) give the plane
// wall's restitution on face interiors, on cell edges, on diagonals and on
// vertices, at 10 entry phases. The contact is the same law with the same
// normal and overlap: on a face the plane distance is exact (the plane is
// z = 0, its normal (0, 0, 1) exactly), on an edge or vertex directly below
// the centre the distance differs from it by rounding (1e-16 relative); the
// only other difference is sqrt(m*) = sqrt(1/(1/m)) against sqrt(m) (one
// rounding). Over a contact of 30 steps these give a relative restitution
// difference of order 1e-15; the bound 1e-12 leaves a factor of 1000.
TEST(MeshContact, ImpactsOnATessellatedPlaneMatchThePlaneWall) {
  const double r = 0.005;
  const rt::Model wall = plane_scene(nullptr, r, 0.5, 0.5, Vec3::Zero(), 30);
  double worst = 0;
  for (bool stl : {false, true}) {
    const TriangleMesh mesh = plane_mesh(20, 0.02, stl);
    const rt::Model m = plane_scene(&mesh, r, 0.5, 0.5, Vec3::Zero(), 30);
    ASSERT_EQ(rt::mesh_surface_vertices(*m.bodies[0].surfaces[0]), 21 * 21) << "welded";
    const TriangleMesh ref = plane_mesh(20, 0.02, false);
    auto v = [&](int i, int j) { return ref.vertices[j * 21 + i]; };
    const std::vector<std::pair<const char*, Vec3>> points = {
        {"face", (v(10, 10) + v(11, 10) + v(11, 11)) / 3.0},
        {"face near an edge", v(7, 4) + Vec3(0.001, 1e-7, 0)},
        {"cell edge", 0.5 * (v(10, 10) + v(11, 10))},
        {"diagonal", 0.5 * (v(3, 12) + v(4, 13))},
        {"vertex", v(10, 10)},
        {"vertex", v(6, 13)},
    };
    for (const auto& [what, p] : points)
      for (int ph = 0; ph < 10; ++ph) {
        const Impact a = drop(wall, p, 0.5, 0.1 * ph), b = drop(m, p, 0.5, 0.1 * ph);
        const double d = std::fabs(b.eps - a.eps) / a.eps;
        worst = std::max(worst, d);
        EXPECT_LE(d, 1e-12) << what << (stl ? " (STL vertices)" : "") << " phase " << ph << ": wall " << a.eps
                            << ", mesh " << b.eps;
        EXPECT_EQ(b.max_contacts, 1) << what << " phase " << ph;
        EXPECT_NEAR(a.eps, 0.5, 0.03);
      }
  }
  RecordProperty("max_relative_restitution_difference", rt::test::figure(worst));
  std::printf("largest relative restitution difference mesh / wall: %.3g\n", worst);
}

// 2. A grain sliding and then rolling over the tessellated plane under
// gravity, along a line of vertices and cell edges and obliquely across
// faces, edges and diagonals: normal force, tangential spring and position
// follow the plane wall's at every step (one contact throughout, its springs
// carried across triangle boundaries). Differences stay at rounding level:
// the bound 1e-12 of the normal force (relative) and 1e-12 of the spring
// length (relative to the largest spring) is far above the ~1e-15 seen.
TEST(MeshContact, SlidingAcrossTrianglesMatchesThePlaneWall) {
  const double r = 0.005;
  const Vec3 g(0, 0, -9.81);
  const rt::Model wall = plane_scene(nullptr, r, 0.5, 0.3, g, 30);
  const TriangleMesh mesh = plane_mesh(20, 0.02, true);
  const rt::Model m = plane_scene(&mesh, r, 0.5, 0.3, g, 30);
  const double mass = m.grain_mass[0];
  const double rest = r - mass * 9.81 / m.kn;  // resting height
  const TriangleMesh ref = plane_mesh(20, 0.02, false);
  double worst_fn = 0, worst_spring = 0, worst_pos = 0;
  long crossings = 0;
  for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(0.8, 0.6, 0)}) {
    rt::State a = rt::make_state(wall), b = rt::make_state(m);
    const Vec3 start = dir.x() == 1 ? Vec3(-0.016, ref.vertices[21 * 9].y(), rest) : Vec3(-0.014, -0.012, rest);
    a.pos[0] = b.pos[0] = start;
    a.vel[0] = b.vel[0] = 0.3 * dir;
    double max_spring = 0;
    int last_tri = -1;
    std::vector<int> tris;
    std::vector<rt::MeshHit> hits;
    for (int k = 0; k < 12000; ++k) {
      rt::step(wall, a);
      rt::step(m, b);
      ASSERT_EQ(a.stats.wall_contacts, 1);
      ASSERT_EQ(b.stats.body_contacts, 1) << "step " << k;
      const double fa = a.force[0].z(), fb = b.force[0].z();
      worst_fn = std::max(worst_fn, std::fabs(fb - fa) / std::fabs(fa));
      const rt::MeshSlot* sl = &b.body_grains.mesh_slots[b.body_grains.mesh_first[0]];
      int live = 0;
      Vec3 spring = Vec3::Zero();
      for (int q = 0; q < rt::kMeshSlots; ++q)
        if (sl[q].touching) {
          ++live;
          spring = sl[q].spring_t;
        }
      ASSERT_EQ(live, 1) << "step " << k;
      max_spring = std::max(max_spring, a.wall_pairs.spring_t[0].norm());
      worst_spring = std::max(worst_spring, (spring - a.wall_pairs.spring_t[0]).norm() / std::max(max_spring, 1e-300));
      worst_pos = std::max(worst_pos, (b.pos[0] - a.pos[0]).norm() / r);
      rt::mesh_hits(*m.bodies[0].surfaces[0], b.pos[0], r, tris, hits);
      ASSERT_EQ(hits.size(), 1u);
      if (hits[0].tri != last_tri) ++crossings;
      last_tri = hits[0].tri;
    }
    EXPECT_GT(max_spring, 0);
    EXPECT_GT((b.pos[0] - start).norm(), 0.008) << "the grain must cross many triangles";
  }
  RecordProperty("max_normal_force_difference", rt::test::figure(worst_fn));
  RecordProperty("max_spring_difference", rt::test::figure(worst_spring));
  RecordProperty("triangle_changes", std::to_string(crossings));
  std::printf("relative differences mesh / wall: normal force %.3g, spring %.3g, position %.3g (%ld triangle changes)\n",
              worst_fn, worst_spring, worst_pos, crossings);
  EXPECT_GT(crossings, 10);
  EXPECT_LE(worst_fn, 1e-12);
  EXPECT_LE(worst_spring, 1e-12);
  EXPECT_LE(worst_pos, 1e-12);
}

// 3. One contact per touched face in a concave corner (two or three
// perpendicular faces of 4 x 4 cells each), with the force of each face;
// one contact on a convex edge and one on a convex corner of a box.
TEST(MeshContact, OneContactPerFaceInACornerAndOnePerConvexFeature) {
  const double r = 0.005, delta = 1e-4;
  // Inside corner: floor z = 0, walls x = 0 and y = 0, normals into x, y, z > 0.
  TriangleMesh corner;
  {
    const TriangleMesh floor = plane_mesh(4, 0.01, false);
    auto add = [&corner, &floor](auto map) {
      const int base = static_cast<int>(corner.vertices.size());
      for (const Vec3& p : floor.vertices) corner.vertices.push_back(map(p + Vec3(0.01, 0.01, 0)));
      for (const auto& t : floor.triangles) corner.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    };
    add([](const Vec3& p) { return p; });                               // z = 0, normal +z
    add([](const Vec3& p) { return Vec3(p.z(), p.x(), p.y()); });       // x = 0, normal +x
    add([](const Vec3& p) { return Vec3(p.y(), p.z(), p.x()); });       // y = 0, normal +y
  }
  rt::Model m;
  add_materials(m, 0.5, 0.5);
  m.gravity = Vec3::Zero();
  m.kn = 1e4;
  m.dt = 1e-5;
  rt::add_grain(m, r, 0);
  add_fixed_mesh(m, corner);
  rt::finalize_model(m);
  struct Case {
    const char* what;
    Vec3 pos;
    long contacts;
    Vec3 force;  // expected, kn delta per face
  };
  const double a = r - delta, f = m.kn * delta;
  for (const Case& c : {Case{"three faces", Vec3(a, a, a), 3, Vec3(f, f, f)},
                        Case{"two faces", Vec3(a, 0.007, a), 2, Vec3(f, 0, f)},
                        Case{"one face", Vec3(0.007, 0.008, a), 1, Vec3(0, 0, f)}}) {
    rt::State s = rt::make_state(m);
    s.pos[0] = c.pos;
    rt::prime(m, s);
    EXPECT_EQ(s.stats.body_contacts, c.contacts) << c.what;
    EXPECT_LE((s.force[0] - c.force).norm(), 1e-12 * f) << c.what << ": " << s.force[0].transpose();
    RecordProperty(std::string("contacts_") + (c.contacts == 3 ? "3" : c.contacts == 2 ? "2" : "1"),
                   std::to_string(s.stats.body_contacts));
  }
  // Outside a box: a convex edge and a convex corner are one contact each.
  rt::Model mb;
  add_materials(mb, 0.5, 0.5);
  mb.gravity = Vec3::Zero();
  mb.kn = 1e4;
  mb.dt = 1e-5;
  rt::add_grain(mb, r, 0);
  add_fixed_mesh(mb, rt::test::box_mesh(Vec3(-0.01, -0.01, -0.01), Vec3(0.01, 0.01, 0.01), 3));
  rt::finalize_model(mb);
  const double e = (r - delta) / std::sqrt(2.0), v3 = (r - delta) / std::sqrt(3.0);
  for (const Case& c : {Case{"convex edge", Vec3(0.01 + e, 0.003, 0.01 + e), 1, Vec3(f, 0, f) / std::sqrt(2.0)},
                        Case{"convex corner", Vec3(0.01 + v3, 0.01 + v3, 0.01 + v3), 1, Vec3(f, f, f) / std::sqrt(3.0)},
                        Case{"face", Vec3(0.004, 0.001, 0.01 + a), 1, Vec3(0, 0, f)}}) {
    rt::State s = rt::make_state(mb);
    s.pos[0] = c.pos;
    rt::prime(mb, s);
    EXPECT_EQ(s.stats.body_contacts, c.contacts) << c.what;
    EXPECT_LE((s.force[0] - c.force).norm(), 1e-9 * f) << c.what << ": " << s.force[0].transpose();
  }
}

// 4. No tunnelling: a 1.75 mm grain at 300 m/s against a 1 mm thick closed
// plate (20 x 20 mm, faces of 4 x 4 cells) at the sampler's stiffness for
// 300 m/s, k_n = 5.47e6 N/m (300/50)^2, and at the largest step the scenario
// reader accepts (4 steps per grain–body contact; fewer is refused), face
// on, edge on (the 1 mm side face, and the long edge at 45 degrees) and
// corner on. The grain always ends on the side it came from.
TEST(MeshContact, NoTunnellingThroughAThinPlateAt300MetresPerSecond) {
  const double r = 0.00175, v = 300;
  rt::Model m;
  add_materials(m, 0.5, 0.5);
  m.gravity = Vec3::Zero();
  m.kn = 5.47e6 * (v / 50) * (v / 50);
  rt::add_grain(m, r, 0);
  add_fixed_mesh(m, rt::test::box_mesh(Vec3(-0.01, -0.01, -0.0005), Vec3(0.01, 0.01, 0.0005), 4));
  m.dt = 1;  // set below from the resolution report
  rt::finalize_model(m);
  const double mass = m.grain_mass[0];
  const double tc = rt::linear_contact_time(mass, m.kn, 0.5);
  m.dt = tc / 4;  // the extreme accepted (steps per contact >= 4)
  const auto res = rt::pair_resolution(m, v);
  ASSERT_EQ(res.size(), 1u);
  EXPECT_NEAR(res[0].steps, 4.0, 1e-9);
  RecordProperty("kn", rt::test::figure(m.kn));
  RecordProperty("dt", rt::test::figure(m.dt));
  struct Shot {
    const char* what;
    Vec3 target;  // aim point on the plate
    Vec3 dir;     // direction of flight
  };
  const Vec3 d45 = Vec3(-1, 0, -1).normalized(), d3 = Vec3(-1, -1, -1).normalized();
  for (const Shot& sh : {Shot{"face", Vec3(0.0012, 0.0007, 0.0005), Vec3(0, 0, -1)},
                         Shot{"face on a vertex", Vec3(0.0, 0.0, 0.0005), Vec3(0, 0, -1)},
                         Shot{"side face (edge on)", Vec3(0.01, 0.0003, 0.0), Vec3(-1, 0, 0)},
                         Shot{"long edge at 45 degrees", Vec3(0.01, 0.0021, 0.0005), d45},
                         Shot{"corner", Vec3(0.01, 0.01, 0.0005), d3},
                         Shot{"oblique on the face", Vec3(0.002, 0.001, 0.0005), Vec3(-0.5, 0.2, -1).normalized()}}) {
    rt::State s = rt::make_state(m);
    s.pos[0] = sh.target - (r + 20 * v * m.dt) * sh.dir;
    s.vel[0] = v * sh.dir;
    double deepest = 0;
    long steps = 0;
    for (; steps < 2000; ++steps) {
      rt::step(m, s);
      deepest = std::max(deepest, s.stats.max_overlap_ratio);
      if (s.vel[0].dot(sh.dir) < 0 && (s.pos[0] - sh.target).dot(sh.dir) < -(r + 5 * v * m.dt)) break;
    }
    const double side = (s.pos[0] - sh.target).dot(sh.dir);
    EXPECT_LT(side, -r) << sh.what << ": the grain passed through or stuck (" << s.pos[0].transpose() << ")";
    EXPECT_LT(s.vel[0].dot(sh.dir), 0) << sh.what;
    EXPECT_LT(steps, 2000) << sh.what;
    std::printf("%-26s rebound %.3g of the speed, deepest overlap %.3g r, %ld steps\n", sh.what,
                -s.vel[0].dot(sh.dir) / v, deepest, steps);
  }
}

// 5. A free box made of a triangle mesh resting on four glued grains under
// gravity: the same motion, contacts and forces as the box as a Box shape
// (up to rounding), and the grains take the opposite of the body's force.
TEST(MeshContact, MeshBoxOnGrainsMatchesTheBoxShape) {
  const double r = 0.005;
  const Vec3 half(0.02, 0.015, 0.01);
  auto scene = [&](bool mesh) {
    rt::Model m;
    add_materials(m, 0.5, 0.5);
    m.gravity = Vec3(0, 0, -9.81);
    const double mass = 4.0 / 3.0 * kPi * r * r * r * 2430;
    m.kn = rt::kn_rule(mass, 1.0, 0.01 * r);
    m.dt = rt::dt_rule(mass, m.kn, 30);
    for (int k = 0; k < 4; ++k) rt::add_grain(m, r, 0, true);
    BodyModel b;
    b.name = "box";
    b.mass = 0.05;
    b.inertia = Vec3(half.y() * half.y() + half.z() * half.z(), half.x() * half.x() + half.z() * half.z(),
                     half.x() * half.x() + half.y() * half.y()) *
                (b.mass / 3);
    b.material = 1;
    if (mesh) {
      b.meshes = {rt::test::box_mesh(-half, half, 2)};
      b.shapes = {mesh_shape()};
    } else {
      Shape s;
      s.type = ShapeType::Box;
      s.size = half;
      b.shapes = {s};
    }
    m.bodies.push_back(b);
    rt::finalize_model(m);
    return m;
  };
  const rt::Model mm = scene(true), mbox = scene(false);
  auto start = [&](const rt::Model& m) {
    rt::State s = rt::make_state(m);
    const Vec3 xy[4] = {Vec3(-0.012, -0.009, 0), Vec3(0.013, -0.008, 0), Vec3(0.011, 0.01, 0), Vec3(-0.014, 0.007, 0)};
    for (int k = 0; k < 4; ++k) s.pos[k] = xy[k];
    s.bodies[0].pos = Vec3(0.001, 0.0005, r + half.z() + 2e-4);
    s.bodies[0].q = rt::Quat(Eigen::AngleAxisd(0.01, Vec3(0.3, 1, 0).normalized()));
    rt::set_body_velocity(m.bodies[0], s.bodies[0], Vec3(0.01, 0, -0.05), Vec3(0, 0.2, 0));
    return s;
  };
  rt::State a = start(mbox), b = start(mm);
  double worst_force = 0, worst_pos = 0, worst_balance = 0;
  for (int k = 0; k < 20000; ++k) {
    rt::step(mbox, a);
    rt::step(mm, b);
    ASSERT_EQ(a.stats.body_contacts, b.stats.body_contacts) << "step " << k;
    const double scale = 0.05 * 9.81;
    worst_force = std::max(worst_force, (b.bodies[0].force - a.bodies[0].force).norm() / scale);
    worst_pos = std::max(worst_pos, (b.bodies[0].pos - a.bodies[0].pos).norm() / r);
    Vec3 sum = Vec3::Zero();
    for (int i = 0; i < 4; ++i) sum += b.force[i];
    worst_balance = std::max(worst_balance, (sum + b.bodies[0].force).norm() / scale);
  }
  EXPECT_EQ(b.stats.body_contacts, 4) << "resting on the four grains";
  EXPECT_NEAR(b.bodies[0].force.z(), 0.05 * 9.81, 0.02 * 0.05 * 9.81) << "at rest, the grains carry the weight";
  RecordProperty("max_body_force_difference", rt::test::figure(worst_force));
  RecordProperty("max_momentum_balance_error", rt::test::figure(worst_balance));
  std::printf("mesh box / Box shape: force difference %.3g of the weight, position %.3g r; balance %.3g\n", worst_force,
              worst_pos, worst_balance);
  EXPECT_LE(worst_force, 1e-9);
  EXPECT_LE(worst_pos, 1e-9);
  EXPECT_LE(worst_balance, 1e-12);
}

// The slots of the grain–mesh contacts are saved and restored by a
// checkpoint: a run continued from one is bit-identical, and an edit that
// removes other grains keeps them.
TEST(MeshContact, CheckpointKeepsTheContactHistory) {
  const double r = 0.005;
  const TriangleMesh mesh = plane_mesh(20, 0.02, false);
  rt::Model m = plane_scene(&mesh, r, 0.5, 0.3, Vec3(0, 0, -9.81), 30);
  rt::State s = rt::make_state(m);
  s.pos[0] = Vec3(-0.01, 0.0031, r - m.grain_mass[0] * 9.81 / m.kn);
  s.vel[0] = Vec3(0.08, 0.01, 0);
  for (int k = 0; k < 300; ++k) rt::step(m, s);
  ASSERT_EQ(s.stats.body_contacts, 1);
  const std::string path = ::testing::TempDir() + "mesh_contact.ckpt";
  rt::save_checkpoint(path, m, s);
  rt::State t = rt::load_checkpoint(path, m);
  ASSERT_EQ(t.body_grains.mesh_slots.size(), s.body_grains.mesh_slots.size());
  EXPECT_EQ(t.body_grains.mesh_first, s.body_grains.mesh_first);
  for (int k = 0; k < 500; ++k) {
    rt::step(m, s);
    rt::step(m, t);
  }
  EXPECT_EQ(std::memcmp(s.pos.data(), t.pos.data(), sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(s.body_grains.mesh_slots.data(), t.body_grains.mesh_slots.data(),
                        s.body_grains.mesh_slots.size() * sizeof(rt::MeshSlot)),
            0);
  std::remove(path.c_str());
}

// Removing grains keeps the slots of the surviving grains' mesh contacts.
TEST(MeshContact, RemovingGrainsKeepsTheSlots) {
  const double r = 0.005;
  const TriangleMesh mesh = plane_mesh(20, 0.02, false);
  rt::Model m;
  add_materials(m, 0.5, 0.3);
  m.gravity = Vec3(0, 0, -9.81);
  const double mass = 4.0 / 3.0 * kPi * r * r * r * 2430;
  m.kn = rt::kn_rule(mass, 1.0, 0.01 * r);
  m.dt = rt::dt_rule(mass, m.kn, 30);
  for (int k = 0; k < 3; ++k) rt::add_grain(m, r, 0);
  add_fixed_mesh(m, mesh);
  rt::finalize_model(m);
  rt::State s = rt::make_state(m);
  for (int k = 0; k < 3; ++k) {
    s.pos[k] = Vec3(-0.012 + 0.012 * k, 0.001 * k, r - mass * 9.81 / m.kn);
    s.vel[k] = Vec3(0.1, 0.02 * k, 0);
  }
  for (int k = 0; k < 200; ++k) rt::step(m, s);
  const rt::BodyGrainList& bl = s.body_grains;
  ASSERT_EQ(bl.size(), 3);
  std::vector<rt::MeshSlot> kept(bl.mesh_slots.begin() + bl.mesh_first[2], bl.mesh_slots.begin() + bl.mesh_first[2] + rt::kMeshSlots);
  rt::remove_grains(m, s, {0, 1, 0});
  ASSERT_EQ(s.body_grains.size(), 2);
  EXPECT_EQ(s.body_grains.mesh_first[1], rt::kMeshSlots);
  EXPECT_EQ(std::memcmp(&s.body_grains.mesh_slots[rt::kMeshSlots], kept.data(), sizeof(rt::MeshSlot) * rt::kMeshSlots), 0);
  for (int k = 0; k < 10; ++k) rt::step(m, s);
  EXPECT_EQ(s.stats.body_contacts, 2);
}
