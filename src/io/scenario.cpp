// Scenario files: YAML -> Model + initial State, with errors that name the
// file, the key and the allowed range.
#include "regolith_twin/io/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/data_file.hpp"
#include "regolith_twin/io/generate.hpp"
#include "regolith_twin/io/snapshot.hpp"
#include "regolith_twin/io/urdf_body.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using Reader = YamlReader;

// Published materials (docs/model.md §9).
const std::map<std::string, Material>& presets() {
  static const std::map<std::string, Material> p = [] {
    std::map<std::string, Material> m;
    auto add = [&](const char* name, double density, double en, double et, double ms, double mr, double mt,
                   double beta) {
      Material x;
      x.name = name;
      x.density = density;
      x.eps_n = en;
      x.eps_t = et;
      x.mu_s = ms;
      x.mu_r = mr;
      x.mu_t = mt;
      x.beta = beta;
      m[name] = x;
    };
    add("gravel", 2430, 0.5, 0.5, 1.0, 1.05, 1.3, 1.0);
    add("moderate", 2430, 0.5, 0.5, 1.0, 1.05, 1.3, 0.2);
    add("glass_beads", 2480, 0.9, 1.0, 1.0, 1.05, 1.3, 0.2);
    add("glass_beads_b", 2480, 0.9, 1.0, 1.0, 2.0, 1.3, 0.1);
    return m;
  }();
  return p;
}

Material parse_material(const Reader& rd, const YAML::Node& node, const std::string& path, const std::string& name) {
  rd.only(node, path,
          {"preset", "density", "eps_n", "eps_t", "mu_s", "mu_r", "mu_t", "beta", "young", "poisson", "kt_over_kn",
           "ct_over_cn", "structure", "own_friction"});
  Material m;
  const std::string preset = rd.text(node, path, "preset", "");
  if (!preset.empty() && !material_preset(preset, m)) {
    std::string list;
    for (const auto& kv : presets()) list += (list.empty() ? "" : ", ") + kv.first;
    rd.fail(Reader::join(path, "preset"), "unknown material preset '" + preset + "' (known: " + list + ")");
  }
  m.name = name;
  m.density = rd.number(node, path, "density", m.density, 1e-3, 1e6);
  m.eps_n = rd.number(node, path, "eps_n", m.eps_n, 1e-3, 1);
  m.eps_t = rd.number(node, path, "eps_t", m.eps_t, 0, 1, true);
  m.mu_s = rd.number(node, path, "mu_s", m.mu_s, 0, 100);
  m.mu_r = rd.number(node, path, "mu_r", m.mu_r, 0, 100);
  m.mu_t = rd.number(node, path, "mu_t", m.mu_t, 0, 100);
  m.beta = rd.number(node, path, "beta", m.beta, 0, 10);
  m.young = rd.number(node, path, "young", m.young, 0, 1e13);
  m.poisson = rd.number(node, path, "poisson", m.poisson, -0.999, 0.499);
  m.kt_over_kn = rd.number(node, path, "kt_over_kn", m.kt_over_kn, 0, 10, true);
  m.ct_over_cn = rd.number(node, path, "ct_over_cn", m.ct_over_cn, -1, 10);
  m.structure = rd.boolean(node, path, "structure", m.structure);
  m.own_friction = rd.boolean(node, path, "own_friction", m.own_friction);
  return m;
}

int material_index(const Reader& rd, const Model& m, const YAML::Node& map, const std::string& path) {
  const std::string name = rd.text(map, path, "material", "");
  if (name.empty()) rd.fail(Reader::join(path, "material"), "missing (name of an entry under 'materials')");
  for (int i = 0; i < m.n_materials(); ++i)
    if (m.materials[i].name == name) return i;
  std::string list;
  for (const auto& x : m.materials) list += (list.empty() ? "" : ", ") + x.name;
  rd.fail(Reader::join(path, "material"), "unknown material '" + name + "' (defined: " + list + ")");
}

Vec3 unit(const Reader& rd, const Vec3& v, const std::string& key) {
  const double n = v.norm();
  if (!(n > 0)) rd.fail(key, "must be a non-zero vector");
  return v / n;
}

Wall parse_wall(const Reader& rd, const Model& m, const YAML::Node& w, const std::string& path) {
  rd.only(w, path,
          {"type", "name", "material", "point", "normal", "center", "base", "axis", "radius", "radius2", "length",
           "inner", "u", "half_u", "half_v"});
  Wall out;
  const std::string type =
      rd.choice(w, path, "type", "", {"plane", "disk", "cylinder", "cone", "rectangle", "sphere_shell"});
  out.name = rd.text(w, path, "name", path);
  out.law_material = material_index(rd, m, w, path);
  const Vec3 up = Vec3::UnitZ();
  if (type == "plane") {
    out.type = WallType::Plane;
    out.origin = rd.vec3(w, path, "point", Vec3::Zero(), true);
    out.axis = unit(rd, rd.vec3(w, path, "normal", up, true), Reader::join(path, "normal"));
  } else if (type == "disk" || type == "rectangle") {
    out.type = type == "disk" ? WallType::Disk : WallType::Rectangle;
    out.origin = rd.vec3(w, path, "center", Vec3::Zero(), true);
    out.axis = unit(rd, rd.vec3(w, path, "normal", up), Reader::join(path, "normal"));
    if (type == "disk") {
      out.radius = rd.number(w, path, "radius", 0, 0, kMaxSceneLength, true);
    } else {
      Vec3 u = rd.vec3(w, path, "u", out.axis.unitOrthogonal());
      u -= u.dot(out.axis) * out.axis;
      out.u = unit(rd, u, Reader::join(path, "u"));
      out.half_u = rd.number(w, path, "half_u", 0, 0, kMaxSceneLength, true);
      out.half_v = rd.number(w, path, "half_v", 0, 0, kMaxSceneLength, true);
    }
  } else if (type == "cylinder" || type == "cone") {
    out.type = type == "cylinder" ? WallType::Cylinder : WallType::Cone;
    out.origin = rd.vec3(w, path, "base", Vec3::Zero(), true);
    out.axis = unit(rd, rd.vec3(w, path, "axis", up), Reader::join(path, "axis"));
    out.radius = rd.number(w, path, "radius", 0, 0, kMaxSceneLength, true);
    out.radius2 = type == "cone" ? rd.number(w, path, "radius2", 0, 0, kMaxSceneLength) : out.radius;
    out.length = rd.number(w, path, "length", type == "cone" ? 1.0 : 0.0, type == "cone" ? 0 : -1, kMaxSceneLength,
                           type == "cone");
    out.inner = rd.boolean(w, path, "inner", true);
  } else {
    out.type = WallType::SphereShell;
    out.origin = rd.vec3(w, path, "center", Vec3::Zero(), true);
    out.radius = rd.number(w, path, "radius", 0, 0, kMaxSceneLength, true);
    out.inner = rd.boolean(w, path, "inner", true);
  }
  return out;
}

RadiusDist parse_radius(const Reader& rd, const YAML::Node& g, const std::string& path) {
  RadiusDist d;
  const YAML::Node r = g["radius"];
  const std::string key = Reader::join(path, "radius");
  if (!r) rd.fail(key, "missing (a number, or {mean, sigma, cut})");
  if (r.IsScalar()) {
    d.mean = rd.number(r, key, 1e-7, kMaxSceneLength);  // 0.1 um: below the finest dust
    return d;
  }
  rd.only(r, key, {"mean", "sigma", "cut"});
  if (!Reader::get(r, "mean")) rd.fail(Reader::join(key, "mean"), "missing (the mean radius, m)");
  d.mean = rd.number(r, key, "mean", 0, 1e-7, kMaxSceneLength);
  d.sigma = rd.number(r, key, "sigma", 0, 0, 0.9);
  d.cut = rd.number(r, key, "cut", 1.0, 0.1, 5);  // a narrower cut would reject almost every draw
  if (d.sigma * d.cut >= 1) rd.fail(key, "sigma * cut must be < 1 (radii must stay positive)");
  return d;
}

// The keys that give a fill's region, with their values, for messages.
std::string region_keys(const std::string& fp, const Region& r) {
  if (r.shape == RegionShape::Box)
    return Reader::join(fp, "lo") + " to " + Reader::join(fp, "hi") + ", " + Reader::num_text((r.hi - r.lo).x()) + " x " +
           Reader::num_text((r.hi - r.lo).y()) + " x " + Reader::num_text((r.hi - r.lo).z()) + " m";
  return Reader::join(fp, "radius") + " = " + Reader::num_text(r.radius) + " m, " + Reader::join(fp, "z") + " = [" +
         Reader::num_text(r.lo.z()) + ", " + Reader::num_text(r.hi.z()) + "] m";
}

Region parse_region(const Reader& rd, const YAML::Node& f, const std::string& path) {
  Region r;
  const std::string shape = rd.choice(f, path, "shape", "box", {"box", "cylinder"});
  if (shape == "box") {
    r.shape = RegionShape::Box;
    r.lo = rd.vec3(f, path, "lo", Vec3::Zero(), true);
    r.hi = rd.vec3(f, path, "hi", Vec3::Zero(), true);
    if (!((r.hi - r.lo).minCoeff() > 0)) rd.fail(Reader::join(path, "hi"), "every component must exceed lo");
  } else {
    r.shape = RegionShape::Cylinder;
    r.center = rd.vec3(f, path, "center", Vec3::Zero(), true);
    r.radius = rd.number(f, path, "radius", 0, 0, kMaxSceneLength, true);
    const YAML::Node z = f["z"];
    if (!z || !z.IsSequence() || z.size() != 2) rd.fail(Reader::join(path, "z"), "expected [z_min, z_max]");
    const double z0 = rd.number(z[0], Reader::join(path, "z[0]"), -kMaxSceneLength, kMaxSceneLength);
    const double z1 = rd.number(z[1], Reader::join(path, "z[1]"), z0, kMaxSceneLength, true);
    r.lo = Vec3(r.center.x() - r.radius, r.center.y() - r.radius, z0);
    r.hi = Vec3(r.center.x() + r.radius, r.center.y() + r.radius, z1);
  }
  return r;
}

// A random fill's `grading` (docs/scenes.md E.1, "Graded fills").
Grading parse_grading(const Reader& rd, const YAML::Node& f, const std::string& fp, const Region& region,
                      const RadiusDist& dist) {
  const std::string gp = Reader::join(fp, "grading");
  const YAML::Node g = rd.map(f, fp, "grading", true);
  rd.only(g, gp, {"surface", "base", "compaction", "center", "fine_depth", "fine_radius", "depth_rate", "radial_rate",
                  "max_scale"});
  Grading gr;
  if (!Reader::get(g, "surface")) rd.fail(Reader::join(gp, "surface"), "missing (z of the settled bed's surface, m)");
  gr.surface = rd.number(g, gp, "surface", 0, -kMaxSceneLength, kMaxSceneLength);
  gr.base = rd.number(g, gp, "base", region.lo.z(), -kMaxSceneLength, kMaxSceneLength);
  gr.compaction = rd.number(g, gp, "compaction", 1.0, 1e-3, 1.0);
  const YAML::Node c = g["center"];
  const Vec3 mid = region.shape == RegionShape::Cylinder ? region.center : Vec3(0.5 * (region.lo + region.hi));
  gr.center_x = mid.x();
  gr.center_y = mid.y();
  if (c) {
    if (!c.IsSequence() || c.size() != 2) rd.fail(Reader::join(gp, "center"), "expected [x, y] (m)");
    gr.center_x = rd.number(c[0], Reader::join(gp, "center[0]"), -kMaxSceneLength, kMaxSceneLength);
    gr.center_y = rd.number(c[1], Reader::join(gp, "center[1]"), -kMaxSceneLength, kMaxSceneLength);
  }
  gr.fine_depth = rd.number(g, gp, "fine_depth", 0, 0, kMaxSceneLength);
  gr.fine_radius = rd.number(g, gp, "fine_radius", 0, 0, kMaxSceneLength);
  gr.depth_rate = rd.number(g, gp, "depth_rate", 0, 0, 10);
  gr.radial_rate = rd.number(g, gp, "radial_rate", 0, 0, 10);
  gr.max_scale = rd.number(g, gp, "max_scale", 4, 1, 10);
  gr.mean_diameter = 2 * dist.mean;
  if (g["radial_rate"] && !g["fine_radius"])
    rd.fail(Reader::join(gp, "fine_radius"), "missing (the fine zone's radius around center, m; radial_rate needs it)");
  return gr;
}

// One `grains` entry: explicit grain, lattice fill or data file.
void parse_grains(const Reader& rd, Scenario& sc, const YAML::Node& g, const std::string& path,
                  std::mt19937_64& rng) {
  rd.only(g, path, {"name", "material", "radius", "position", "velocity", "omega", "fill", "file", "fixed"});
  Model& m = sc.model;
  GrainGroup grp;
  grp.name = rd.text(g, path, "name", path);
  grp.first = m.n_grains;
  const int mat = material_index(rd, m, g, path);
  const bool fixed = rd.boolean(g, path, "fixed", false);
  const Vec3 vel = rd.vec3(g, path, "velocity", Vec3::Zero());
  const Vec3 omg = rd.vec3(g, path, "omega", Vec3::Zero());
  std::vector<Vec3> pos;
  std::vector<double> radii;
  const int modes = int(bool(g["position"])) + int(bool(g["fill"])) + int(bool(g["file"]));
  if (modes != 1) rd.fail(path, "give exactly one of 'position', 'fill' or 'file'");
  if (g["position"]) {
    pos.push_back(rd.vec3(g, path, "position", Vec3::Zero(), true));
    radii.push_back(parse_radius(rd, g, path).mean);
  } else if (g["fill"]) {
    const std::string fp = Reader::join(path, "fill");
    const YAML::Node f = rd.map(g, path, "fill", true);
    rd.only(f, fp, {"shape", "lo", "hi", "center", "radius", "z", "count", "solid_fraction", "arrangement", "spacing",
                    "jitter", "gap", "grading"});
    const RadiusDist dist = parse_radius(rd, g, path);
    const Region region = parse_region(rd, f, fp);
    if (f["count"] && f["solid_fraction"])
      rd.fail(Reader::join(fp, "count"), "give either count or " + Reader::join(fp, "solid_fraction") + ", not both");
    const long count = rd.integer(f, fp, "count", 1000, 1, 50000000);
    const std::string arrangement = rd.choice(f, fp, "arrangement", "lattice", {"lattice", "random"});
    if (arrangement == "lattice") {
      for (const char* k : {"gap", "solid_fraction", "grading"})
        if (f[k]) rd.fail(Reader::join(fp, k), "applies to arrangement: random only");
      const double spacing = rd.number(f, fp, "spacing", 2.1 * dist.max(), 2 * dist.max(), kMaxSceneLength);
      const double jitter = rd.number(f, fp, "jitter", 0.05 * (spacing - 2 * dist.max()) + 0.01 * dist.mean, 0,
                                      0.5 * spacing);
      pos = lattice_sites(region, spacing, dist.max(), jitter, int(count), rng);
      if (long(pos.size()) < count)
        rd.fail(Reader::join(fp, "count"), std::to_string(count) + " grains do not fit in the region (room for " +
                                                std::to_string(pos.size()) + ") at " + Reader::join(fp, "spacing") +
                                                " = " + Reader::num_text(spacing) + " m (from " + Reader::join(path, "radius") +
                                                " " + Reader::num_text(dist.mean) + " m): make the region (" +
                                                region_keys(fp, region) + ") larger or the grains fewer");
      radii = draw_radii(dist, int(pos.size()), rng);
    } else {
      // Random sequential addition (docs/scenes.md E.1): radii first, then
      // each grain at a uniform position clear of the earlier ones by `gap`.
      for (const char* k : {"spacing", "jitter"})
        if (f[k]) rd.fail(Reader::join(fp, k), "applies to arrangement: lattice only");
      const double gap = rd.number(f, fp, "gap", 0.1 * dist.mean, 0, kMaxSceneLength);
      Grading grading;
      const bool graded = bool(f["grading"]);
      if (graded) grading = parse_grading(rd, f, fp, region, dist);
      RandomFill fill;
      if (f["solid_fraction"]) {
        // The random close packing of spheres is 0.64; sequential addition jams near 0.38.
        const double fraction = rd.number(f, fp, "solid_fraction", 0, 1e-6, 0.35);
        const double mean_volume = 4.0 / 3.0 * kPi * std::pow(dist.mean, 3);
        if (fraction * region_volume(region) / mean_volume > 5e7)
          rd.fail(Reader::join(fp, "solid_fraction"), "would generate more than 50,000,000 grains in the region (" +
                                                          region_keys(fp, region) + ")");
        fill = random_fraction(region, dist, fraction, 0.0, gap, 20000, rng, graded ? &grading : nullptr);
        double volume = 0;
        for (const double r : fill.radii) volume += 4.0 / 3.0 * kPi * r * r * r;
        if (fill.sites.empty() || volume < fraction * region_volume(region))
          rd.fail(Reader::join(fp, "solid_fraction"),
                  Reader::num_text(fraction) + " is not reached at random in the region (room found for " +
                      std::to_string(fill.sites.size()) + " grains, a solid fraction of " +
                      Reader::num_text(volume / region_volume(region)) + ", in 20000 draws each): make it smaller");
      } else {
        const std::vector<double> drawn = draw_radii(dist, int(count), rng);
        fill = random_sites(region, drawn, 0.0, gap, 20000, rng, graded ? &grading : nullptr);
        if (long(fill.sites.size()) < count)
          rd.fail(Reader::join(fp, "count"), std::to_string(count) +
                                                  " grains do not fit at random in the region (room found for " +
                                                  std::to_string(fill.sites.size()) +
                                                  " in 20000 draws each): make the region larger");
      }
      pos = std::move(fill.sites);
      radii = std::move(fill.radii);
    }
  } else {
    std::string file = rd.text(g, path, "file", "");
    // A relative path is taken from the scenario file's folder.
    const auto slash = rd.source().rfind('/');
    if (!file.empty() && file[0] != '/' && slash != std::string::npos) file = rd.source().substr(0, slash + 1) + file;
    if (is_snapshot(file)) {
      for (const auto& rec : read_snapshot(file)) {
        pos.push_back(rec.pos);
        radii.push_back(rec.radius);
      }
    } else {
      for (const auto& rec : read_sphere_data(file)) {
        pos.push_back(rec.pos);
        radii.push_back(rec.radius);
      }
    }
  }
  for (size_t k = 0; k < pos.size(); ++k) add_grain(m, radii[k], mat, fixed);
  grp.count = m.n_grains - grp.first;
  sc.groups.push_back(grp);
  // Kinematics are kept aside until the state exists.
  for (size_t k = 0; k < pos.size(); ++k) {
    sc.initial.pos.push_back(pos[k]);
    sc.initial.vel.push_back(vel);
    sc.initial.omega.push_back(omg);
  }
}

// Orientation from {rpy: [roll, pitch, yaw]} in radians, {rpy_deg: [...]} in
// degrees (fixed axes x, then y, then z, as URDF), or {quaternion: [w, x, y, z]}.
Quat parse_orientation(const Reader& rd, const YAML::Node& parent, const std::string& path, const std::string& key) {
  const YAML::Node o = rd.map(parent, path, key, false);
  if (!o) return Quat::Identity();
  const std::string p = Reader::join(path, key);
  rd.only(o, p, {"rpy", "rpy_deg", "quaternion"});
  if (o.size() != 1) rd.fail(p, "give exactly one of rpy (rad), rpy_deg or quaternion [w, x, y, z]");
  if (o["quaternion"]) {
    const YAML::Node qn = o["quaternion"];
    if (!qn.IsSequence() || qn.size() != 4) rd.fail(p + ".quaternion", "expected [w, x, y, z]");
    Quat q(rd.number(qn[0], p + ".quaternion[0]", -1e6, 1e6), rd.number(qn[1], p + ".quaternion[1]", -1e6, 1e6),
           rd.number(qn[2], p + ".quaternion[2]", -1e6, 1e6), rd.number(qn[3], p + ".quaternion[3]", -1e6, 1e6));
    if (!(q.norm() > 0)) rd.fail(p + ".quaternion", "must be non-zero");
    return q.normalized();
  }
  const bool deg = bool(o["rpy_deg"]);
  const Vec3 a = rd.vec3(o, p, deg ? "rpy_deg" : "rpy", Vec3::Zero(), true) * (deg ? kPi / 180 : 1.0);
  return Quat(Eigen::AngleAxisd(a.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(a.y(), Vec3::UnitY()) *
              Eigen::AngleAxisd(a.x(), Vec3::UnitX()));
}

// An inline collision shape: {type: box|sphere|cylinder|ellipsoid, size, position, orientation}.
// Sizes are full extents for a box, [a, b, c] semi-axes for an ellipsoid,
// radius for a sphere, [radius, length] for a cylinder along its z axis.
Shape parse_shape(const Reader& rd, const YAML::Node& n, const std::string& path) {
  rd.only(n, path, {"type", "size", "radius", "length", "position", "orientation"});
  Shape sh;
  const std::string type = rd.choice(n, path, "type", "", {"box", "sphere", "cylinder", "ellipsoid"});
  if (type == "box" || type == "ellipsoid") {
    const Vec3 v = rd.vec3(n, path, "size", Vec3::Zero(), true);
    for (int k = 0; k < 3; ++k)
      if (!(v[k] > 0)) rd.fail(Reader::join(path, "size"), "every extent must be > 0 m");
    sh.type = type == "box" ? ShapeType::Box : ShapeType::Ellipsoid;
    sh.size = type == "box" ? Vec3(v / 2) : v;
  } else if (type == "sphere") {
    sh.type = ShapeType::Sphere;
    sh.size = Vec3::Constant(rd.number(n, path, "radius", 0, 0, kMaxSceneLength, true));
    if (!n["radius"]) rd.fail(Reader::join(path, "radius"), "missing (m, > 0)");
  } else {
    sh.type = ShapeType::Cylinder;
    const double r = rd.number(n, path, "radius", 0, 0, kMaxSceneLength, true), l = rd.number(n, path, "length", 0, 0, kMaxSceneLength, true);
    if (!n["radius"] || !n["length"]) rd.fail(path, "a cylinder needs radius and length (m, > 0)");
    sh.size = Vec3(r, r, l / 2);
  }
  sh.pos = rd.vec3(n, path, "position", Vec3::Zero());
  sh.rot = parse_orientation(rd, n, path, "orientation");
  sh.link = path;
  return sh;
}

// A rigid body from a URDF file or from inline shapes. The pose is that of
// the description's reference frame (URDF root link, or the inline frame).
void parse_body(const Reader& rd, Scenario& sc, const YAML::Node& n, const std::string& path) {
  rd.only(n, path,
          {"name", "urdf", "link_box", "shapes", "mass", "inertia", "center_of_mass", "fixed", "material", "position",
           "orientation", "velocity", "omega", "carve"});
  Model& m = sc.model;
  BodyModel b;
  const bool from_urdf = bool(n["urdf"]);
  if (from_urdf == bool(n["shapes"])) rd.fail(path, "give exactly one of 'urdf' (a file) or 'shapes' (a list)");
  b.fixed = rd.boolean(n, path, "fixed", false);
  if (from_urdf) {
    std::string file = rd.text(n, path, "urdf", "");
    const auto slash = rd.source().rfind('/');
    if (!file.empty() && file[0] != '/' && slash != std::string::npos && !std::ifstream(file))
      file = rd.source().substr(0, slash + 1) + file;
    UrdfOverrides ov;
    if (const YAML::Node lb = rd.map(n, path, "link_box", false))
      for (const auto& kv : lb) {
        const std::string link = kv.first.as<std::string>();
        ov.box_size[link] = rd.vec3(lb, Reader::join(path, "link_box"), link, Vec3::Zero(), true);
      }
    try {
      b = load_urdf_body(file, ov);
    } catch (const InputError& e) {
      rd.fail(Reader::join(path, "urdf"), e.what());
    }
    b.fixed = rd.boolean(n, path, "fixed", false);
    b.urdf_file = file;
  } else {
    const YAML::Node shapes = n["shapes"];
    if (!shapes.IsSequence() || shapes.size() == 0) rd.fail(Reader::join(path, "shapes"), "expected a non-empty list");
    for (size_t k = 0; k < shapes.size(); ++k)
      b.shapes.push_back(parse_shape(rd, shapes[k], Reader::join(path, "shapes[" + std::to_string(k) + "]")));
    if (!b.fixed) {
      b.mass = rd.number(n, path, "mass", 0, 1e-9, kMaxSceneMass);
      if (!n["mass"]) rd.fail(Reader::join(path, "mass"), "missing (kg, > 0)");
      b.inertia = rd.vec3(n, path, "inertia", Vec3::Zero(), true);  // principal moments about the shapes' axes
      const Vec3& I = b.inertia;
      if (!(I.minCoeff() > 0)) rd.fail(Reader::join(path, "inertia"), "principal moments must be > 0 kg m^2");
      for (int k = 0; k < 3; ++k)
        if (I[k] > I[(k + 1) % 3] + I[(k + 2) % 3])
          rd.fail(Reader::join(path, "inertia"), "principal moments violate I_a <= I_b + I_c (not a physical body)");
      const Vec3 com = rd.vec3(n, path, "center_of_mass", Vec3::Zero());
      for (Shape& sh : b.shapes) sh.pos -= com;
      b.ref_pos = com;
    }
    b.ref_frame = "base";
  }
  b.name = rd.text(n, path, "name", b.name.empty() ? path : b.name);
  b.material = material_index(rd, m, n, path);
  try {
    finalize_body(b);
  } catch (const InputError& e) {
    rd.fail(path, e.what());
  }
  // Initial pose and velocity of the reference frame.
  const Vec3 ref_pos = rd.vec3(n, path, "position", Vec3::Zero());
  const Quat ref_q = parse_orientation(rd, n, path, "orientation");
  BodyState bs;
  bs.q = (ref_q * b.ref_rot).normalized();
  bs.pos = ref_pos + ref_q * b.ref_pos;
  const Vec3 v = rd.vec3(n, path, "velocity", Vec3::Zero()), w = rd.vec3(n, path, "omega", Vec3::Zero());
  for (const auto& other : m.bodies)
    if (other.name == b.name) rd.fail(Reader::join(path, "name"), "duplicate body name '" + b.name + "'");
  if (rd.boolean(n, path, "carve", false)) sc.carve.push_back(int(m.bodies.size()));
  m.bodies.push_back(b);
  set_body_velocity(m.bodies.back(), bs, v, w);
  sc.initial.bodies.push_back(bs);
}

void apply_override(YAML::Node root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set '" + assignment + "': expected dotted.key=value");
  const std::string key = assignment.substr(0, eq);
  YAML::Node value;
  const std::string text = assignment.substr(eq + 1);
  if (text.size() > kMaxYamlBytes)
    throw InputError("--set '" + key + "=...': value larger than the limit of " + std::to_string(kMaxYamlBytes) +
                     " bytes");
  check_yaml_nesting("--set '" + assignment + "'", text);
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError("--set '" + assignment + "': value is not valid YAML: " + e.what());
  }
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  // Walk with fresh handles (yaml-cpp assignment rebinds). A numeric part
  // indexes a list: --set stages.0.duration=0.1
  std::function<void(YAML::Node, size_t)> set = [&](YAML::Node node, size_t i) {
    const std::string& part = parts[i];
    const bool index = !part.empty() && part.find_first_not_of("0123456789") == std::string::npos;
    if (index && !node.IsSequence()) throw InputError("--set '" + assignment + "': '" + part + "' indexes a non-list");
    // A key needs a mapping (or nothing yet): a list entry or a document that
    // is a single value has no keys (yaml-cpp would throw past InputError).
    if (!index && !node.IsMap() && !node.IsNull())
      throw InputError("--set '" + assignment + "': '" + part + "' is a key of something that is not a mapping");
    if (index && (part.size() > 9 || std::stoul(part) >= node.size()))  // std::stoul throws past 2^64
      throw InputError("--set '" + assignment + "': index " + part + " is past the end of the list");
    if (i + 1 == parts.size()) {
      if (index)
        node[std::stoul(part)] = value;
      else
        node[part] = value;
      return;
    }
    if (index) {
      set(node[std::stoul(part)], i + 1);
      return;
    }
    YAML::Node child = node[part];
    if (!child || !(child.IsMap() || child.IsSequence())) {
      node[part] = YAML::Node(YAML::NodeType::Map);
      child = node[part];
    }
    set(child, i + 1);
  };
  set(root, 0);
}

}  // namespace

std::string body_names_text(const Model& m) {
  std::vector<std::string> names;
  for (const BodyModel& b : m.bodies) names.push_back(b.name);
  return Reader::entry_names("bodies", names);
}

bool material_preset(const std::string& name, Material& out) {
  const auto it = presets().find(name);
  if (it == presets().end()) return false;
  out = it->second;
  return true;
}

int remove_grains(Model& m, State& s, const std::vector<uint8_t>& drop, std::vector<GrainGroup>& groups,
                  std::vector<int>* old_to_new_out) {
  std::vector<int> local;
  std::vector<int>& old_to_new = old_to_new_out ? *old_to_new_out : local;
  const int removed = remove_grains(m, s, drop, &old_to_new);
  if (removed == 0) return 0;
  // Groups are ranges of grain ids: each keeps its surviving grains.
  std::vector<int> keep;
  for (int i = 0; i < int(old_to_new.size()); ++i)
    if (old_to_new[i] >= 0) keep.push_back(i);
  for (GrainGroup& g : groups) {
    const int first = int(std::lower_bound(keep.begin(), keep.end(), g.first) - keep.begin());
    const int last = int(std::lower_bound(keep.begin(), keep.end(), g.first + g.count) - keep.begin());
    g.first = first;
    g.count = last - first;
  }
  return removed;
}

int remove_grains(Scenario& sc, State& s, const std::vector<uint8_t>& drop) {
  return remove_grains(sc.model, s, drop, sc.groups);
}

const GrainGroup* Scenario::group(const std::string& n) const {
  for (const auto& g : groups)
    if (g.name == n) return &g;
  return nullptr;
}

namespace {

// The keys that place a wall, and a grains entry, for the messages below.
std::string wall_keys(const Wall& w, size_t k) {
  const std::string p = "walls[" + std::to_string(k) + "].";
  switch (w.type) {
    case WallType::Plane: return p + "point, " + p + "normal";
    case WallType::Disk: return p + "center, " + p + "normal, " + p + "radius";
    case WallType::Rectangle: return p + "center, " + p + "normal, " + p + "u, " + p + "half_u, " + p + "half_v";
    case WallType::Cylinder: return p + "base, " + p + "axis, " + p + "radius, " + p + "length";
    case WallType::Cone: return p + "base, " + p + "axis, " + p + "radius, " + p + "radius2, " + p + "length";
    default: return p + "center, " + p + "radius";
  }
}

std::string grain_keys(const YAML::Node& root, size_t g) {
  const std::string p = "grains[" + std::to_string(g) + "].";
  const YAML::Node e = root["grains"][g];
  if (e["position"]) return p + "position, " + p + "radius";
  if (e["file"]) return p + "file";
  const YAML::Node f = e["fill"];
  if (f && f["center"]) return p + "fill.center, " + p + "fill.radius, " + p + "fill.z, " + p + "radius";
  return p + "fill.lo, " + p + "fill.hi, " + p + "fill.spacing, " + p + "radius";
}

// Grains that start where no step could sort them out (docs/scenes.md,
// "Input ranges"): a centre on the far side of a wall's surface, or two
// grains overlapping by more than half the smaller radius (coincident
// grains; two glued grains exert no force on each other and may). Refused naming the keys that place them, before any step.
void check_start_positions(const Reader& rd, const YAML::Node& root, const Scenario& sc) {
  const Model& m = sc.model;
  const State& s = sc.initial;
  const auto group_of = [&](int i) {
    for (size_t g = 0; g < sc.groups.size(); ++g)
      if (i >= sc.groups[g].first && i < sc.groups[g].first + sc.groups[g].count) return g;
    return size_t(0);
  };
  char b[160];
  for (size_t w = 0; w < m.walls.size(); ++w) {
    int count = 0, first = -1;
    for (int i = 0; i < m.n_grains; ++i)
      if (wall_gap(m.walls[w], s.pos[i], m.grain_radius[i]).overlap > m.grain_radius[i]) {
        if (first < 0) first = i;
        ++count;
      }
    if (count == 0) continue;
    const size_t g = group_of(first);
    std::snprintf(b, sizeof b, "%d grain(s) start with their centre beyond the surface of walls[%zu] ('%s'), the first at (%.4g, %.4g, %.4g) m",
                  count, w, m.walls[w].name.c_str(), s.pos[first].x(), s.pos[first].y(), s.pos[first].z());
    rd.fail("grains[" + std::to_string(g) + "]", std::string(b) + ": the wall (" + wall_keys(m.walls[w], w) +
                                                     ") and the grains (" + grain_keys(root, g) + ") do not agree");
  }
  // Coincident grains: a grid of cells two of the largest radii wide.
  if (m.n_grains < 2) return;
  double rmax = 0;
  for (int i = 0; i < m.n_grains; ++i) rmax = std::max(rmax, m.grain_radius[i]);
  const double cell = 2 * rmax;
  std::unordered_map<long long, std::vector<int>> grid;
  const auto key = [&](long long x, long long y, long long z) { return (x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL); };
  const auto coord = [&](double v) { return (long long)std::floor(v / cell); };
  for (int i = 0; i < m.n_grains; ++i)
    grid[key(coord(s.pos[i].x()), coord(s.pos[i].y()), coord(s.pos[i].z()))].push_back(i);
  for (int i = 0; i < m.n_grains; ++i) {
    const long long cx = coord(s.pos[i].x()), cy = coord(s.pos[i].y()), cz = coord(s.pos[i].z());
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (const int j : it->second) {
            if (j <= i || (held(m, i) && held(m, j))) continue;  // glued grains never meet
            const double ri = m.grain_radius[i], rj = m.grain_radius[j];
            const double overlap = ri + rj - (s.pos[i] - s.pos[j]).norm();
            if (overlap <= 0.5 * std::min(ri, rj)) continue;
            const size_t gi = group_of(i), gj = group_of(j);
            std::snprintf(b, sizeof b, "grains %d and %d start overlapping by %.3g m (more than half the smaller radius) at (%.4g, %.4g, %.4g) m",
                          i, j, overlap, s.pos[i].x(), s.pos[i].y(), s.pos[i].z());
            rd.fail("grains[" + std::to_string(gi) + "]",
                    std::string(b) + ": no step can part them; place them apart (" + grain_keys(root, gi) +
                        (gi != gj ? "; " + grain_keys(root, gj) : std::string()) + ")");
          }
        }
  }
}

Scenario interpret_scenario(const YAML::Node& root, const std::string& source, const DerivedContact& derived) {
  const Reader rd(source);
  if (!root || !root.IsMap()) throw InputError(source + ": expected a YAML mapping at the top level");
  rd.only(root, "",
          {"name", "seed", "gravity", "contact", "guards", "sleep", "schedule", "free_flight", "periodic", "gas",
           "materials", "walls", "bodies", "grains", "stages", "output"});
  Scenario sc;
  sc.file = source;
  sc.name = rd.text(root, "", "name", "scenario");
  sc.seed = static_cast<uint64_t>(rd.integer(root, "", "seed", 1, 0, std::numeric_limits<long>::max()));
  std::mt19937_64 rng(sc.seed);
  Model& m = sc.model;
  m.gravity = rd.vec3(root, "", "gravity", Vec3(0, 0, -9.81));

  // Materials (an ordered mapping name -> fields).
  const YAML::Node mats = rd.map(root, "", "materials", true);
  for (const auto& kv : mats) {
    const std::string name = kv.first.as<std::string>();
    if (!kv.second.IsMap()) rd.fail("materials." + name, "expected a mapping of material fields");
    m.materials.push_back(parse_material(rd, kv.second, "materials." + name, name));
  }

  // Walls.
  if (const YAML::Node walls = root["walls"]) {
    if (!walls.IsSequence()) rd.fail("walls", "expected a list of walls");
    for (size_t i = 0; i < walls.size(); ++i)
      m.walls.push_back(parse_wall(rd, m, walls[i], "walls[" + std::to_string(i) + "]"));
  }

  // Bodies.
  if (const YAML::Node bodies = root["bodies"]) {
    if (!bodies.IsSequence()) rd.fail("bodies", "expected a list of bodies");
    for (size_t i = 0; i < bodies.size(); ++i) parse_body(rd, sc, bodies[i], "bodies[" + std::to_string(i) + "]");
  }

  // Grains.
  const YAML::Node grains = root["grains"];
  if (!m.bodies.empty() && !grains) {
    // a scene of bodies only
  } else if (!grains || !grains.IsSequence() || grains.size() == 0) {
    rd.fail("grains", "expected a non-empty list");
  }
  for (size_t i = 0; grains && i < grains.size(); ++i)
    parse_grains(rd, sc, grains[i], "grains[" + std::to_string(i) + "]", rng);

  // Contact law, stiffness and time step.
  const YAML::Node c = rd.map(root, "", "contact", false);
  rd.only(c, "contact", {"model", "kn", "body_kn", "v_max", "x_max", "steps_per_contact", "dt", "skin", "partitions"});
  m.contact_model = rd.choice(c, "contact", "model", "linear", {"linear", "hertz_mindlin"}) == "linear"
                        ? ContactModel::Linear
                        : ContactModel::HertzMindlin;
  double mean_mass = 0, min_r = 1e300;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    mean_mass += 4.0 / 3.0 * kPi * r * r * r * m.materials[m.grain_material[i]].density;
    min_r = std::min(min_r, r);
  }
  if (m.n_grains == 0) {
    if (!Reader::get(c, "kn") || !Reader::get(c, "dt") || c["kn"].Scalar() == "rule")
      rd.fail("contact", "a scene without grains needs explicit contact.kn (N/m) and contact.dt (s)");
    mean_mass = 1;
    min_r = 1;
  } else {
    mean_mass /= m.n_grains;
  }
  sc.v_ref = rd.number(c, "contact", "v_max", 1.0, 1e-6, 1e5);
  const double x_max = rd.number(c, "contact", "x_max", 0.01, 1e-6, 0.5) * min_r;
  if (derived.kn > 0 && Reader::get(c, "kn"))
    rd.fail("contact.kn", "set from " + derived.by + " in this scene: remove it here");
  if (derived.dt > 0 && Reader::get(c, "dt"))
    rd.fail("contact.dt", "set from " + derived.by + " in this scene: remove it here");
  if (derived.kn > 0)
    m.kn = derived.kn;
  else if (Reader::get(c, "kn") && !(c["kn"].IsScalar() && c["kn"].Scalar() == "rule"))
    m.kn = rd.number(c["kn"], "contact.kn", 1e-6, kMaxSceneStiffness);
  else
    m.kn = kn_rule(mean_mass, sc.v_ref, x_max);
  const double n_steps = rd.number(c, "contact", "steps_per_contact", 30, 1, 1e6);
  if (derived.dt > 0) {
    m.dt = derived.dt;
  } else if (Reader::get(c, "dt")) {
    m.dt = rd.number(c["dt"], "contact.dt", 0, 1, true);
  } else if (m.contact_model == ContactModel::Linear) {
    m.dt = dt_rule(mean_mass, m.kn, n_steps);
  } else {
    rd.fail("contact.dt", "missing: the Hertz–Mindlin law needs an explicit dt");
  }
  // Body–body stiffness of one shape pair (docs/model.md §6); absent: the scene k_n.
  m.body_kn = rd.number(c, "contact", "body_kn", 0, 0, kMaxSceneStiffness, true);
  m.skin = rd.number(c, "contact", "skin", 0, 0, 1);
  if (m.skin > 0 && m.skin < 1e-9) rd.fail("contact.skin", "value below 1e-9 m: give 0 (the default list skin) or a skin of at least 1e-9 m");
  m.partitions = int(rd.integer(c, "contact", "partitions", 4, 1, 256));

  const YAML::Node gd = rd.map(root, "", "guards", false);
  rd.only(gd, "guards",
          {"max_overlap_ratio", "allow_under_resolved", "max_body_step_ratio", "max_grain_step_ratio",
           "max_body_overlap_ratio", "max_contacts_per_grain", "max_energy_growth", "energy_check_every"});
  m.guards.max_overlap_ratio = rd.number(gd, "guards", "max_overlap_ratio", 0.25, 0, 2, true);
  m.guards.max_body_step_ratio = rd.number(gd, "guards", "max_body_step_ratio", 1.0, 0, 100);
  m.guards.allow_under_resolved = rd.boolean(gd, "guards", "allow_under_resolved", false);
  m.guards.max_grain_step_ratio = rd.number(gd, "guards", "max_grain_step_ratio", 1.0, 0, 100);
  m.guards.max_body_overlap_ratio = rd.number(gd, "guards", "max_body_overlap_ratio", 1.0, 0, 100);
  m.guards.max_contacts_per_grain = int(rd.integer(gd, "guards", "max_contacts_per_grain", 0, -1, 100000));
  m.guards.max_energy_growth = rd.number(gd, "guards", "max_energy_growth", 0.1, 0, 1e6);
  m.guards.energy_check_every = int(rd.integer(gd, "guards", "energy_check_every", 1000, 1, 1000000000));

  // Sleeping of quiescent regions (docs/model.md §16).
  const YAML::Node sl = rd.map(root, "", "sleep", false);
  rd.only(sl, "sleep", {"enabled", "speed", "time", "force", "cell", "check_every", "at_start"});
  SleepParams& sp = m.sleep;
  sp.enabled = rd.boolean(sl, "sleep", "enabled", false);
  sp.speed = rd.number(sl, "sleep", "speed", sp.speed, 0, kMaxSceneSpeed, true);
  sp.time = rd.number(sl, "sleep", "time", sp.time, 0, kMaxSceneDuration);
  sp.force = rd.number(sl, "sleep", "force", sp.force, 0, 1e9, true);
  sp.cell = rd.number(sl, "sleep", "cell", sp.cell, 0, kMaxSceneLength);
  sp.check_every = int(rd.integer(sl, "sleep", "check_every", sp.check_every, 1, 1000000));
  sp.at_start = rd.boolean(sl, "sleep", "at_start", sp.at_start);

  // Stiffness schedule (docs/model.md §17).
  const YAML::Node sh = rd.map(root, "", "schedule", false);
  rd.only(sh, "schedule", {"enabled", "speed", "margin", "floor", "after", "check_every", "max_injected"});
  ScheduleParams& q = m.schedule;
  q.enabled = rd.boolean(sh, "schedule", "enabled", false);
  q.speed = rd.number(sh, "schedule", "speed", derived.design_speed > 0 ? derived.design_speed : sc.v_ref, 0, 1e5,
                      true);
  q.margin = rd.number(sh, "schedule", "margin", q.margin, 1, 100);
  q.floor = rd.number(sh, "schedule", "floor", q.floor, 1e-8, 1);
  q.after = rd.number(sh, "schedule", "after", q.after, 0, kMaxSceneDuration);
  q.check_every = int(rd.integer(sh, "schedule", "check_every", q.check_every, 1, 1000000));
  q.max_injected = rd.number(sh, "schedule", "max_injected", q.max_injected, 0, 1e6);

  // Free flight (docs/model.md §18).
  const YAML::Node ff = rd.map(root, "", "free_flight", false);
  rd.only(ff, "free_flight", {"enabled", "reach_cells"});
  m.free_flight.enabled = rd.boolean(ff, "free_flight", "enabled", false);
  m.free_flight.reach_cells = int(rd.integer(ff, "free_flight", "reach_cells", m.free_flight.reach_cells, 1, 16));

  // Periodic boundaries (docs/model.md §11.1): periodic.x / periodic.y = [lo, hi].
  const YAML::Node per = rd.map(root, "", "periodic", false);
  rd.only(per, "periodic", {"x", "y"});
  for (int a = 0; a < 2; ++a) {
    const std::string key = a == 0 ? "x" : "y";
    const YAML::Node n = Reader::get(per, key);
    if (!n) continue;
    const std::string path = "periodic." + key;
    if (!n.IsSequence() || n.size() != 2) rd.fail(path, "expected [lo, hi] (m)");
    const double lo = rd.number(n[0], path + "[0]", -kMaxSceneLength, kMaxSceneLength);
    const double hi = rd.number(n[1], path + "[1]", lo, kMaxSceneLength, true);
    (a == 0 ? m.periodic.x : m.periodic.y) = true;
    m.periodic.lo[a] = lo;
    m.periodic.length[a] = hi - lo;
  }

  // A gas flowing over the grains (docs/model.md §10.1).
  if (const YAML::Node gas = rd.map(root, "", "gas", false)) {
    rd.only(gas, "gas", {"density", "viscosity", "sound_speed", "gamma", "temperature_ratio", "direction", "u0",
                         "shear", "u_log", "h_log", "anchor_z", "drag", "lift", "radial", "nozzle",
                         "density_length"});
    GasFlowParams g;
    g.density = rd.number(gas, "gas", "density", 0, 0, 1e4, true);
    g.viscosity = rd.number(gas, "gas", "viscosity", 0, 0, 1e3, true);
    g.sound_speed = rd.number(gas, "gas", "sound_speed", 0, 0, kMaxSceneSpeed, true);
    if (!(g.density > 0) || !(g.viscosity > 0) || !(g.sound_speed > 0))
      rd.fail("gas", "density (kg/m^3), viscosity (Pa s) and sound_speed (m/s) are required");
    g.gamma = rd.number(gas, "gas", "gamma", g.gamma, 1, 10, true);
    g.tp_over_tg = rd.number(gas, "gas", "temperature_ratio", g.tp_over_tg, 0, 1e3, true);
    g.direction = rd.vec3(gas, "gas", "direction", Vec3::UnitX());
    if (g.direction.z() != 0 || !(g.direction.norm() > 0))
      rd.fail("gas.direction", "expected a horizontal direction [x, y, 0], not zero");
    g.u0 = rd.number(gas, "gas", "u0", 0, -1e5, 1e5);
    g.shear = rd.number(gas, "gas", "shear", 0, -1e9, 1e9);
    g.u_log = rd.number(gas, "gas", "u_log", 0, -1e5, 1e5);
    g.h_log = rd.number(gas, "gas", "h_log", 0, 0, kMaxSceneLength);
    if (g.u_log != 0 && !(g.h_log > 0)) rd.fail("gas.h_log", "required (> 0 m) with u_log");
    g.anchor_z = rd.number(gas, "gas", "anchor_z", 0, -kMaxSceneLength, kMaxSceneLength);
    g.drag = rd.boolean(gas, "gas", "drag", true);
    g.lift = rd.boolean(gas, "gas", "lift", true);
    g.radial = rd.boolean(gas, "gas", "radial", false);
    g.nozzle = rd.vec3(gas, "gas", "nozzle", Vec3::Zero());
    g.density_length = rd.number(gas, "gas", "density_length", 0, 0, kMaxSceneLength);
    if ((g.radial || g.density_length > 0) && !YamlReader::get(gas, "nozzle"))
      rd.fail("gas.nozzle", "required with gas.radial or gas.density_length: the nozzle's position [x, y, z] (m)");
    m.fields.push_back(std::make_shared<GasField>(g));
  }

  try {
    finalize_model(m);
  } catch (const InputError& e) {  // the model's own checks (a periodic box too short, ...): name the file
    throw InputError(source + ": " + e.what());
  }
  sc.scene_kn = m.kn;
  sc.scene_body_kn = m.body_kn;
  sc.scene_dt = m.dt;

  // Resolution report: warn below 10 steps per contact, refuse below 4.
  sc.resolution = pair_resolution(m, sc.v_ref);
  std::string mat_keys;
  for (const Material& mat : m.materials) mat_keys += (mat_keys.empty() ? "" : ", ") + std::string("materials.") + mat.name;
  for (const auto& r : sc.resolution) {
    std::ostringstream os;
    os << r.label << ": " << r.steps << " steps per contact";
    if (r.steps < m.guards.min_steps_per_contact_refuse && !m.guards.allow_under_resolved)
      rd.fail("contact.dt", os.str() +
                                " (below 4; set guards.allow_under_resolved: true to run anyway). The contact time "
                                "of a pair comes from its masses and damping (" + mat_keys +
                                ": density, eps_n; the grains' radius; bodies[i].mass), k_n (contact.kn, "
                                "contact.v_max, contact.x_max, contact.body_kn) and dt (contact.dt, "
                                "contact.steps_per_contact)");
    if (r.steps < m.guards.min_steps_per_contact_warn) sc.warnings.push_back(os.str() + " (below 10)");
  }

  // Initial state.
  std::vector<Vec3> pos = std::move(sc.initial.pos), vel = std::move(sc.initial.vel),
                    omg = std::move(sc.initial.omega);
  std::vector<BodyState> bodies = std::move(sc.initial.bodies);
  sc.initial = make_state(m);
  sc.initial.bodies = bodies;
  sc.initial.pos = pos;
  sc.initial.vel = vel;
  sc.initial.omega = omg;

  check_start_positions(rd, root, sc);

  // Bodies buried in a bed ('carve: true'): the grains they overlap make room.
  if (!sc.carve.empty()) {
    std::vector<uint8_t> drop(m.n_grains, 0);
    for (const int b : sc.carve) {
      const BodyModel& bm = m.bodies[b];
      const BodyState& bs = sc.initial.bodies[b];
      for (int i = 0; i < m.n_grains; ++i) {
        // Beyond the bounding sphere no shape can overlap (a mesh's gap
        // searches all its triangles: an inside test needs the nearest one).
        if ((sc.initial.pos[i] - bs.pos).norm() > bm.bound_radius + m.grain_radius[i]) continue;
        for (const Shape& sh : bm.shapes)
          if (shape_gap(bm, sh, bs.q.conjugate() * (sc.initial.pos[i] - bs.pos), m.grain_radius[i]).overlap > 0)
            drop[i] = 1;
      }
    }
    sc.carved_grains = remove_grains(sc, sc.initial, drop);
  }

  // Stages.
  if (const YAML::Node st = root["stages"]) {
    if (!st.IsSequence() || st.size() == 0) rd.fail("stages", "expected a non-empty list");
    for (size_t i = 0; i < st.size(); ++i) {
      const std::string p = "stages[" + std::to_string(i) + "]";
      rd.only(st[i], p,
              {"name", "duration", "hold", "remove_walls", "until_rms_speed", "until_max_speed", "check_every",
               "gravity", "gravity_ramp", "trim_above", "trim_tops", "stiffness_scale", "max_injection", "quench_every", "minimize", "release_springs"});
      Stage s;
      s.name = rd.text(st[i], p, "name", "stage" + std::to_string(i));
      s.duration = rd.number(st[i], p, "duration", 0, 0, 1e9, true);
      if (!st[i]["duration"]) rd.fail(p + ".duration", "missing (simulated seconds, > 0)");
      if (const YAML::Node h = st[i]["hold"]) {
        if (!h.IsSequence()) rd.fail(p + ".hold", "expected a list of grain group names");
        for (const auto& x : h) {
          const std::string gname = x.as<std::string>();
          if (!sc.group(gname)) {
            std::vector<std::string> names;
            for (const GrainGroup& g : sc.groups) names.push_back(g.name);
            rd.fail(p + ".hold",
                    "unknown grain group '" + gname + "' (the groups: " + Reader::entry_names("grains", names) + ")");
          }
          s.hold.push_back(gname);
        }
      }
      if (const YAML::Node rw = st[i]["remove_walls"]) {
        if (!rw.IsSequence()) rd.fail(p + ".remove_walls", "expected a list of wall names");
        for (const auto& x : rw) {
          const std::string wname = x.as<std::string>();
          bool found = false;
          for (const auto& w : m.walls) found = found || w.name == wname;
          if (!found) {
            std::vector<std::string> names;
            for (const Wall& w : m.walls) names.push_back(w.name);
            rd.fail(p + ".remove_walls",
                    "unknown wall '" + wname + "' (the walls: " + Reader::entry_names("walls", names) + ")");
          }
          s.remove_walls.push_back(wname);
        }
      }
      // Stop criteria: absent = off (-1 inside); given, a speed > 0.
      s.until_rms_speed = st[i]["until_rms_speed"] ? rd.number(st[i], p, "until_rms_speed", -1, 0, kMaxSceneSpeed, true) : -1;
      s.until_max_speed = st[i]["until_max_speed"] ? rd.number(st[i], p, "until_max_speed", -1, 0, kMaxSceneSpeed, true) : -1;
      s.check_every = rd.number(st[i], p, "check_every", 0.01, 0, kMaxSceneDuration, true);
      if (st[i]["gravity"]) {
        s.set_gravity = true;
        s.gravity = rd.vec3(st[i], p, "gravity", Vec3::Zero(), true);
      }
      s.gravity_ramp = rd.number(st[i], p, "gravity_ramp", 0, 0, s.duration);
      if (s.gravity_ramp > 0 && !s.set_gravity) rd.fail(p + ".gravity_ramp", "needs a 'gravity' to ramp to");
      s.stiffness_scale = rd.number(st[i], p, "stiffness_scale", 0, 0, 1);
      if (s.stiffness_scale > 0 && s.stiffness_scale < 1e-6)
        rd.fail(p + ".stiffness_scale", "value below 1e-6: give 0 (keep the scene's k_n) or a scale in [1e-6, 1]");
      s.max_injection = rd.number(st[i], p, "max_injection", -1, 0, 1e6);
      if (st[i]["max_injection"] && s.stiffness_scale <= 0)
        rd.fail(p + ".max_injection", "needs a 'stiffness_scale' (the check is made when k_n changes)");
      s.quench_every = rd.number(st[i], p, "quench_every", 0, 0, kMaxSceneDuration);
      s.minimize = rd.boolean(st[i], p, "minimize", false);
      s.release_springs = rd.boolean(st[i], p, "release_springs", false);
      s.trim_tops = rd.boolean(st[i], p, "trim_tops", false);
      if (st[i]["trim_tops"] && !st[i]["trim_above"]) rd.fail(p + ".trim_tops", "needs a 'trim_above' height");
      if (st[i]["trim_above"]) {
        s.trim = true;
        s.trim_above = rd.number(st[i], p, "trim_above", 0, -kMaxSceneLength, kMaxSceneLength);
        // A trim plane at or below a floor (a plane wall facing up) would remove every grain.
        for (const Wall& w : m.walls)
          if (w.type == WallType::Plane && w.axis.z() > 1 - 1e-9 && !(s.trim_above > w.origin.z()))
            rd.fail(p + ".trim_above", "z = " + std::to_string(s.trim_above) + " m is not above the floor" +
                                           (w.name.empty() ? std::string() : " '" + w.name + "'") + " (z = " +
                                           std::to_string(w.origin.z()) + " m): the trim would remove every grain");
      }
      sc.stages.push_back(s);
    }
  } else {
    rd.fail("stages", "missing (a list of {name, duration, ...})");
  }
  const YAML::Node out = rd.map(root, "", "output", false);
  rd.only(out, "output", {"every"});
  sc.output_every = rd.number(out, "output", "every", 0.01, 0, kMaxSceneDuration, true);
  return sc;
}

}  // namespace

Scenario parse_scenario(const YAML::Node& root, const std::string& source, const DerivedContact& derived) {
  // A key that is not a plain name, a list where a name belongs: yaml-cpp's
  // conversion errors become InputErrors naming the file (and line).
  try {
    return interpret_scenario(root, source, derived);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": " + e.what());
  }
}

Scenario parse_scenario_text(const std::string& yaml_text, const std::string& source) {
  check_yaml_nesting(source, yaml_text);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": not valid YAML: " + e.what());
  }
  return parse_scenario(root, source);
}

namespace {

// Deep merge for 'base:': mappings merge key by key, anything else (lists,
// scalars) in `over` replaces what `base` had.
YAML::Node merged(const YAML::Node& base, const YAML::Node& over) {
  if (!base.IsMap() || !over.IsMap()) return YAML::Clone(over);
  YAML::Node out = YAML::Clone(base);
  for (const auto& kv : over) {
    const std::string key = kv.first.as<std::string>();
    out[key] = out[key] ? merged(out[key], kv.second) : YAML::Clone(kv.second);
  }
  return out;
}

YAML::Node read_document(const std::string& path, int depth) {
  // Size and nesting are bounded before yaml-cpp sees the text (docs/files.md, "Loaded files").
  const std::string text = read_file_limited(path, kMaxYamlBytes, "scenario file");
  check_yaml_nesting(path, text);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap() || !root["base"]) return root;
  // 'base: FILE' (relative to this file): start from FILE and change what this file gives.
  if (!root["base"].IsScalar()) throw InputError(path + ": key 'base': expected a file name");
  if (depth >= 8) throw InputError(path + ": key 'base': more than 8 nested base files (a cycle?)");
  std::string file = root["base"].Scalar();
  const auto slash = path.rfind('/');
  if (!file.empty() && file[0] != '/' && slash != std::string::npos) file = path.substr(0, slash + 1) + file;
  YAML::Node base;
  try {
    base = read_document(file, depth + 1);
  } catch (const InputError& e) {
    throw InputError(path + ": key 'base': " + e.what());
  }
  root.remove("base");
  try {
    return merged(base, root);
  } catch (const YAML::Exception& e) {  // a key that is not a plain name
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace

YAML::Node load_document(const std::string& path, const std::vector<std::string>& overrides) {
  YAML::Node root = read_document(path, 0);
  for (const auto& o : overrides) apply_override(root, o);
  // Callers look keys up in it (a lookup in a single value throws past InputError).
  if (!root.IsMap()) throw InputError(path + ": expected a YAML mapping at the top level");
  return root;
}

Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_scenario(load_document(path, overrides), path);
}

}  // namespace rt
