// Analytic verification of binary collisions (docs/model.md §2–4, §7):
//  * the damped linear normal contact: measured restitution, contact duration
//    and maximum overlap against the closed-form solution, swept over contact
//    entry phases and steps per contact (a convergence study);
//  * the Chung & Ooi (2011) impact benchmarks 1–4 with the Hertz–Mindlin law
//    (Granular Matter 13:643–656), against the Hertz solution and rigid-body
//    Coulomb theory;
//  * the damping prefactor of the Hertz–Mindlin law that reproduces a given
//    coefficient of restitution exactly (a root find on the dimensionless
//    contact equation).
// Every case builds an ordinary Model/State and advances it with rt::step(),
// so these functions exercise the engine exactly as a scene does.
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/core/model.hpp"
#include "regolith_twin/core/state.hpp"

namespace rt::validate {

// ---------------------------------------------------------------------------
// Linear normal collision (docs/model.md §2, §4).
enum class PairKind { GrainGrain, GrainWall };
const char* pair_kind_name(PairKind k);

struct LinearImpactSetup {
  PairKind kind = PairKind::GrainGrain;
  double eps_n = 0.5;        // input normal restitution
  double steps = 30;         // N of dt = pi sqrt(m_p/(2 k_n)) / N
  double phase = 0.5;        // where in a step the first overlap falls, [0, 1)
  double radius = 0.005;     // grain radius, m
  double density = 2500;     // kg/m^3
  double speed = 1.0;        // impact relative normal speed, m/s
  double xmax_fraction = 0.01;  // x_max / radius in k_n = m_p (v / x_max)^2
};

struct LinearImpactOutcome {
  double eps_measured = 0;   // -(u_n after) / (u_n before)
  double kn = 0, dt = 0;     // stiffness from the rule and step from N
  double mstar = 0;          // reduced mass of the pair, kg
  double x_max = 0;          // allowed overlap of the stiffness rule, m
  double max_overlap = 0;    // largest overlap seen at a force evaluation, m
  double t_contact = 0;      // analytic duration sqrt(m* (pi^2 + ln^2 eps) / k_n), s
  int contact_steps = 0;     // steps from the first with overlap > 0 to the last, inclusive
  double t_measured = 0;     // contact_steps * dt, s
  bool ended = false;        // the contact ended within the step budget
};

LinearImpactOutcome run_linear_impact(const LinearImpactSetup& setup);

// Statistics over n_phases uniformly spaced entry phases (p + 1/2) / n_phases.
struct PhaseSweep {
  PairKind kind = PairKind::GrainGrain;
  double eps_n = 0, steps = 0;
  int n_phases = 0;
  double t_contact = 0, dt = 0;    // analytic duration and step, s
  double steps_per_contact = 0;    // t_c / dt
  double eps_mean = 0, eps_min = 0, eps_max = 0;
  double mean_error = 0;           // (mean eps - eps_n) / eps_n (signed)
  double mean_abs_error = 0;       // mean over phases of |eps - eps_n| / eps_n
  double worst_abs_error = 0;      // max over phases of |eps - eps_n| / eps_n
  double worst_duration_error = 0; // max over phases of |t_measured - t_c| / dt
  double max_overlap_ratio = 0;    // max over phases of max overlap / x_max
  bool all_ended = true;
};

PhaseSweep sweep_phases(PairKind kind, double eps_n, double steps, int n_phases);

// Steps per contact N used by the convergence study: 8 ... 240, roughly
// log-spaced, always containing 30 (the engine default).
std::vector<double> convergence_steps();

// Least-squares slope of log(y) against log(x).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

// Relative error treated as rounding level (no convergence order is defined below it).
constexpr double kRoundingLevel = 1e-12;

// ---------------------------------------------------------------------------
// Hertz impact, analytic (elastic, no damping).
struct HertzElastic {
  double max_overlap;   // (15 m* v^2 / (16 E* sqrt(R)))^(2/5), m
  double max_force;     // 4/3 E* sqrt(R) x_max^(3/2), N
  double contact_time;  // 4/5 B(2/5, 1/2) x_max / v, s
};
HertzElastic hertz_elastic_impact(double mstar, double reff, double e_star, double v);

// Damping prefactor alpha in gamma = alpha sqrt(S_n m*) from docs/model.md §3:
// 2 sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2).
double hertz_damping_prefactor_model(double e);
// Restitution of an isolated Hertz contact with damping gamma = alpha sqrt(S_n m*)
// (tension allowed): integration of the dimensionless equation
//   xi'' = -4/3 xi^(3/2) - sqrt(2) alpha xi^(1/4) xi',  xi(0) = 0, xi'(0) = 1,
// which holds for every E*, R, m* and impact speed (the law is self-similar).
double hertz_restitution(double alpha);
// The prefactor alpha for which hertz_restitution(alpha) == e (root find),
// for 0 < e <= 1. Meant to replace hertz_damping_prefactor_model in the core.
double hertz_damping_prefactor_calibrated(double e);

// ---------------------------------------------------------------------------
// Chung & Ooi (2011) benchmarks with the Hertz–Mindlin law.
struct ElasticMaterial {
  std::string name;
  double young, poisson, density;
};
// Materials and cases of the paper's tests 1–4 (values in collisions.cpp).
ElasticMaterial chung_ooi_glass();
ElasticMaterial chung_ooi_limestone();
ElasticMaterial chung_ooi_aluminium_alloy();
ElasticMaterial chung_ooi_magnesium_alloy();
ElasticMaterial chung_ooi_aluminium_oxide();

struct HertzImpactSetup {
  ElasticMaterial material;
  bool wall = false;            // sphere on a rigid plane (else two identical spheres head-on)
  double radius = 0.01;         // m
  double speed = 1.0;           // impact speed of the (each) sphere, m/s
  double angle_deg = 0;         // incidence angle from the normal (wall only)
  double restitution = 1.0;     // input e (eps_n of the pair)
  double mu = 0.0;              // sliding friction
  double steps_per_contact = 500;  // dt = Hertz contact time / this
  double damping_prefactor = -1;   // >= 0 overrides the law's alpha (calibrated runs)
};

struct HertzImpactOutcome {
  double dt = 0, steps_per_contact = 0;
  double mstar = 0, reff = 0, e_star = 0, v_rel = 0;  // pair constants, impact relative normal speed
  double max_overlap = 0;       // m
  double max_force = 0;         // largest normal contact force, N
  double t_measured = 0;        // steps with overlap > 0 times dt, s
  double e_n = 0;               // -(u_n after)/(u_n before)
  double vt_in = 0, vt_out = 0; // tangential velocity of the centre before/after (wall), m/s
  double omega_out = 0;         // spin after, rad/s (positive reduces the contact-point slip)
  int stick_steps = 0;          // contact steps whose friction force was below mu f_n (mu > 0 only)
  bool ended = false;
};

HertzImpactOutcome run_hertz_impact(const HertzImpactSetup& setup);

// Test 1 / 2: one elastic impact against the Hertz solution.
struct ElasticBenchmark {
  std::string test, material;
  HertzElastic analytic;
  HertzImpactOutcome measured;
};
ElasticBenchmark chung_ooi_test1(const ElasticMaterial& mat, double steps_per_contact = 500);
ElasticBenchmark chung_ooi_test2(const ElasticMaterial& mat, double steps_per_contact = 500);

// Test 3: normal impact on a rigid plane with restitution e_in.
struct RestitutionRow {
  double e_in = 0;
  double alpha_model = 0, alpha_calibrated = 0;
  double e_ode_model = 0;     // hertz_restitution(alpha_model): the continuous-time value
  double e_out_model = 0;     // engine, law prefactor from docs/model.md §3
  double e_out_calibrated = 0;  // engine, calibrated prefactor
  double steps_per_contact = 0;
};
RestitutionRow chung_ooi_test3(double e_in, double steps_per_contact = 500);

// Test 4: oblique impact on a rigid plane at constant speed.
struct ObliqueRow {
  double angle_deg = 0;
  double vt_ratio = 0;          // v_t' / v_t (tangential restitution of the centre)
  double omega_r_over_v = 0;    // omega' R / v
  double rebound_deg = 0;       // atan(v_t' / v_n') of the centre
  double patch_rebound_deg = 0; // atan((v_t' - omega' R) / v_n') of the contact patch
  double e_n = 0;               // measured normal restitution
  // Rigid-body Coulomb theory with the input e: gross sliding when
  // tan(angle) >= 7/2 mu (1 + e), else rolling contact (patch at rest after).
  double vt_ratio_rigid = 0, omega_r_over_v_rigid = 0, rebound_deg_rigid = 0, patch_rebound_deg_rigid = 0;
  bool gross_sliding_rigid = false;
  double vt_ratio_sliding = 0, omega_r_over_v_sliding = 0;  // the gross-sliding line at any angle
  // The paper's normalised angles (Maw et al.): chi = 2(1-nu)/(2-nu),
  // psi1 = chi tan(angle) / mu, psi2 = chi (v_t' - omega' R) / (mu v_n).
  double psi1 = 0, psi2 = 0;
  bool slid_throughout = false; // the friction force sat at the Coulomb limit at every contact step
  double steps_per_contact = 0;
};
ObliqueRow chung_ooi_test4(double angle_deg, double steps_per_contact = 500);
constexpr double kTest4Speed = 3.9;      // m/s
constexpr double kTest4Friction = 0.092;
constexpr double kTest4Restitution = 0.98;
constexpr double kTest4Radius = 0.0025;  // m

}  // namespace rt::validate
