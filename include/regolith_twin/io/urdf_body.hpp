// Rigid bodies from URDF (docs/model.md §6), parsed with urdfdom.
//
// Every link of the file must hang off one root link through fixed joints: the
// links merge into one rigid body. Each link contributes its <inertial> (mass,
// centre of mass, inertia tensor; a link without one is massless) and its
// <collision> geometry (box, cylinder, sphere, or an STL mesh).
//
// The body frame of the result is at the merged centre of mass, with axes along
// the principal axes of the merged inertia tensor. The axes are matched to the
// root link's axes: the body x, y and z axes are the principal axes closest to
// the root x, y and z axes (the assignment that maximises the sum of |cosines|),
// each pointing along its root axis, and right-handed. A body whose merged
// tensor is already diagonal in the root frame (a box centred on its link)
// therefore keeps the root axes exactly; within a degenerate eigenspace (equal
// moments) the root axes, projected onto it, are used. ref_pos/ref_rot give the
// body frame in the root link frame.
//
// Meshes: binary and ASCII STL. Relative file names are resolved against the
// URDF file's directory, `package://regolith_twin/...` against the package root
// (the nearest directory above the URDF file holding this package's
// package.xml), `file://` as an absolute path. The URDF <scale> is applied to
// the vertices; identical vertices are merged; triangles keep the file's vertex
// order (counter-clockwise seen from outside, as STL prescribes).
#pragma once

#include <map>
#include <optional>
#include <string>

#include "regolith_twin/core/body.hpp"

namespace rt {

struct UrdfOverrides {
  // Collision box of the named link resized to these full extents (m, > 0).
  // The point of the box at the link frame origin keeps its place relative to
  // the box: a box hung below its link frame (link frame on its top face
  // centre) stays attached there and grows downwards. The link must have
  // exactly one box collision. Used for the MicrOmega prominence of the MASCOT
  // lander, whose size is not published. Mass properties are unchanged.
  std::map<std::string, Vec3> box_size;
  // Total mass (kg, > 0). The merged inertia tensor is scaled by the same
  // factor (the same mass distribution at another density).
  std::optional<double> mass;
  // Centre of mass in the root link frame (m). The merged inertia tensor about
  // the centre of mass is kept as it is; only the point it refers to moves.
  std::optional<Vec3> centre_of_mass;
};

// Load the URDF file at `path` as one rigid body: name = robot name,
// ref_frame = root link name, frames = one per link (root first, then depth
// first with children in name order; pose relative to the parent link).
// finalize_body is applied. Throws InputError naming the file and the link,
// joint or element at fault.
BodyModel load_urdf_body(const std::string& path, const UrdfOverrides& ov = {});

// Read an STL file (binary or ASCII) into a mesh, vertices multiplied
// component-wise by `scale` (a negative scale product reverses the winding).
// Throws InputError naming the file.
TriangleMesh load_stl(const std::string& path, const Vec3& scale = Vec3::Ones());

}  // namespace rt
