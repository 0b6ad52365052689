#include "test_support.hpp"

#include "regolith_twin/scene/scenario.hpp"

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

}  // namespace rt::test
