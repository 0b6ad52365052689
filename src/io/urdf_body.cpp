// Rigid bodies from URDF: links merged through fixed joints into one body with
// principal-axis frame, collision shapes and STL meshes (see urdf_body.hpp).
#include "regolith_twin/io/urdf_body.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <sstream>

#include "regolith_twin/io/data_file.hpp"

namespace rt {
namespace {

namespace fs = std::filesystem;

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::string vec_text(const Vec3& v) { return "(" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + ")"; }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// ---------------------------------------------------------------- STL -------

[[noreturn]] void stl_fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}

using RawTriangle = std::array<Vec3, 3>;

std::uint32_t read_le32(const std::string& d, std::size_t off) {
  const auto b = [&](std::size_t k) { return static_cast<std::uint32_t>(static_cast<unsigned char>(d[off + k])); };
  return b(0) | (b(1) << 8) | (b(2) << 16) | (b(3) << 24);
}

float read_le_float(const std::string& d, std::size_t off) {
  const std::uint32_t bits = read_le32(d, off);
  float f;
  static_assert(sizeof(f) == sizeof(bits), "IEEE single precision float expected");
  std::memcpy(&f, &bits, sizeof(f));
  return f;
}

std::vector<RawTriangle> read_binary_stl(const std::string& data, std::uint32_t count) {
  std::vector<RawTriangle> tris(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    // 50 bytes a facet: normal (ignored), three vertices, attribute byte count.
    const std::size_t base = 84 + 50 * static_cast<std::size_t>(t) + 12;
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) tris[t][v][c] = read_le_float(data, base + 4 * (3 * v + c));
  }
  return tris;
}

std::vector<RawTriangle> read_ascii_stl(const std::string& path, const std::string& data) {
  // Skip "solid <name>" up to the end of its line: the name may hold spaces.
  const std::size_t eol = data.find('\n');
  std::istringstream in(eol == std::string::npos ? std::string() : data.substr(eol + 1));
  std::vector<RawTriangle> tris;
  std::string tok;
  auto facet_text = [&]() { return "ASCII STL, facet " + std::to_string(tris.size() + 1); };
  auto expect = [&](const char* word) {
    if (!(in >> tok) || lower(tok) != word)
      stl_fail(path, facet_text() + ": expected '" + word + "', got '" + (in ? tok : std::string("end of file")) + "'");
  };
  auto number = [&]() {
    if (!(in >> tok)) stl_fail(path, facet_text() + ": expected a number, got end of file");
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(v))
      stl_fail(path, facet_text() + ": expected a finite number, got '" + tok + "'");
    return v;
  };
  while (true) {
    if (!(in >> tok)) stl_fail(path, "ASCII STL: missing 'endsolid'");
    const std::string key = lower(tok);
    if (key == "endsolid") break;
    if (key != "facet") stl_fail(path, facet_text() + ": expected 'facet' or 'endsolid', got '" + tok + "'");
    expect("normal");
    for (int c = 0; c < 3; ++c) number();  // the facet normal is not used
    expect("outer");
    expect("loop");
    RawTriangle t;
    for (int v = 0; v < 3; ++v) {
      expect("vertex");
      for (int c = 0; c < 3; ++c) t[v][c] = number();
    }
    expect("endloop");
    expect("endfacet");
    tris.push_back(t);
  }
  return tris;
}

// ------------------------------------------------------------- poses --------

// x_parent = p + q * x_child
struct Pose {
  Vec3 p = Vec3::Zero();
  Quat q = Quat::Identity();
};

Pose to_pose(const urdf::Pose& u) {
  Pose r;
  r.p = Vec3(u.position.x, u.position.y, u.position.z);
  r.q = Quat(u.rotation.w, u.rotation.x, u.rotation.y, u.rotation.z);
  r.q.normalize();
  return r;
}

Pose compose(const Pose& a, const Pose& b) {
  Pose r;
  r.p = a.p + a.q * b.p;
  r.q = (a.q * b.q).normalized();
  return r;
}

// Principal axes of a symmetric positive definite tensor I (root frame) as the
// columns of a rotation matrix, matched to the root axes (see urdf_body.hpp).
Mat3 principal_axes(const Mat3& I) {
  if (I(0, 1) == 0 && I(0, 2) == 0 && I(1, 2) == 0) return Mat3::Identity();
  const Eigen::SelfAdjointEigenSolver<Mat3> es(I);
  const Vec3 lam = es.eigenvalues();  // ascending
  const Mat3 V = es.eigenvectors();
  const double tol = 1e-9 * lam.cwiseAbs().maxCoeff();
  const bool eq01 = lam[1] - lam[0] <= tol, eq12 = lam[2] - lam[1] <= tol;
  if (eq01 && eq12) return Mat3::Identity();  // spherical top: every axis is principal
  Mat3 R;
  if (eq01 || eq12) {
    // Axially symmetric: the distinct axis goes to the root axis it is closest
    // to; the next root axis (cyclically), projected onto the symmetric plane,
    // gives the second; the third completes a right-handed frame.
    Vec3 u = V.col(eq01 ? 2 : 0);
    int k = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(u[a]) > std::abs(u[k])) k = a;
    if (u[k] < 0) u = -u;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Vec3 ei = Vec3::Unit(i);
    const Vec3 a = (ei - ei.dot(u) * u).normalized();
    R.col(k) = u;
    R.col(i) = a;
    R.col(j) = u.cross(a);
    return R;
  }
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int best = 0;
  double best_score = -1;
  for (int p = 0; p < 6; ++p) {
    double score = 0;
    for (int e = 0; e < 3; ++e) score += std::abs(V(perms[p][e], e));
    if (score > best_score) {
      best_score = score;
      best = p;
    }
  }
  for (int e = 0; e < 3; ++e) {
    const int axis = perms[best][e];
    Vec3 v = V.col(e);
    if (v[axis] < 0) v = -v;
    R.col(axis) = v;
  }
  R.col(2) = R.col(0).cross(R.col(1)).normalized();  // right-handed
  return R;
}

// ------------------------------------------------------------- urdfdom ------

// Collects urdfdom's error messages while a file is parsed.
class ParseLog : public console_bridge::OutputHandler {
 public:
  ParseLog() { console_bridge::useOutputHandler(this); }
  ~ParseLog() override { console_bridge::restorePreviousOutputHandler(); }
  ParseLog(const ParseLog&) = delete;
  ParseLog& operator=(const ParseLog&) = delete;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR) return;
    if (!text_.empty()) text_ += "; ";
    text_ += text;
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

std::mutex& parse_mutex() {
  static std::mutex m;
  return m;
}

const char* joint_type_name(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

// The package root: the nearest directory at or above `dir` holding this
// package's package.xml (source tree or installed share directory).
std::string find_package_root(const fs::path& dir) {
  for (fs::path d = dir; !d.empty(); d = d.parent_path()) {
    std::ifstream in(d / "package.xml");
    if (in) {
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (text.find("<name>regolith_twin</name>") != std::string::npos) return d.string();
    }
    if (d == d.parent_path()) break;
  }
  return {};
}

class Loader {
 public:
  Loader(std::string path, const UrdfOverrides& ov) : path_(std::move(path)), ov_(ov) {}

  BodyModel load() {
    parse();
    check_joints();
    collect_links(model_->getRoot(), Pose(), "");
    merge_inertials();
    place_body_frame();
    build_shapes();
    body_.name = model_->getName();
    body_.ref_frame = model_->getRoot()->name;
    try {
      finalize_body(body_);
    } catch (const InputError& e) {
      throw InputError(path_ + ": " + e.what());
    }
    return std::move(body_);
  }

 private:
  struct LinkInfo {
    urdf::LinkConstSharedPtr link;
    Pose in_root;  // link frame in the root link frame
  };

  [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }
  [[noreturn]] void fail_link(const std::string& link, const std::string& what) const {
    fail("link '" + link + "': " + what);
  }

  void parse() {
    // Size and element depth are bounded before urdfdom sees the text (docs/files.md, "Loaded files").
    const std::string xml = read_file_limited(path_, kMaxUrdfBytes, "URDF file");
    check_xml_nesting(path_, xml);
    std::string log;
    {
      std::lock_guard<std::mutex> lock(parse_mutex());
      ParseLog capture;
      try {
        model_ = urdf::parseURDF(xml);
      } catch (const std::exception& e) {
        model_.reset();
        log = e.what();
      }
      if (log.empty()) log = capture.text();
    }
    if (!model_) fail("not a valid URDF (urdfdom: " + (log.empty() ? std::string("no message") : log) + ")");
    // urdfdom drops elements it cannot read (an unknown geometry such as
    // <capsule>, a malformed <collision>) with an error message but still
    // returns a model: refuse such a file rather than lose its geometry.
    if (!log.empty()) fail("URDF elements urdfdom could not read (urdfdom: " + log + ")");
    if (!model_->getRoot()) fail("URDF has no root link");
  }

  void check_joints() const {
    for (const auto& [name, joint] : model_->joints_) {
      if (joint->type != urdf::Joint::FIXED)
        fail("joint '" + name + "' is " + joint_type_name(joint->type) + " (between links '" +
             joint->parent_link_name + "' and '" + joint->child_link_name +
             "'): only fixed joints merge into one rigid body");
    }
  }

  void collect_links(const urdf::LinkConstSharedPtr& link, const Pose& in_root, const std::string& parent) {
    links_.push_back({link, in_root});
    BodyFrame f;
    f.name = link->name;
    f.parent = parent;
    if (link->parent_joint) {
      const Pose j = to_pose(link->parent_joint->parent_to_joint_origin_transform);
      f.pos = j.p;
      f.rot = j.q;
    }
    body_.frames.push_back(f);
    std::vector<urdf::LinkSharedPtr> children = link->child_links;
    std::sort(children.begin(), children.end(), [](const auto& a, const auto& b) { return a->name < b->name; });
    for (const auto& c : children) {
      const Pose j = to_pose(c->parent_joint->parent_to_joint_origin_transform);
      collect_links(c, compose(in_root, j), link->name);
    }
  }

  // Total mass, centre of mass and inertia tensor about it, in the root frame.
  void merge_inertials() {
    struct Part {
      double m;
      Vec3 c;
      Mat3 I;
    };
    std::vector<Part> parts;
    std::string massive;  // names of the links with mass, for messages
    int n_massive = 0;
    double M = 0;
    Vec3 mc = Vec3::Zero();
    for (const LinkInfo& li : links_) {
      const auto& in = li.link->inertial;
      if (!in) continue;
      const std::string& name = li.link->name;
      if (!std::isfinite(in->mass) || in->mass < 0)
        fail_link(name, "<inertial> <mass> must be >= 0 kg (got " + num(in->mass) + ")");
      Mat3 I;
      I << in->ixx, in->ixy, in->ixz, in->ixy, in->iyy, in->iyz, in->ixz, in->iyz, in->izz;
      if (!I.allFinite()) fail_link(name, "<inertial> <inertia> has a non-finite entry");
      const Vec3 lam = Eigen::SelfAdjointEigenSolver<Mat3>(I, Eigen::EigenvaluesOnly).eigenvalues();
      if (lam[0] < -1e-12 * std::max(1.0, std::abs(lam[2])))
        fail_link(name, "<inertial> <inertia> is not positive semi-definite (principal moments " + vec_text(lam) +
                            " kg m^2)");
      const Pose p = compose(li.in_root, to_pose(in->origin));
      const Mat3 R = p.q.toRotationMatrix();
      parts.push_back({in->mass, p.p, R * I * R.transpose()});
      M += in->mass;
      mc += in->mass * p.p;
      if (in->mass > 0) {
        massive += (massive.empty() ? "'" : ", '") + name + "'";
        ++n_massive;
      }
    }
    if (!(M > 0))
      fail("total mass is " + num(M) + " kg: must be > 0 kg (root link '" + model_->getRoot()->name +
           "'; give a link an <inertial> with <mass> > 0)");
    Vec3 c = mc / M;
    Mat3 I = Mat3::Zero();
    for (const Part& p : parts) {
      const Vec3 d = p.c - c;  // parallel-axis theorem
      I += p.I + p.m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    I = 0.5 * (I + I.transpose());
    if (ov_.mass) {
      if (!std::isfinite(*ov_.mass) || !(*ov_.mass > 0))
        fail("mass override " + num(*ov_.mass) + " kg: must be > 0 kg");
      I *= *ov_.mass / M;
      M = *ov_.mass;
    }
    if (ov_.centre_of_mass) {
      if (!ov_.centre_of_mass->allFinite()) fail("centre-of-mass override must be finite");
      c = *ov_.centre_of_mass;
    }
    const Vec3 lam = Eigen::SelfAdjointEigenSolver<Mat3>(I, Eigen::EigenvaluesOnly).eigenvalues();
    if (!(lam[0] > 1e-12 * lam[2]))
      fail((n_massive == 1 ? "link " + massive + ": inertia tensor" : "inertia tensor of links " + massive + " merged") +
           " about the centre of mass is not positive definite (principal moments " + vec_text(lam) + " kg m^2)");
    mass_ = M;
    com_ = c;
    inertia_ = I;
  }

  void place_body_frame() {
    const Mat3 R = principal_axes(inertia_);
    body_.mass = mass_;
    body_.ref_pos = com_;
    body_.ref_rot = Quat(R).normalized();
    const Mat3 Rq = body_.ref_rot.toRotationMatrix();
    for (int k = 0; k < 3; ++k) body_.inertia[k] = Rq.col(k).dot(inertia_ * Rq.col(k));
  }

  void build_shapes() {
    for (const auto& [name, size] : ov_.box_size) {
      const auto link = model_->getLink(name);
      if (!link) fail("box size override for link '" + name + "': no such link");
      int boxes = 0;
      for (const auto& col : collisions(link))
        if (col->geometry && col->geometry->type == urdf::Geometry::BOX) ++boxes;
      if (boxes != 1)
        fail_link(name, "box size override needs exactly one <box> collision (found " + std::to_string(boxes) + ")");
      if (!size.allFinite() || !(size.minCoeff() > 0))
        fail_link(name, "box size override " + vec_text(size) + " m: every extent must be > 0 m");
    }
    const Quat to_body = body_.ref_rot.conjugate();
    for (const LinkInfo& li : links_) {
      const std::string& name = li.link->name;
      for (const auto& col : collisions(li.link)) {
        if (!col->geometry) fail_link(name, "<collision> without <geometry>");
        Pose local = to_pose(col->origin);
        Shape sh;
        sh.link = name;
        switch (col->geometry->type) {
          case urdf::Geometry::SPHERE: {
            const auto* g = static_cast<const urdf::Sphere*>(col->geometry.get());
            sh.type = ShapeType::Sphere;
            sh.size = Vec3::Constant(g->radius);
            break;
          }
          case urdf::Geometry::BOX: {
            const auto* g = static_cast<const urdf::Box*>(col->geometry.get());
            sh.type = ShapeType::Box;
            const Vec3 dim(g->dim.x, g->dim.y, g->dim.z);
            const auto o = ov_.box_size.find(name);
            if (o != ov_.box_size.end()) {
              if (!(dim.minCoeff() > 0)) fail_link(name, "<box> size must be > 0 m to be resized");
              // The link origin, in box coordinates, scales with the box.
              const Vec3 anchor = local.q.conjugate() * (-local.p);
              local.p = -(local.q * Vec3(anchor.cwiseProduct(o->second).cwiseQuotient(dim)));
              sh.size = 0.5 * o->second;
            } else {
              sh.size = 0.5 * dim;
            }
            break;
          }
          case urdf::Geometry::CYLINDER: {
            const auto* g = static_cast<const urdf::Cylinder*>(col->geometry.get());
            sh.type = ShapeType::Cylinder;
            sh.size = Vec3(g->radius, g->radius, 0.5 * g->length);
            break;
          }
          case urdf::Geometry::MESH: {
            const auto* g = static_cast<const urdf::Mesh*>(col->geometry.get());
            sh.type = ShapeType::Mesh;
            sh.mesh = static_cast<int>(body_.meshes.size());
            body_.meshes.push_back(load_mesh(name, g->filename, Vec3(g->scale.x, g->scale.y, g->scale.z)));
            break;
          }
          default:
            fail_link(name, "unsupported <collision> geometry (allowed: box, cylinder, sphere, mesh)");
        }
        const Pose in_root = compose(li.in_root, local);
        sh.pos = to_body * (in_root.p - body_.ref_pos);
        sh.rot = (to_body * in_root.q).normalized();
        body_.shapes.push_back(sh);
      }
    }
  }

  static std::vector<urdf::CollisionSharedPtr> collisions(const urdf::LinkConstSharedPtr& link) {
    if (!link->collision_array.empty()) return link->collision_array;
    if (link->collision) return {link->collision};
    return {};
  }

  TriangleMesh load_mesh(const std::string& link, const std::string& uri, const Vec3& scale) const {
    const fs::path urdf_dir = fs::absolute(fs::path(path_)).parent_path();
    fs::path file;
    const std::string pkg = "package://", this_pkg = "package://regolith_twin/", file_uri = "file://";
    if (uri.compare(0, this_pkg.size(), this_pkg) == 0) {
      const std::string root = find_package_root(urdf_dir);
      if (root.empty())
        fail_link(link, "mesh '" + uri + "': no regolith_twin package.xml above " + urdf_dir.string());
      file = fs::path(root) / uri.substr(this_pkg.size());
    } else if (uri.compare(0, pkg.size(), pkg) == 0) {
      fail_link(link, "mesh '" + uri + "': only package://regolith_twin/ paths are resolved");
    } else if (uri.compare(0, file_uri.size(), file_uri) == 0) {
      file = uri.substr(file_uri.size());
    } else if (uri.find("://") != std::string::npos) {
      fail_link(link, "mesh '" + uri + "': unsupported URI scheme (use a relative path, package://regolith_twin/ or file://)");
    } else {
      file = fs::path(uri).is_absolute() ? fs::path(uri) : urdf_dir / uri;
    }
    if (lower(file.extension().string()) != ".stl")
      fail_link(link, "mesh '" + uri + "': unsupported mesh format (STL only)");
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) fail_link(link, "mesh file '" + file.string() + "' not found (from '" + uri + "')");
    if (!scale.allFinite() || scale.cwiseAbs().minCoeff() == 0)
      fail_link(link, "mesh '" + uri + "': <scale> " + vec_text(scale) + " must be finite and non-zero");
    try {
      return load_stl(file.string(), scale);
    } catch (const InputError& e) {
      fail_link(link, std::string("mesh: ") + e.what());
    }
  }

  std::string path_;
  const UrdfOverrides& ov_;
  urdf::ModelInterfaceSharedPtr model_;
  std::vector<LinkInfo> links_;
  BodyModel body_;
  double mass_ = 0;
  Vec3 com_ = Vec3::Zero();
  Mat3 inertia_ = Mat3::Zero();
};

}  // namespace

TriangleMesh load_stl(const std::string& path, const Vec3& scale) {
  const std::string data = read_file_limited(path, kMaxMeshBytes, "STL file");  // docs/files.md
  std::vector<RawTriangle> raw;
  // Binary when the size matches the facet count exactly (a binary header may
  // itself begin with "solid"); otherwise ASCII.
  const bool binary = data.size() >= 84 && data.size() == 84 + 50 * static_cast<std::size_t>(read_le32(data, 80));
  if (binary) {
    raw = read_binary_stl(data, read_le32(data, 80));
  } else {
    const std::size_t first = data.find_first_not_of(" \t\r\n");
    if (first == std::string::npos || lower(data.substr(first, 5)) != "solid")
      stl_fail(path, "not an STL file (binary size is not 84 + 50 x facet count, and no ASCII 'solid' header)");
    raw = read_ascii_stl(path, data.substr(first));
  }
  if (raw.empty()) stl_fail(path, "STL file has no facets");

  TriangleMesh mesh;
  std::map<std::array<double, 3>, int> index;  // identical vertices merged
  const bool flip = scale.x() * scale.y() * scale.z() < 0;
  for (std::size_t t = 0; t < raw.size(); ++t) {
    std::array<int, 3> tri;
    for (int v = 0; v < 3; ++v) {
      const Vec3 p = raw[t][v].cwiseProduct(scale);
      if (!p.allFinite()) stl_fail(path, "facet " + std::to_string(t + 1) + " has a non-finite vertex");
      const std::array<double, 3> key{p.x(), p.y(), p.z()};
      const auto [it, added] = index.emplace(key, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(p);
      tri[v] = it->second;
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;  // degenerate facet
    if (flip) std::swap(tri[1], tri[2]);
    mesh.triangles.push_back(tri);
  }
  if (mesh.triangles.empty()) stl_fail(path, "STL file has only degenerate facets");
  // Keep only the vertices of the remaining facets, in order of first use.
  std::vector<int> renumber(mesh.vertices.size(), -1);
  std::vector<Vec3> used;
  for (auto& tri : mesh.triangles)
    for (int& v : tri) {
      if (renumber[v] < 0) {
        renumber[v] = static_cast<int>(used.size());
        used.push_back(mesh.vertices[v]);
      }
      v = renumber[v];
    }
  mesh.vertices = std::move(used);
  return mesh;
}

BodyModel load_urdf_body(const std::string& path, const UrdfOverrides& ov) { return Loader(path, ov).load(); }

}  // namespace rt
