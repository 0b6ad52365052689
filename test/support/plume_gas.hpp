// The gas and grain of the lunar plume study (docs/scenes.md D), shared by
// the gas tests: rho_g 1.27 kg/m^3, mu_g 1.983e-5 Pa s, c 515.6 m/s,
// gamma 1.33, grains of 1 mm and 2700 kg/m^3 (Kn = 4.4e-5).
#pragma once

#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/gas.hpp"

namespace rt::test {

constexpr double kPlumeRho = 1.27, kPlumeMu = 1.983e-5, kPlumeC = 515.6, kPlumeGamma = 1.33;
constexpr double kPlumeD = 1e-3, kPlumeGrainDensity = 2700;

inline GasFlowParams plume_gas_flow() {
  GasFlowParams p;
  p.density = kPlumeRho;
  p.viscosity = kPlumeMu;
  p.sound_speed = kPlumeC;
  p.gamma = kPlumeGamma;
  return p;
}

// The constants of a 1 mm grain in that gas.
inline GasConstants plume_gas_constants() {
  GasConstants g;
  g.gamma = kPlumeGamma;
  g.kn = knudsen_number(kPlumeGamma, kPlumeMu, kPlumeRho, kPlumeD, kPlumeC);
  return g;
}

// Reynolds number of a 1 mm grain at relative speed v, m/s.
inline double plume_reynolds(double v) { return kPlumeRho * v * kPlumeD / kPlumeMu; }

}  // namespace rt::test
