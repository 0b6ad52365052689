// Body–body contact through Bullet's narrow phase (docs/model.md §6): exact points
// and depths for resting shapes, the pair's stiffness independent of the
// number of points, restitution of head-on and face-on impacts, and energy of
// a box dropped on a rigid plate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "regolith_twin/core/body_collision.hpp"
#include "regolith_twin/core/step.hpp"
#include "test_support.hpp"

namespace {

using rt::BodyModel;
using rt::BodyState;
using rt::Mat3;
using rt::Model;
using rt::Quat;
using rt::Shape;
using rt::ShapeType;
using rt::State;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

Shape shape(ShapeType type, const Vec3& size, const Vec3& pos = Vec3::Zero(), const Quat& rot = Quat::Identity()) {
  Shape sh;
  sh.type = type;
  sh.size = size;
  sh.pos = pos;
  sh.rot = rot;
  return sh;
}

// A fixed plate whose top face is the plane z = 0 (a large thin box).
BodyModel plate(double half = 2.0) {
  BodyModel b;
  b.name = "plate";
  b.fixed = true;
  b.shapes.push_back(shape(ShapeType::Box, Vec3(half, half, 0.1), Vec3(0, 0, -0.1)));
  return b;
}

// A solid box of density 1000 kg/m^3 with half extents h.
BodyModel box(const Vec3& h, const std::string& name = "box") {
  BodyModel b;
  b.name = name;
  b.mass = 8 * h.prod() * 1000;
  b.inertia = b.mass / 3 * Vec3(h.y() * h.y() + h.z() * h.z(), h.x() * h.x() + h.z() * h.z(),
                                 h.x() * h.x() + h.y() * h.y());
  b.shapes.push_back(shape(ShapeType::Box, h));
  return b;
}

BodyModel ball(double r, double mass) {
  BodyModel b;
  b.name = "ball";
  b.mass = mass;
  b.inertia = Vec3::Constant(0.4 * mass * r * r);
  b.shapes.push_back(shape(ShapeType::Sphere, Vec3::Constant(r)));
  return b;
}

rt::TriangleMesh cube_mesh(double a) {
  rt::TriangleMesh tm;
  for (int k = 0; k < 8; ++k) tm.vertices.push_back(Vec3(k & 1 ? a : -a, k & 2 ? a : -a, k & 4 ? a : -a));
  tm.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                  {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return tm;
}

Model make_model(std::vector<BodyModel> bodies, double eps, double mu, double kn, double dt) {
  Model m;
  rt::Material mat = rt::test::simple_material("hull", 2000, eps, eps, mu);
  mat.structure = true;
  mat.own_friction = true;
  m.materials = {mat};
  m.kn = kn;
  m.body_kn = kn;
  m.dt = dt;
  m.gravity = Vec3::Zero();
  m.bodies = std::move(bodies);
  for (BodyModel& b : m.bodies) rt::finalize_body(b);
  rt::finalize_model(m);
  return m;
}

State body_state(const Model& m) {
  State s = rt::make_state(m);
  s.bodies.resize(m.bodies.size());
  return s;
}

// Place body i at rest.
void place(const Model& m, State& s, int i, const Vec3& pos, const Quat& q = Quat::Identity()) {
  s.bodies[i].pos = pos;
  s.bodies[i].q = q;
  rt::set_body_velocity(m.bodies[i], s.bodies[i], Vec3::Zero(), Vec3::Zero());
}

// Forces of the current pose only (velocities zero, springs fresh).
void forces(const Model& m, State& s) {
  for (BodyState& b : s.bodies) {
    b.force.setZero();
    b.torque.setZero();
  }
  rt::body_body_forces(m, s);
}

// --- (a) resting contacts: exact points, total force k_n x for any n -------------

struct Resting {
  long points;
  Vec3 force, torque;  // on the upper body (index 1)
  double min_depth, max_depth;
};

Resting rest(const BodyModel& upper, const Vec3& pos, const Quat& q, double kn = 1e6) {
  const Model m = make_model({plate(), upper}, 0.5, 0.5, kn, 1e-5);
  State s = body_state(m);
  place(m, s, 0, Vec3::Zero());
  place(m, s, 1, pos, q);
  forces(m, s);
  Resting r{s.stats.body_body_contacts, s.bodies[1].force, s.bodies[1].torque, 1e300, -1e300};
  for (const auto& c : s.body_points) {
    r.min_depth = std::min(r.min_depth, c.overlap);
    r.max_depth = std::max(r.max_depth, c.overlap);
  }
  // Reaction on the plate.
  EXPECT_NEAR((s.bodies[0].force + s.bodies[1].force).norm(), 0.0, 1e-12 * kn);
  return r;
}

TEST(BodyCollision, BoxFaceDownOnPlateGetsFourExactPointsAndTotalForceKnX) {
  const double kn = 1e6, x = 1e-3;
  const Vec3 h(0.3, 0.2, 0.1);
  for (double yaw : {0.0, 0.3, 1.1}) {
    const Quat q(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    const Resting r = rest(box(h), Vec3(0.05, -0.02, h.z() - x), q, kn);
    EXPECT_EQ(r.points, 4) << "yaw " << yaw;
    EXPECT_NEAR(r.min_depth, x, 1e-12) << "yaw " << yaw;
    EXPECT_NEAR(r.max_depth, x, 1e-12) << "yaw " << yaw;
    EXPECT_NEAR(r.force.z(), kn * x, 1e-9 * kn * x) << "yaw " << yaw;
    EXPECT_NEAR(r.force.head<2>().norm(), 0.0, 1e-9 * kn * x);
    EXPECT_NEAR(r.torque.norm(), 0.0, 1e-9 * kn * x * h.norm()) << "yaw " << yaw;
  }
}

TEST(BodyCollision, EveryPointCarriesAFixedShareOfThePairStiffness) {
  const double kn = 1e6, x = 5e-4;
  // A sphere: one point with the pair's k_n.
  const Resting sphere = rest(ball(0.1, 2.0), Vec3(0, 0, 0.1 - x), Quat::Identity(), kn);
  EXPECT_EQ(sphere.points, 1);
  EXPECT_NEAR(sphere.force.z(), kn * x, 1e-9 * kn * x);

  // A box: each point carries k_n/4, so the face (4 points) has k_n, an edge
  // (2 points) k_n/2, a corner k_n/4.
  const Vec3 h(0.2, 0.2, 0.2);
  const Resting on_face = rest(box(h), Vec3(0, 0, h.z() - x), Quat::Identity(), kn);
  EXPECT_EQ(on_face.points, 4);
  EXPECT_NEAR(on_face.force.z(), kn * x, 1e-9 * kn * x);

  const Quat edge(Eigen::AngleAxisd(kPi / 4, Vec3::UnitY()));  // lowest edge along y, h sqrt(2) below the centre
  const Resting on_edge = rest(box(h), Vec3(0, 0, h.x() * std::sqrt(2.0) - x), edge, kn);
  EXPECT_EQ(on_edge.points, 2);
  EXPECT_NEAR(on_edge.min_depth, x, 1e-12);
  EXPECT_NEAR(on_edge.max_depth, x, 1e-12);
  EXPECT_NEAR(on_edge.force.z(), kn * x / 2, 1e-9 * kn * x);
  EXPECT_NEAR(on_edge.torque.norm(), 0.0, 1e-9 * kn * x);

  const Quat corner = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3(0, 0, -1));
  const Resting on_corner = rest(box(h), Vec3(0, 0, h.norm() - x), corner, kn);
  EXPECT_EQ(on_corner.points, 1);
  EXPECT_NEAR(on_corner.max_depth, x, 1e-12);
  EXPECT_NEAR(on_corner.force.z(), kn * x / 4, 1e-9 * kn * x);
}

TEST(BodyCollision, CurvedAndMeshShapesRestAtTheirExactDepth) {
  const double kn = 1e6, x = 1e-3;
  // Cylinder standing on its end cap (several points from the perturbed queries).
  {
    BodyModel c;
    c.name = "can";
    c.mass = 3;
    c.inertia = Vec3(0.02, 0.02, 0.015);
    c.shapes.push_back(shape(ShapeType::Cylinder, Vec3(0.1, 0.1, 0.15)));
    const Resting r = rest(c, Vec3(0, 0, 0.15 - x), Quat::Identity(), kn);
    EXPECT_GE(r.points, 3);
    EXPECT_NEAR(r.min_depth, x, 1e-9);
    EXPECT_NEAR(r.max_depth, x, 1e-9);
    EXPECT_NEAR(r.force.z(), kn * x, 1e-6 * kn * x);
    ::testing::Test::RecordProperty("cylinder_points", std::to_string(r.points));
  }
  // Ellipsoid at an arbitrary attitude: lowest point at |A R^T e_z| below the centre.
  {
    BodyModel e;
    e.name = "egg";
    e.mass = 3;
    e.inertia = Vec3(0.02, 0.03, 0.04);
    const Vec3 semi(0.3, 0.2, 0.1);
    e.shapes.push_back(shape(ShapeType::Ellipsoid, semi));
    const Quat q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    const Mat3 R = q.toRotationMatrix();
    const double low = (R.row(2).transpose().cwiseProduct(semi)).norm();
    const Resting r = rest(e, Vec3(0.1, 0.2, low - x), q, kn);
    EXPECT_GE(r.points, 1);
    EXPECT_NEAR(r.max_depth, x, 1e-8);
    EXPECT_NEAR(r.force.z(), kn * x, 1e-5 * kn * x);
    ::testing::Test::RecordProperty("ellipsoid_depth_error", rt::test::figure(std::fabs(r.max_depth - x)));
  }
  // A moving mesh (a cube, as its convex hull) face-down on the plate.
  {
    BodyModel b = box(Vec3(0.2, 0.2, 0.2), "cube_mesh");
    b.shapes.clear();
    b.meshes.push_back(cube_mesh(0.2));
    Shape sh = shape(ShapeType::Mesh, Vec3::Zero());
    sh.mesh = 0;
    b.shapes.push_back(sh);
    const Resting r = rest(b, Vec3(0, 0, 0.2 - x), Quat(Eigen::AngleAxisd(0.4, Vec3::UnitZ())), kn);
    EXPECT_EQ(r.points, 4);
    EXPECT_NEAR(r.min_depth, x, 1e-9);
    EXPECT_NEAR(r.max_depth, x, 1e-9);
    EXPECT_NEAR(r.force.z(), kn * x, 1e-6 * kn * x);
  }
}

TEST(BodyCollision, BoxOnAFixedTriangleMeshFloor) {
  const double kn = 1e6, x = 1e-3;
  BodyModel floor;
  floor.name = "floor";
  floor.fixed = true;
  rt::TriangleMesh tm;
  tm.vertices = {Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0)};
  tm.triangles = {{0, 1, 2}, {0, 2, 3}};
  floor.meshes.push_back(tm);
  Shape sh = shape(ShapeType::Mesh, Vec3::Zero());
  sh.mesh = 0;
  floor.shapes.push_back(sh);
  const Vec3 h(0.3, 0.2, 0.1);
  const Model m = make_model({floor, box(h)}, 0.5, 0.5, kn, 1e-5);
  State s = body_state(m);
  place(m, s, 0, Vec3::Zero());
  place(m, s, 1, Vec3(0.3, 0.1, h.z() - x), Quat(Eigen::AngleAxisd(0.2, Vec3::UnitZ())));
  forces(m, s);
  EXPECT_GE(s.stats.body_body_contacts, 3);
  for (const auto& c : s.body_points) EXPECT_NEAR(c.overlap, x, 1e-9);
  EXPECT_NEAR(s.bodies[1].force.z(), kn * x, 1e-6 * kn * x);
  EXPECT_NEAR(s.bodies[1].torque.head<2>().norm(), 0.0, 1e-6 * kn * x);
}

TEST(BodyCollision, AFaceOnAFaceKeepsFourPoints) {
  // A moving mesh cube turned 45 degrees on a fixed pedestal of the same
  // footprint: the overlap is an octagon, reduced to four points.
  const double kn = 1e6, x = 1e-3, a = 0.2;
  BodyModel pedestal;
  pedestal.name = "pedestal";
  pedestal.fixed = true;
  pedestal.shapes.push_back(shape(ShapeType::Box, Vec3(a, a, 0.1), Vec3(0, 0, -0.1)));
  BodyModel cube = box(Vec3(a, a, a), "cube_mesh");
  cube.shapes.clear();
  cube.meshes.push_back(cube_mesh(a));
  Shape sh = shape(ShapeType::Mesh, Vec3::Zero());
  sh.mesh = 0;
  cube.shapes.push_back(sh);
  const Model m = make_model({pedestal, cube}, 0.5, 0.5, kn, 1e-5);
  State s = body_state(m);
  place(m, s, 0, Vec3::Zero());
  place(m, s, 1, Vec3(0, 0, a - x), Quat(Eigen::AngleAxisd(kPi / 4, Vec3::UnitZ())));
  forces(m, s);
  EXPECT_EQ(s.stats.body_body_contacts, 4);
  for (const auto& c : s.body_points) EXPECT_NEAR(c.overlap, x, 1e-9);
  EXPECT_NEAR(s.bodies[1].force.z(), kn * x, 1e-6 * kn * x);
}

// --- (b) restitution of impacts ------------------------------------------------------

TEST(BodyCollision, HeadOnSphereSphereReproducesRestitution) {
  for (double eps : {0.3, 0.6, 0.9}) {
    const double kn = 1e5, m1 = 1.0, m2 = 2.0, r = 0.1;
    const double mstar = m1 * m2 / (m1 + m2);
    const double tc = rt::linear_contact_time(mstar, kn, eps);
    const Model m = make_model({ball(r, m1), ball(r, m2)}, eps, 0.5, kn, tc / 200);
    State s = body_state(m);
    place(m, s, 0, Vec3(0, 0, 0));
    place(m, s, 1, Vec3(2 * r + 1e-4, 0, 0));
    const Vec3 u0(1.0, 0, 0);
    rt::set_body_velocity(m.bodies[0], s.bodies[0], u0 * (m2 / (m1 + m2)), Vec3::Zero());
    rt::set_body_velocity(m.bodies[1], s.bodies[1], -u0 * (m1 / (m1 + m2)), Vec3::Zero());
    bool touched = false;
    for (int k = 0; k < 2000; ++k) {
      rt::step(m, s);
      touched = touched || s.stats.body_body_contacts > 0;
      if (touched && s.stats.body_body_contacts == 0) break;
    }
    ASSERT_TRUE(touched);
    const double v_after = (s.bodies[1].vel - s.bodies[0].vel).x();
    EXPECT_NEAR(v_after / u0.x(), eps, 0.01 * eps) << "eps " << eps;
    EXPECT_NEAR(s.bodies[0].omega.norm() + s.bodies[1].omega.norm(), 0.0, 1e-9);
    ::testing::Test::RecordProperty("sphere_eps_" + rt::test::figure(eps), rt::test::figure(v_after / u0.x()));
  }
}

TEST(BodyCollision, FaceDownBoxImpactReproducesRestitutionWithFourPoints) {
  for (double eps : {0.3, 0.6, 0.9}) {
    const double kn = 1e6;
    const Vec3 h(0.3, 0.2, 0.1);
    BodyModel b = box(h);
    const double tc = rt::linear_contact_time(b.mass, kn, eps);
    const Model m = make_model({plate(), b}, eps, 0.5, kn, tc / 200);
    State s = body_state(m);
    place(m, s, 0, Vec3::Zero());
    place(m, s, 1, Vec3(0, 0, h.z() + 1e-4), Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ())));
    rt::set_body_velocity(m.bodies[1], s.bodies[1], Vec3(0, 0, -1), Vec3::Zero());
    bool touched = false;
    long max_points = 0, min_points = 100;
    for (int k = 0; k < 2000; ++k) {
      rt::step(m, s);
      const long n = s.stats.body_body_contacts;
      if (n > 0) {
        touched = true;
        max_points = std::max(max_points, n);
        min_points = std::min(min_points, n);
      }
      if (touched && n == 0) break;
    }
    ASSERT_TRUE(touched);
    EXPECT_EQ(min_points, 4);
    EXPECT_EQ(max_points, 4);
    EXPECT_NEAR(s.bodies[1].vel.z(), eps, 0.01 * eps) << "eps " << eps;
    EXPECT_NEAR(s.bodies[1].omega.norm(), 0.0, 1e-9);
  }
}



// --- (c) energy of a box dropped on a rigid plate --------------------------------------

double body_energy(const Model& m, const State& s, int i) {
  const BodyModel& b = m.bodies[i];
  const BodyState& st = s.bodies[i];
  return rt::body_lin_energy(b, st) + rt::body_rot_energy(b, st) - b.mass * m.gravity.dot(st.pos);
}

struct DropResult {
  double first_out = 0;   // E / E_in at the first contact-free instant after the first contact
  double max_out = 0;     // max of E / E_in over every later contact-free instant
  double min_out = 1e300; // min of the same
  long max_points = 0;
};

// A box of half extents h dropped at attitude q, lowest corner 1 cm above the
// plate, falling at 1 m/s; followed for 0.15 s (one bounce and more).
DropResult drop(double eps, double mu, const Quat& q) {
  const double kn = 1e7;
  const Vec3 h(0.3, 0.2, 0.1);
  BodyModel b = box(h);
  const double tc = rt::linear_contact_time(b.mass / 4, kn, eps);  // a corner impact: a fraction of M
  Model m = make_model({plate(), b}, eps, mu, kn, tc / 100);
  m.gravity = Vec3(0, 0, -9.81);
  State s = body_state(m);
  place(m, s, 0, Vec3::Zero());
  const Mat3 R = q.toRotationMatrix();
  const double low = (R.row(2).transpose().cwiseAbs().cwiseProduct(h)).sum();  // centre above the lowest corner
  place(m, s, 1, Vec3(0.1, -0.05, low + 0.01), q);
  rt::set_body_velocity(m.bodies[1], s.bodies[1], Vec3(0, 0, -1), Vec3::Zero());
  const double e_in = body_energy(m, s, 1);
  DropResult r;
  bool touched = false, left = false;
  const long steps = static_cast<long>(0.15 / m.dt);
  for (long k = 0; k < steps; ++k) {
    rt::step(m, s);
    const long n = s.stats.body_body_contacts;
    r.max_points = std::max(r.max_points, n);
    if (n > 0) {
      touched = true;
      continue;
    }
    if (!touched) continue;
    const double ratio = body_energy(m, s, 1) / e_in;
    if (!left) r.first_out = ratio;
    left = true;
    r.max_out = std::max(r.max_out, ratio);
    r.min_out = std::min(r.min_out, ratio);
  }
  EXPECT_TRUE(touched && left);
  return r;
}

Quat random_attitude(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Shoemake's uniform random rotation.
  const double u1 = u(rng), u2 = 2 * kPi * u(rng), u3 = 2 * kPi * u(rng);
  const double a = std::sqrt(1 - u1), c = std::sqrt(u1);
  return Quat(c * std::cos(u3), a * std::sin(u2), a * std::cos(u2), c * std::sin(u3));
}

TEST(BodyCollision, BoxDroppedAtRandomAttitudesNeverLeavesWithMoreEnergy) {
  std::mt19937_64 rng(20240611);
  double worst_first = 0, worst_any = 0, worst_elastic = 0;
  for (int k = 0; k < 100; ++k) {
    const Quat q = random_attitude(rng);
    const DropResult damped = drop(0.6, 0.5, q);
    EXPECT_LE(damped.max_out, 1.0) << "drop " << k;
    worst_first = std::max(worst_first, damped.first_out);
    worst_any = std::max(worst_any, damped.max_out);
    const DropResult elastic = drop(1.0, 0.0, q);
    const double err = std::max(std::fabs(elastic.max_out - 1), std::fabs(elastic.min_out - 1));
    EXPECT_LE(err, 0.01) << "drop " << k;
    worst_elastic = std::max(worst_elastic, err);
  }
  ::testing::Test::RecordProperty("max_first_eout_over_ein", rt::test::figure(worst_first));
  ::testing::Test::RecordProperty("max_eout_over_ein", rt::test::figure(worst_any));
  ::testing::Test::RecordProperty("elastic_energy_error", rt::test::figure(worst_elastic));
  std::printf("eps 0.6 mu 0.5: max E_out/E_in first departure %.6f, any contact-free instant %.6f; "
              "eps 1 mu 0: max |E/E_in - 1| %.3e\n", worst_first, worst_any, worst_elastic);
}

}  // namespace

namespace {

// The narrow phase keeps nothing between steps: a copy of the State taken in
// the middle of a contact continues bit-identically to the original.
TEST(BodyCollision, CopiedStateContinuesBitIdentically) {
  const Vec3 h(0.3, 0.2, 0.1);
  Model m = make_model({plate(), box(h)}, 0.6, 0.5, 1e7, 2e-5);
  m.gravity = Vec3(0, 0, -9.81);
  State s = body_state(m);
  place(m, s, 0, Vec3::Zero());
  const Quat q(Eigen::AngleAxisd(0.3, Vec3(1, 2, 0).normalized()));
  const Mat3 R = q.toRotationMatrix();
  place(m, s, 1, Vec3(0, 0, (R.row(2).transpose().cwiseAbs().cwiseProduct(h)).sum() + 1e-3), q);
  rt::set_body_velocity(m.bodies[1], s.bodies[1], Vec3(0.3, 0, -1), Vec3(0, 0, 2));
  while (s.body_points.empty()) rt::step(m, s);
  for (int k = 0; k < 20; ++k) rt::step(m, s);
  ASSERT_FALSE(s.body_points.empty());
  State copy = s;
  for (int k = 0; k < 400; ++k) {
    rt::step(m, s);
    rt::step(m, copy);
  }
  EXPECT_EQ(s.bodies[1].pos, copy.bodies[1].pos);
  EXPECT_EQ(s.bodies[1].q.coeffs(), copy.bodies[1].q.coeffs());
  EXPECT_EQ(s.bodies[1].ang_mom, copy.bodies[1].ang_mom);
}

}  // namespace
