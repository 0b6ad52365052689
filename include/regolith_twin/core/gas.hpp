// Drag and lift coefficients of a sphere in a gas (docs/model.md §10, "Gas"):
// Loth (2008) for drag over the whole range of Reynolds and Mach numbers,
// with the corrected free-molecular term, and Loth's shear-lift fit. Pure
// functions of the dimensionless numbers; the field that applies them to
// grains is GasField (gas_field.hpp).
#pragma once

namespace rt {

// The dimensionless gas parameters that do not depend on the relative speed.
struct GasConstants {
  double gamma = 1.33;           // ratio of specific heats
  double tp_over_tg = 1.0;       // particle over gas temperature, T_p / T_inf
  // Knudsen number Kn = sqrt(pi gamma / 2) Ma / Re = sqrt(pi gamma / 2) mu_g / (rho_g d c):
  // a property of the gas and the grain diameter, not of the speed.
  double kn = 0;
};

// Kn = sqrt(pi gamma / 2) mu_g / (rho_g d c) of a grain of diameter d.
double knudsen_number(double gamma, double viscosity, double density, double diameter, double sound_speed);

// Free-molecular drag C_D,fm at speed ratio s = Ma sqrt(gamma / 2) > 0
// (diffuse reflection; the last term is 2 sqrt(pi T_p / T_inf) / (3 s)).
double free_molecular_drag(double s, double tp_over_tg);

// C_D,fm,Re: the free-molecular drag blended toward 1.63 with rising Re
// (1.63 at Re = 45 for every Ma > 0).
double loth_free_molecular_blend(double re, double ma, const GasConstants& g);

// Loth's Re >= 45 ("compression") branch.
double loth_drag_compression(double re, double ma);

// Loth's Re < 45 ("rarefaction") branch, times Re (finite as Re -> 0).
double loth_drag_rarefaction_re(double re, double ma, const GasConstants& g);

// C_D Re over the whole range (Re >= 0, Ma >= 0): the rarefaction branch
// below Re = 45, the compression branch above. Finite at Re = 0, where the
// drag force C_D Re (pi d mu_g / 8) v0 vanishes.
double loth_drag_re(double re, double ma, const GasConstants& g);

// C_D = loth_drag_re / Re, for Re > 0.
double loth_drag(double re, double ma, const GasConstants& g);

// Loth's shear-lift coefficient C_L at Reynolds number re > 0 and
// dimensionless shear omega_star = |dU/dh| d / |v0| >= 0, with the particle
// spin taken as Omega*_p = omega_star / 2. Fitted for Re <= 50 and
// omega_star <= 0.8.
double loth_lift(double re, double omega_star);

}  // namespace rt
