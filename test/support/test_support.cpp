#include "test_support.hpp"

#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/scenario.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace {

// Spinning OpenMP threads starve each other when the machine's cores are
// shared with other jobs (a 2-thread run then becomes many times slower than
// a serial one). libgomp reads OMP_WAIT_POLICY once, when it is loaded, so
// unless the caller chose a policy a test binary restarts itself with passive
// waiting before any test runs. Results do not depend on it.
[[maybe_unused]] const bool kRestartedWithPassiveWait = [] {
  if (std::getenv("OMP_WAIT_POLICY")) return false;
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string args((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<char*> argv;
  for (size_t p = 0; p < args.size(); p += std::strlen(&args[p]) + 1) argv.push_back(&args[p]);
  if (argv.empty()) return false;
  argv.push_back(nullptr);
  setenv("OMP_WAIT_POLICY", "passive", 1);
  execv("/proc/self/exe", argv.data());
  return false;  // exec failed: carry on with the default policy
}();

}  // namespace

namespace rt::test {

std::string figure(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

Material simple_material(const std::string& name, double density, double eps_n, double eps_t, double mu_s) {
  Material m;
  m.name = name;
  m.density = density;
  m.eps_n = eps_n;
  m.eps_t = eps_t;
  m.mu_s = mu_s;
  m.mu_r = 0;
  m.mu_t = 0;
  return m;
}

void grains_in_a_row(Model& m, State& s, const std::vector<double>& radii, double spacing) {
  m.materials.push_back(simple_material("grain", 2700, 0.8, 0.8, 0.2));
  m.gravity = Vec3::Zero();
  for (double r : radii) add_grain(m, r, 0);
  m.kn = 8000;
  m.dt = 1e-6;
  finalize_model(m);
  s = make_state(m);
  for (size_t i = 0; i < radii.size(); ++i) s.pos[i] = Vec3(spacing * double(i), 0, 0.001);
}

void grain_and_wall_in_open_box(Model& m, double side) {
  m.materials = {simple_material("grain", 2430, 0.5, 0.5, 0.5), simple_material("wall", 2430, 0.5, 0.5, 0.5)};
  m.materials[1].structure = true;
  m.walls.push_back(make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));
  m.walls.push_back(make_plane(Vec3::Zero(), Vec3::UnitX(), 1));
  m.walls.push_back(make_plane(Vec3(side, 0, 0), -Vec3::UnitX(), 1));
  m.walls.push_back(make_plane(Vec3::Zero(), Vec3::UnitY(), 1));
  m.walls.push_back(make_plane(Vec3(0, side, 0), -Vec3::UnitY(), 1));
}

bool preset_with_wall(Model& m, const std::string& preset) {
  Material grain;
  if (!material_preset(preset, grain)) return false;
  m.materials.push_back(grain);
  Material wall = grain;
  wall.name = "wall";
  wall.structure = true;
  m.materials.push_back(wall);
  return true;
}

TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi, int n) {
  TriangleMesh m;
  // Face with corner c0 and in-plane directions u, v, u x v along the outward normal.
  auto face = [&](const Vec3& c0, const Vec3& u, const Vec3& v) {
    const int base = static_cast<int>(m.vertices.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.vertices.push_back(c0 + u * (double(i) / n) + v * (double(j) / n));
    auto id = [&](int i, int j) { return base + j * (n + 1) + i; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  };
  const Vec3 e = hi - lo;
  const Vec3 X(e.x(), 0, 0), Y(0, e.y(), 0), Z(0, 0, e.z());
  face(lo, Y, X);      // z = lo (normal -z)
  face(lo + Z, X, Y);  // z = hi (+z)
  face(lo, X, Z);      // y = lo (-y)
  face(lo + Y, Z, X);  // y = hi (+y)
  face(lo, Z, Y);      // x = lo (-x)
  face(lo + X, Y, Z);  // x = hi (+x)
  return m;
}

BodyModel box_body(const std::string& name, const Vec3& half, double density, bool fixed, int material) {
  BodyModel b;
  b.name = name;
  b.fixed = fixed;
  b.material = material;
  b.mass = 8 * half.prod() * density;
  b.inertia = b.mass / 3 *
              Vec3(half.y() * half.y() + half.z() * half.z(), half.x() * half.x() + half.z() * half.z(),
                   half.x() * half.x() + half.y() * half.y());
  Shape sh;
  sh.type = ShapeType::Box;
  sh.size = half;
  b.shapes.push_back(sh);
  return b;
}

SceneRunOutcome run_scene(const Scene& sc, Model& m, State& s) {
  RunOptions ro;
  ro.progress_every = 0;
  Run run(m, s, sc.plan, ro);
  SceneRunOutcome out;
  out.run = sc.begin(run);
  out.run->attach(run);
  out.report = run.run();
  return out;
}

}  // namespace rt::test
