// Rigid bodies (docs/model.md §6): static description (shapes, mass, principal
// inertia) and evolving state (pose, momenta, accumulated wrench), the
// free-rotation integrator and the grain–shape gap functions.
//
// Frames: every body has a body frame at its centre of mass with axes along
// the principal axes of inertia. Shapes are placed in that frame. The frame of
// the description the body came from (the URDF base link) is kept as
// ref_pos/ref_rot so poses can be reported in it.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

using Quat = Eigen::Quaterniond;
using Mat3 = Eigen::Matrix3d;

enum class ShapeType { Sphere, Box, Cylinder, Ellipsoid, Mesh };

// A triangle mesh in its shape frame (already scaled), triangles wound
// counter-clockwise seen from outside.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// Welded mesh, adjacency and BVH for grain contacts (core/mesh_contact.hpp).
struct MeshSurface;

struct Shape {
  ShapeType type = ShapeType::Box;
  Vec3 pos = Vec3::Zero();      // shape origin in the body frame, m
  Quat rot = Quat::Identity();  // shape frame -> body frame
  // sphere: (r, r, r); box: half extents; cylinder: (r, r, half length) about
  // the shape's z axis; ellipsoid: semi-axes. Mesh: unused.
  Vec3 size = Vec3::Zero();
  int mesh = -1;                // index into BodyModel::meshes (Mesh only)
  std::string link;             // description link it came from (messages, tf)
};

// A named frame rigidly attached to the body (URDF links merged by fixed
// joints), as a pose in the body's reference frame; published as tf.
struct BodyFrame {
  std::string name;
  std::string parent;           // parent frame name ("" for the reference frame itself)
  Vec3 pos = Vec3::Zero();      // pose relative to the parent frame
  Quat rot = Quat::Identity();
};

struct BodyModel {
  std::string name;
  double mass = 0;              // kg (ignored when fixed)
  Vec3 inertia = Vec3::Zero();  // principal moments of inertia about the centre of mass, kg m^2
  bool fixed = false;           // immovable (infinite mass): a rigid floor, cliff or held boulder
  int material = 0;             // structure material: the body's restitution, the grains' friction
  // Body frame in the reference frame: x_ref = ref_pos + ref_rot * x_body.
  Vec3 ref_pos = Vec3::Zero();
  Quat ref_rot = Quat::Identity();
  std::vector<Shape> shapes;
  std::vector<TriangleMesh> meshes;
  // Surface of each mesh for grain contacts (mesh_contact.hpp), built by
  // finalize_body; immutable and shared by copies of the body.
  std::vector<std::shared_ptr<const MeshSurface>> surfaces;
  std::vector<BodyFrame> frames;  // fixed child frames (reference frame first)
  std::string ref_frame;          // name of the reference frame (URDF base link)
  std::string urdf_file;          // the URDF it was read from ("" for shapes given in a scenario)
  double bound_radius = 0;      // largest distance of a shape point from the centre of mass, m (set by finalize_body)
  double inv_mass() const { return fixed ? 0.0 : 1.0 / mass; }
};

struct BodyState {
  Vec3 pos = Vec3::Zero();        // centre of mass, world, m
  Quat q = Quat::Identity();      // body frame -> world
  Vec3 vel = Vec3::Zero();        // m/s; during the force pass, the predicted v(n+1)
  Vec3 omega = Vec3::Zero();      // world, rad/s; during the force pass, the predicted omega(n+1)
  Vec3 vel_mid = Vec3::Zero();    // v(n+1/2), m/s
  Vec3 omega_mid = Vec3::Zero();  // omega(n+1/2), world, rad/s
  Vec3 ang_mom = Vec3::Zero();    // angular momentum about the centre of mass, world, kg m^2/s
  Vec3 force = Vec3::Zero();      // total force of the last force pass (no gravity), N
  Vec3 torque = Vec3::Zero();     // total torque about the centre of mass, N m
  Vec3 pos_at_build = Vec3::Zero();  // pose when the grain–body list was built
  Quat q_at_build = Quat::Identity();
};

// Bounding radius of the shapes and the surfaces of the meshes; throws
// InputError on invalid sizes, mass or meshes.
void finalize_body(BodyModel& b);

// World inverse inertia R I^-1 R^T of a body at orientation q (zero when fixed).
Mat3 inverse_inertia_world(const BodyModel& b, const Quat& q);

// Set a body's velocity and angular velocity (world), keeping L consistent.
void set_body_velocity(const BodyModel& b, BodyState& s, const Vec3& v, const Vec3& omega);

// Rotational kinetic energy 1/2 omega . L and translational 1/2 M v^2, J.
double body_rot_energy(const BodyModel& b, const BodyState& s);
double body_lin_energy(const BodyModel& b, const BodyState& s);

// Torque-free rotation over time dt with world angular momentum L: the
// symmetric splitting of the free rigid body into exact rotations about the
// principal axes (x/2, y/2, z, y/2, x/2). |L| is kept exactly, energy to
// O((omega dt)^2) without drift. Returns the new orientation.
Quat free_rotation(const Vec3& inertia, const Quat& q, const Vec3& L, double dt);

// Contact of a sphere (centre p in the body frame, radius r) with one shape.
struct ShapeGap {
  double overlap = -1e300;      // > 0 when touching, m
  Vec3 n = Vec3::UnitZ();       // unit normal from the sphere centre towards the shape, body frame
  Vec3 point = Vec3::Zero();    // contact point on the shape surface, body frame
};
// A mesh shape gives its nearest surface point (mesh_contact.hpp: mesh_gap),
// searching only within r + reach (beyond: overlap -1e300); the other shapes
// ignore reach. Grain–mesh forces use every touched feature (mesh_hits), not
// this one point.
ShapeGap shape_gap(const BodyModel& b, const Shape& sh, const Vec3& p, double r,
                   double reach = std::numeric_limits<double>::infinity());

// One touched feature of a mesh shape (mesh_contact.hpp: mesh_hits).
struct MeshHit {
  enum Kind { Face = 0, Edge = 1, Vertex = 2 };
  Vec3 n = Vec3::UnitZ();       // unit normal from the sphere centre towards the surface
  Vec3 point = Vec3::Zero();    // closest point of the feature
  double overlap = 0;           // r - distance, > 0, m
  int tri = -1;                 // a triangle of the feature (welded surface's numbering)
  int kind = Face;
  int slot = -1;                // history slot of the contact (set by the force pass)
};

// Orientation q of the body's reference frame in the world from a body pose.
inline Quat reference_rotation(const BodyModel& b, const Quat& q_body) { return q_body * b.ref_rot.conjugate(); }
inline Vec3 reference_position(const BodyModel& b, const Vec3& pos, const Quat& q_body) {
  return pos - reference_rotation(b, q_body) * b.ref_pos;
}

}  // namespace rt
