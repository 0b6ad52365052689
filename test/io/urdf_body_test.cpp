// Rigid bodies from URDF: the MASCOT lander as published, links merged through
// fixed joints (centre of mass and parallel-axis inertia checked against hand
// computations), STL meshes (binary and ASCII, scale, package paths), and
// InputErrors naming the file and the link or joint at fault.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "regolith_twin/io/urdf_body.hpp"
#include "test_support.hpp"

namespace {

using rt::BodyModel;
using rt::InputError;
using rt::Mat3;
using rt::Quat;
using rt::ShapeType;
using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;

void expect_vec_near(const Vec3& a, const Vec3& b, double tol, const std::string& what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": got (" << a.transpose() << "), expected (" << b.transpose() << ")";
}

// The 12 facets of the cube [-0.5, 0.5]^3, counter-clockwise seen from outside.
std::vector<std::array<Vec3, 3>> cube_facets() {
  std::vector<std::array<Vec3, 3>> f;
  for (int a = 0; a < 3; ++a) {
    const Vec3 u = Vec3::Unit((a + 1) % 3), v = Vec3::Unit((a + 2) % 3);  // u x v = e_a
    for (int s : {1, -1}) {
      const Vec3 c = 0.5 * s * Vec3::Unit(a);
      const Vec3 mm = c - 0.5 * u - 0.5 * v, pm = c + 0.5 * u - 0.5 * v, pp = c + 0.5 * u + 0.5 * v,
                 mp = c - 0.5 * u + 0.5 * v;
      if (s > 0) {
        f.push_back({mm, pm, pp});
        f.push_back({mm, pp, mp});
      } else {
        f.push_back({mm, pp, pm});
        f.push_back({mm, mp, pp});
      }
    }
  }
  return f;
}

void put_le32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
}

void put_float(std::string& out, double v) {
  const float f = static_cast<float>(v);
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  put_le32(out, bits);
}

// Binary STL; the header starts with "solid" on purpose (common in the wild).
std::string binary_stl(const std::vector<std::array<Vec3, 3>>& facets) {
  std::string out = "solid cube written as binary";
  out.resize(80, ' ');
  put_le32(out, static_cast<std::uint32_t>(facets.size()));
  for (const auto& t : facets) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    for (int c = 0; c < 3; ++c) put_float(out, n[c]);
    for (const Vec3& p : t)
      for (int c = 0; c < 3; ++c) put_float(out, p[c]);
    out += std::string(2, '\0');
  }
  return out;
}

std::string ascii_stl(const std::vector<std::array<Vec3, 3>>& facets) {
  std::ostringstream s;
  s << "solid unit cube\n";
  for (const auto& t : facets) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    s << "  facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n    outer loop\n";
    for (const Vec3& p : t) s << "      vertex " << p.x() << " " << p.y() << " " << p.z() << "\n";
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid unit cube\n";
  return s.str();
}

// Signed volume enclosed by a mesh (positive when wound outwards).
double mesh_volume(const rt::TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
  return v;
}

const char* const kInertialOne = R"(<inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>)";

class UrdfBody : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/regolith_urdf_test_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // A URDF robot "test" around the given links and joints.
  std::string write_urdf(const std::string& name, const std::string& body) {
    return write(name, "<?xml version=\"1.0\"?>\n<robot name=\"test\">\n" + body + "\n</robot>\n");
  }

  // The message of the InputError thrown by loading `path`; fails if none.
  static std::string error_of(const std::string& path, const rt::UrdfOverrides& ov = {}) {
    try {
      rt::load_urdf_body(path, ov);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << path << " loaded without an InputError";
    return {};
  }

  std::string dir_;
};

// ----------------------------------------------------------------- MASCOT ---

TEST_F(UrdfBody, MascotAsPublished) {
  const BodyModel b = rt::load_urdf_body("urdf/mascot.urdf");
  EXPECT_EQ(b.name, "mascot");
  EXPECT_EQ(b.ref_frame, "mascot_base");
  EXPECT_DOUBLE_EQ(b.mass, 10.0);
  // Uniform box, m/12 (b^2 + c^2) ..., which the published values round to.
  const double a = 0.29, w = 0.275, h = 0.195;
  const Vec3 uniform(10.0 / 12 * (w * w + h * h), 10.0 / 12 * (a * a + h * h), 10.0 / 12 * (a * a + w * w));
  const Vec3 published(0.0947, 0.1018, 0.1331);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.inertia[k], uniform[k], 1e-12 * uniform[k]) << "axis " << k;
    EXPECT_NEAR(b.inertia[k], published[k], 0.5e-4) << "axis " << k << " (published to 4 decimals)";
  }
  // Body frame = box centre = root frame, axes along the box edges.
  expect_vec_near(b.ref_pos, Vec3::Zero(), 1e-15, "centre of mass");
  EXPECT_LT(b.ref_rot.angularDistance(Quat::Identity()), 1e-15);

  ASSERT_EQ(b.shapes.size(), 2u);
  const rt::Shape& box = b.shapes[0];
  EXPECT_EQ(box.type, ShapeType::Box);
  EXPECT_EQ(box.link, "mascot_base");
  expect_vec_near(box.size, Vec3(a / 2, w / 2, h / 2), 1e-15, "lander half extents");
  expect_vec_near(box.pos, Vec3::Zero(), 1e-15, "lander box centre");

  // The prominence: 5 x 5 x 2 cm, its top face on the bottom face.
  const rt::Shape& pm = b.shapes[1];
  EXPECT_EQ(pm.type, ShapeType::Box);
  EXPECT_EQ(pm.link, "micromega");
  expect_vec_near(pm.size, Vec3(0.025, 0.025, 0.01), 1e-15, "prominence half extents");
  expect_vec_near(pm.pos, Vec3(0, 0, -h / 2 - 0.01), 1e-15, "prominence centre");
  EXPECT_NEAR(pm.pos.z() + pm.size.z(), -h / 2, 1e-15) << "prominence top on the bottom face";

  ASSERT_EQ(b.frames.size(), 2u);
  EXPECT_EQ(b.frames[0].name, "mascot_base");
  EXPECT_EQ(b.frames[0].parent, "");
  EXPECT_EQ(b.frames[1].name, "micromega");
  EXPECT_EQ(b.frames[1].parent, "mascot_base");
  expect_vec_near(b.frames[1].pos, Vec3(0, 0, -h / 2), 1e-15, "micromega frame");
  EXPECT_NEAR(b.bound_radius, 0.5 * std::sqrt(a * a + w * w + h * h), 1e-15) << "half diagonal of the box";
}

TEST_F(UrdfBody, MascotProminenceOverride) {
  rt::UrdfOverrides ov;
  ov.box_size["micromega"] = Vec3(0.08, 0.06, 0.035);
  const BodyModel b = rt::load_urdf_body("urdf/mascot.urdf", ov);
  ASSERT_EQ(b.shapes.size(), 2u);
  const rt::Shape& pm = b.shapes[1];
  expect_vec_near(pm.size, Vec3(0.04, 0.03, 0.0175), 1e-15, "resized half extents");
  // Still centred under the link frame and hanging from the bottom face.
  expect_vec_near(pm.pos, Vec3(0, 0, -0.0975 - 0.0175), 1e-15, "resized centre");
  EXPECT_NEAR(pm.pos.z() + pm.size.z(), -0.0975, 1e-15);
  // Mass properties unchanged.
  EXPECT_DOUBLE_EQ(b.mass, 10.0);
  expect_vec_near(b.ref_pos, Vec3::Zero(), 1e-15, "centre of mass");

  rt::UrdfOverrides bad;
  bad.box_size["antenna"] = Vec3(0.01, 0.01, 0.01);
  const std::string msg = error_of("urdf/mascot.urdf", bad);
  EXPECT_NE(msg.find("mascot.urdf"), std::string::npos) << msg;
  EXPECT_NE(msg.find("antenna"), std::string::npos) << msg;
  bad.box_size.clear();
  bad.box_size["micromega"] = Vec3(0.01, 0, 0.01);
  EXPECT_NE(error_of("urdf/mascot.urdf", bad).find("micromega"), std::string::npos);
}

TEST_F(UrdfBody, MassAndCentreOfMassOverrides) {
  rt::UrdfOverrides ov;
  ov.mass = 12.5;
  ov.centre_of_mass = Vec3(0.01, -0.02, 0.005);
  const BodyModel b = rt::load_urdf_body("urdf/mascot.urdf", ov);
  EXPECT_DOUBLE_EQ(b.mass, 12.5);
  expect_vec_near(b.ref_pos, Vec3(0.01, -0.02, 0.005), 1e-15, "centre of mass");
  EXPECT_NEAR(b.inertia.x(), 1.25 * 0.094708333333333335, 1e-14);
  // Shapes are placed relative to the new centre of mass.
  expect_vec_near(b.shapes[0].pos, Vec3(-0.01, 0.02, -0.005), 1e-15, "lander box centre");
}

// ------------------------------------------------- merging through joints ---

// Root link a: 2 kg at (0.1, 0, 0), I = diag(0.01, 0.02, 0.03), a sphere.
// Link b via a fixed joint at (0, 0.2, 0) turned 90 deg about z: 1 kg, its
// inertial at (0.05, 0, 0) turned 90 deg about x, I = diag(0.004, 0.005,
// 0.006), a cylinder.
const char* const kTwoLinks = R"(
  <link name="a">
    <inertial><origin xyz="0.1 0 0"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="a_to_b" type="fixed">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0.2 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="b">
    <inertial><origin xyz="0.05 0 0" rpy="1.5707963267948966 0 0"/><mass value="1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.1"/></geometry></collision>
  </link>)";

TEST_F(UrdfBody, FixedJointMergesInertials) {
  const BodyModel b = rt::load_urdf_body(write_urdf("two.urdf", kTwoLinks));
  EXPECT_DOUBLE_EQ(b.mass, 3.0);
  // b's inertial in the root frame: (0, 0.2, 0) + Rz(90)(0.05, 0, 0) = (0, 0.25, 0);
  // Rz(90) Rx(90) turns diag(0.004, 0.005, 0.006) into diag(0.006, 0.004, 0.005).
  // Centre of mass (2 (0.1, 0, 0) + (0, 0.25, 0)) / 3 = (1/15, 1/12, 0).
  expect_vec_near(b.ref_pos, Vec3(1.0 / 15, 1.0 / 12, 0), 1e-15, "centre of mass");
  // Offsets from it: a (1/30, -1/12, 0), b (-1/15, 1/6, 0). Parallel axis:
  //   Ixx = 0.01 + 0.006 + 2/144 + 1/36  = 0.016 + 1/24
  //   Iyy = 0.02 + 0.004 + 2/900 + 1/225 = 0.024 + 1/150
  //   Izz = 0.03 + 0.005 + 1/24 + 1/150
  //   Ixy = -(2 (1/30)(-1/12) + (-1/15)(1/6)) = 1/60, Ixz = Iyz = 0
  const double ixx = 0.016 + 1.0 / 24, iyy = 0.024 + 1.0 / 150, izz = 0.035 + 1.0 / 24 + 1.0 / 150, ixy = 1.0 / 60;
  Mat3 expected;
  expected << ixx, ixy, 0, ixy, iyy, 0, 0, 0, izz;
  // Principal moments: z is principal; in the xy plane mean +- hypot(half difference, Ixy),
  // the larger one along x turned by theta about z, tan(2 theta) = 2 Ixy / (Ixx - Iyy).
  const double mean = 0.5 * (ixx + iyy), rad = std::hypot(0.5 * (ixx - iyy), ixy);
  const double theta = 0.5 * std::atan2(2 * ixy, ixx - iyy);
  EXPECT_NEAR(b.inertia.x(), mean + rad, 1e-14);
  EXPECT_NEAR(b.inertia.y(), mean - rad, 1e-14);
  EXPECT_NEAR(b.inertia.z(), izz, 1e-14);
  const Mat3 R = b.ref_rot.toRotationMatrix();
  expect_vec_near(R.col(0), Vec3(std::cos(theta), std::sin(theta), 0), 1e-12, "body x axis");
  expect_vec_near(R.col(2), Vec3::UnitZ(), 1e-12, "body z axis");
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  EXPECT_LT((R * b.inertia.asDiagonal() * R.transpose() - expected).norm(), 1e-14);

  // Shapes in the body frame: x_body = R^T (x_root - com).
  ASSERT_EQ(b.shapes.size(), 2u);
  EXPECT_EQ(b.shapes[0].type, ShapeType::Sphere);
  expect_vec_near(b.shapes[0].size, Vec3::Constant(0.05), 1e-15, "sphere size");
  expect_vec_near(b.shapes[0].pos, R.transpose() * (Vec3::Zero() - b.ref_pos), 1e-15, "sphere centre");
  EXPECT_EQ(b.shapes[1].type, ShapeType::Cylinder);
  EXPECT_EQ(b.shapes[1].link, "b");
  expect_vec_near(b.shapes[1].size, Vec3(0.02, 0.02, 0.05), 1e-15, "cylinder size");
  expect_vec_near(b.shapes[1].pos, R.transpose() * (Vec3(0, 0.2, 0.1) - b.ref_pos), 1e-14, "cylinder centre");
  const Quat cyl_root(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
  EXPECT_LT((b.ref_rot * b.shapes[1].rot).angularDistance(cyl_root), 1e-12);

  ASSERT_EQ(b.frames.size(), 2u);
  EXPECT_EQ(b.frames[0].name, "a");
  EXPECT_EQ(b.frames[1].name, "b");
  EXPECT_EQ(b.frames[1].parent, "a");
  expect_vec_near(b.frames[1].pos, Vec3(0, 0.2, 0), 1e-15, "joint origin");
  EXPECT_LT(b.frames[1].rot.angularDistance(cyl_root), 1e-12);
}

TEST_F(UrdfBody, OffDiagonalInertiaAndAxisOrder) {
  // One link, inertia with ixy: principal axes turned about z; the body axes
  // stay matched to the nearest root axes, right-handed.
  const double ixx = 0.02, iyy = 0.03, izz = 0.04, ixy = 0.002;
  const std::string path = write_urdf("tilted.urdf", R"(<link name="solo">
    <inertial><mass value="1"/>
      <inertia ixx="0.02" ixy="0.002" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial>
    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link>)");
  const BodyModel b = rt::load_urdf_body(path);
  const double mean = 0.5 * (ixx + iyy), rad = std::hypot(0.5 * (ixx - iyy), ixy);
  EXPECT_NEAR(b.inertia.x(), mean - rad, 1e-15);  // the axis near x has the smaller moment
  EXPECT_NEAR(b.inertia.y(), mean + rad, 1e-15);
  EXPECT_NEAR(b.inertia.z(), izz, 1e-15);
  const Mat3 R = b.ref_rot.toRotationMatrix();
  EXPECT_GT(R(0, 0), 0.9);
  EXPECT_GT(R(1, 1), 0.9);
  EXPECT_NEAR(R(2, 2), 1.0, 1e-12);
}

TEST_F(UrdfBody, PrincipalAxesMatchedToRootAxes) {
  // diag(1, 2, 2.5) turned 80 deg about z: the axis of moment 1 lies nearest
  // root y, that of moment 2 nearest root x (pointing along +x).
  const double t = 80 * kPi / 180;
  const std::string turned = write_urdf("turned.urdf", R"(<link name="l">
    <inertial><origin rpy="0 0 1.3962634015954636"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="2.5"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  const BodyModel b = rt::load_urdf_body(turned);
  expect_vec_near(b.inertia, Vec3(2, 1, 2.5), 1e-12, "moments");
  const Mat3 R = b.ref_rot.toRotationMatrix();
  expect_vec_near(R.col(0), Vec3(std::sin(t), -std::cos(t), 0), 1e-12, "body x");
  expect_vec_near(R.col(1), Vec3(std::cos(t), std::sin(t), 0), 1e-12, "body y");
  expect_vec_near(R.col(2), Vec3::UnitZ(), 1e-12, "body z");

  // Symmetric top diag(1, 1, 1.5) turned 30 deg about x: the symmetry axis is
  // body z; root x, already in the symmetric plane, stays body x.
  const double s = 30 * kPi / 180;
  const std::string top = write_urdf("top.urdf", R"(<link name="l">
    <inertial><origin rpy="0.5235987755982988 0 0"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1.5"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  const BodyModel c = rt::load_urdf_body(top);
  expect_vec_near(c.inertia, Vec3(1, 1, 1.5), 1e-12, "moments");
  const Mat3 Q = c.ref_rot.toRotationMatrix();
  expect_vec_near(Q.col(0), Vec3::UnitX(), 1e-12, "body x");
  expect_vec_near(Q.col(2), Vec3(0, -std::sin(s), std::cos(s)), 1e-12, "body z");
  EXPECT_NEAR(Q.determinant(), 1.0, 1e-14);
}

// ------------------------------------------------------------------ meshes ---

TEST_F(UrdfBody, StlBinaryAndAscii) {
  const auto facets = cube_facets();
  const std::string bin = write("meshes/cube_bin.stl", binary_stl(facets));
  const std::string txt = write("meshes/cube_txt.stl", ascii_stl(facets));
  for (const std::string& file : {bin, txt}) {
    SCOPED_TRACE(file);
    const rt::TriangleMesh m = rt::load_stl(file, Vec3(0.01, 0.02, 0.03));
    ASSERT_EQ(m.vertices.size(), 8u);  // shared corners merged
    ASSERT_EQ(m.triangles.size(), 12u);
    std::set<std::array<double, 3>> corners;
    for (const Vec3& v : m.vertices) corners.insert({v.x(), v.y(), v.z()});
    for (double x : {-0.005, 0.005})
      for (double y : {-0.01, 0.01})
        for (double z : {-0.015, 0.015}) EXPECT_EQ(corners.count({x, y, z}), 1u) << x << " " << y << " " << z;
    EXPECT_NEAR(mesh_volume(m), 0.01 * 0.02 * 0.03, 1e-15) << "outward winding and scale";
    // A mirroring scale keeps the winding outward.
    EXPECT_NEAR(mesh_volume(rt::load_stl(file, Vec3(-2, 1, 1))), 2.0, 1e-12);
  }
  // A degenerate facet is dropped together with the vertex only it used.
  auto with_sliver = facets;
  with_sliver.push_back({Vec3(9, 9, 9), Vec3(9, 9, 9), Vec3(0.5, 0.5, 0.5)});
  const rt::TriangleMesh sliver = rt::load_stl(write("meshes/sliver.stl", ascii_stl(with_sliver)));
  EXPECT_EQ(sliver.vertices.size(), 8u);
  EXPECT_EQ(sliver.triangles.size(), 12u);
  EXPECT_NEAR(mesh_volume(sliver), 1.0, 1e-15);

  // A truncated binary file with no ASCII header.
  std::string broken = binary_stl(facets);
  broken.replace(0, 5, "cubes");
  broken.resize(broken.size() - 7);
  const std::string cut = write("meshes/cut.stl", broken);
  try {
    rt::load_stl(cut);
    ADD_FAILURE() << "truncated STL accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
  }
}

TEST_F(UrdfBody, MeshLinkWithScaleAndPackagePath) {
  const auto facets = cube_facets();
  write("pkg/package.xml", "<package format=\"2\"><name>regolith_twin</name></package>\n");
  write("pkg/meshes/cube.stl", binary_stl(facets));
  write("pkg/urdf/cube_ascii.stl", ascii_stl(facets));
  const std::string path = write_urdf("pkg/urdf/meshes.urdf", std::string(R"(<link name="hull">)") + kInertialOne +
                                                                   R"(
    <collision><origin xyz="0 0 0.5"/>
      <geometry><mesh filename="package://regolith_twin/meshes/cube.stl" scale="0.1 0.1 0.2"/></geometry></collision>
    <collision><origin xyz="0 0 -0.5"/>
      <geometry><mesh filename="cube_ascii.stl"/></geometry></collision>
  </link>)");
  const BodyModel b = rt::load_urdf_body(path);
  ASSERT_EQ(b.shapes.size(), 2u);
  ASSERT_EQ(b.meshes.size(), 2u);
  EXPECT_EQ(b.shapes[0].type, ShapeType::Mesh);
  EXPECT_EQ(b.shapes[0].mesh, 0);
  EXPECT_EQ(b.shapes[1].mesh, 1);
  expect_vec_near(b.shapes[0].pos, Vec3(0, 0, 0.5), 1e-15, "scaled mesh origin");
  expect_vec_near(b.shapes[1].pos, Vec3(0, 0, -0.5), 1e-15, "relative mesh origin");
  EXPECT_NEAR(mesh_volume(b.meshes[0]), 0.1 * 0.1 * 0.2, 1e-15);
  EXPECT_NEAR(mesh_volume(b.meshes[1]), 1.0, 1e-15);
  for (const Vec3& v : b.meshes[0].vertices) expect_vec_near(v.cwiseAbs(), Vec3(0.05, 0.05, 0.1), 1e-9, "vertex");
}

// ------------------------------------------------------------------ errors ---

void expect_names(const std::string& msg, std::initializer_list<std::string> parts) {
  for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

TEST_F(UrdfBody, MissingAndUnparsableFiles) {
  const std::string missing = dir_ + "/nothing.urdf";
  expect_names(error_of(missing), {missing, "cannot open"});
  const std::string broken = write("broken.urdf", "<robot name=\"x\"><link name=\"a\">");
  expect_names(error_of(broken), {broken, "not a valid URDF"});
  const std::string no_robot = write("empty.urdf", "<?xml version=\"1.0\"?><nothing/>");
  expect_names(error_of(no_robot), {no_robot});
}

TEST_F(UrdfBody, MovingJointRefused) {
  const std::string path = write_urdf("hinge.urdf", std::string(R"(<link name="base">)") + kInertialOne + R"(
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="lid_hinge" type="revolute"><parent link="base"/><child link="lid"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <link name="lid"/>)");
  expect_names(error_of(path), {path, "lid_hinge", "revolute", "only fixed joints merge into one rigid body"});
}

TEST_F(UrdfBody, TwoRootsRefused) {
  const std::string path = write_urdf("roots.urdf", std::string(R"(<link name="alpha">)") + kInertialOne +
                                                        R"(</link><link name="beta"/>)");
  expect_names(error_of(path), {path, "alpha", "beta"});
}

TEST_F(UrdfBody, MassAndInertiaChecked) {
  const std::string massless = write_urdf("massless.urdf", R"(<link name="ghost">
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  expect_names(error_of(massless), {massless, "ghost", "total mass"});

  const std::string negative = write_urdf("negative.urdf", R"(<link name="wobbly">
    <inertial><mass value="1"/><inertia ixx="-0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  expect_names(error_of(negative), {negative, "wobbly", "positive semi-definite"});

  const std::string point = write_urdf("point.urdf", R"(<link name="point">
    <inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  expect_names(error_of(point), {point, "point", "not positive definite"});

  const std::string neg_mass = write_urdf("negmass.urdf", R"(<link name="weird">
    <inertial><mass value="-1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>)");
  expect_names(error_of(neg_mass), {neg_mass, "weird"});

  rt::UrdfOverrides ov;
  ov.mass = 0;
  expect_names(error_of("urdf/mascot.urdf", ov), {"mascot.urdf", "mass override"});
}

TEST_F(UrdfBody, MeshAndGeometryErrors) {
  const std::string missing = write_urdf("nomesh.urdf", std::string(R"(<link name="hull">)") + kInertialOne + R"(
    <collision><geometry><mesh filename="meshes/absent.stl"/></geometry></collision></link>)");
  expect_names(error_of(missing), {missing, "hull", "absent.stl", "not found"});

  write("shape.obj", "v 0 0 0\n");
  const std::string obj = write_urdf("obj.urdf", std::string(R"(<link name="rock">)") + kInertialOne + R"(
    <collision><geometry><mesh filename="shape.obj"/></geometry></collision></link>)");
  expect_names(error_of(obj), {obj, "rock", "unsupported mesh format"});

  const std::string other_pkg = write_urdf("otherpkg.urdf", std::string(R"(<link name="arm">)") + kInertialOne + R"(
    <collision><geometry><mesh filename="package://other_robot/meshes/arm.stl"/></geometry></collision></link>)");
  expect_names(error_of(other_pkg), {other_pkg, "arm", "package://"});

  write("bad.stl", "this is not a mesh");
  const std::string bad = write_urdf("badstl.urdf", std::string(R"(<link name="lump">)") + kInertialOne + R"(
    <collision><geometry><mesh filename="bad.stl"/></geometry></collision></link>)");
  expect_names(error_of(bad), {bad, "lump", "bad.stl", "not an STL file"});

  const std::string capsule = write_urdf("capsule.urdf", std::string(R"(<link name="pill">)") + kInertialOne + R"(
    <collision><geometry><capsule radius="0.1" length="0.2"/></geometry></collision></link>)");
  expect_names(error_of(capsule), {capsule, "pill", "capsule"});

  const std::string no_shape = write_urdf("noshape.urdf", std::string(R"(<link name="bare">)") + kInertialOne + "</link>");
  expect_names(error_of(no_shape), {no_shape, "collision shape"});
}

}  // namespace
