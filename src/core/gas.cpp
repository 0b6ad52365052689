// Loth (2008) drag and lift coefficients (see gas.hpp; docs/model.md §10).
#include "regolith_twin/core/gas.hpp"
#include "regolith_twin/core/types.hpp"

#include <cmath>

namespace rt {

namespace {
// Below this Mach number the Ma^4 free-molecular term of the rarefaction
// branch is dropped: it is below 1e-24 of C_D there, and C_D,fm's two
// 1/s^3 terms cancel to rounding.
constexpr double kMaFreeMolecularNegligible = 1e-6;
}  // namespace

double knudsen_number(double gamma, double viscosity, double density, double diameter, double sound_speed) {
  return std::sqrt(kPi * gamma / 2) * viscosity / (density * diameter * sound_speed);
}

double free_molecular_drag(double s, double tp_over_tg) {
  const double s2 = s * s, s4 = s2 * s2;
  return (1 + 2 * s2) * std::exp(-s2) / (s2 * s * std::sqrt(kPi)) + (4 * s4 + 4 * s2 - 1) * std::erf(s) / (2 * s4) +
         2 * std::sqrt(kPi * tp_over_tg) / (3 * s);
}

double loth_drag_compression(double re, double ma) {
  const double c_m = ma <= 1.45 ? 5.0 / 3.0 + (2.0 / 3.0) * std::tanh(3 * std::log(ma + 0.1))
                                : 2.044 + 0.2 * std::exp(-1.8 * std::pow(std::log(ma / 1.5), 2));
  const double g_m = ma <= 0.89 ? 1 - 1.525 * std::pow(ma, 4) : 2e-4 + 8e-4 * std::tanh(12.77 * (ma - 2.02));
  const double h_m = 1 - 0.258 * c_m / (1 + 514 * g_m);
  return (24 / re) * (1 + 0.15 * std::pow(re, 0.687)) * h_m + 0.42 * c_m / (1 + 42500 * g_m / std::pow(re, 1.16));
}

double loth_free_molecular_blend(double re, double ma, const GasConstants& g) {
  const double fm = free_molecular_drag(ma * std::sqrt(g.gamma / 2), g.tp_over_tg);
  return fm / (1 + (fm / 1.63 - 1) * std::sqrt(re / 45));
}

double loth_drag_rarefaction_re(double re, double ma, const GasConstants& g) {
  const double kn = g.kn;
  const double slip = kn > 0 ? 1 + kn * (2.514 + 0.8 * std::exp(-0.55 / kn)) : 1;
  const double kn_re = 24 * (1 + 0.15 * std::pow(re, 0.687)) / slip;  // C_D,Kn,Re times Re
  if (ma < kMaFreeMolecularNegligible) return kn_re;
  const double ma4 = std::pow(ma, 4);
  return (kn_re + ma4 * loth_free_molecular_blend(re, ma, g) * re) / (1 + ma4);
}

double loth_drag_re(double re, double ma, const GasConstants& g) {
  return re < 45 ? loth_drag_rarefaction_re(re, ma, g) : loth_drag_compression(re, ma) * re;
}

double loth_drag(double re, double ma, const GasConstants& g) { return loth_drag_re(re, ma, g) / re; }

double loth_lift(double re, double omega_star) {
  const double x = std::sqrt(omega_star / re);
  const double j = 0.3 * (1 + std::tanh(2.5 * (std::log10(x) + 0.191))) * (2.0 / 3.0 + std::tanh(6 * x - 1.92));
  const double spin = omega_star / 2;  // Omega*_p
  const double c_spin = 1 - (0.675 + 0.15 * (1 + std::tanh(0.28 * (spin - 2)))) * std::tanh(0.18 * std::sqrt(re));
  return (12.92 / kPi) * j * x + spin * c_spin;
}

}  // namespace rt
