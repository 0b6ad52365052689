#include "test_support.hpp"

namespace rt::test {

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

}  // namespace rt::test
