// Static description of a DEM scene: grain sizes and masses, materials, the
// contact-law table for every pair type, walls, gravity, time step and guard
// thresholds. A Model is built once (by the scenario reader, src/io/scenario.cpp) and is then
// read-only: every stage of the step takes `const Model&` and a mutable State.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/core/types.hpp"

namespace rt {

// Contact law family used for every pair in a scene.
enum class ContactModel { Linear, HertzMindlin };

// A material as published (docs/model.md §9) plus elastic constants for Hertz.
struct Material {
  std::string name;
  double density = 2430.0;  // kg/m^3 (grains; unused for walls)
  double eps_n = 0.5;       // normal coefficient of restitution (0, 1]
  double eps_t = 0.5;       // tangential "restitution" (pkdgrav damping parameter)
  double mu_s = 1.0;        // sliding friction coefficient
  double mu_r = 0.0;        // rolling friction coefficient (0 = no rolling resistance)
  double mu_t = 0.0;        // twisting friction coefficient (0 = no twisting resistance)
  double beta = 1.0;        // shape parameter (grain angularity), dimensionless
  double young = 0.0;       // Young's modulus E, Pa (Hertz–Mindlin only)
  double poisson = 0.25;    // Poisson ratio (Hertz–Mindlin only)
  // Optional overrides of the linear law (<= 0: derived from eps_t / k_n).
  double kt_over_kn = 2.0 / 7.0;  // k_t / k_n
  double ct_over_cn = -1.0;       // if > 0, C_t = ct_over_cn * C_n instead of from eps_t
  // A structure material (walls, impactors, bodies) gives a pair its own
  // restitution and takes the grain's friction unless own_friction is set.
  bool structure = false;
  bool own_friction = false;
};

// Contact-law constants of one pair type (material a with material b, or a
// grain material with a wall). Mass-dependent terms are stored as coefficients
// of sqrt(m*) so one table entry serves every grain size.
struct PairLaw {
  double eps_n = 1, eps_t = 1;  // restitution of this pair type
  // linear law
  double kn = 0.0;     // normal stiffness, N/m
  double kt = 0.0;     // tangential stiffness, N/m
  double cn_coef = 0;  // C_n = cn_coef * sqrt(m*), N s/m
  double ct_coef = 0;  // C_t = ct_coef * sqrt(m*)
  // Hertz–Mindlin
  double e_star = 0;   // effective Young's modulus E*, Pa
  double g_star = 0;   // effective shear modulus G*, Pa
  double hm_damp = 0;  // gamma = hm_damp * sqrt(S_n m*)
  // friction and resistance
  double mu_s = 0;     // sliding friction
  double mu_r = 0;     // rolling friction
  double mu_t = 0;     // twisting friction
  double beta = 0;     // shape parameter
  bool rolling = false;   // rolling resistance active for this pair type
  bool twisting = false;  // twisting resistance active for this pair type
};

// Analytic, infinite-mass wall shapes (docs/model.md §5).
enum class WallType { Plane, Disk, Cylinder, Cone, Rectangle, SphereShell };

struct Wall {
  WallType type = WallType::Plane;
  std::string name;
  Vec3 origin = Vec3::Zero();  // a point on the plane / centre of disk, base centre of cylinder or cone, rectangle centre, sphere centre
  Vec3 axis = Vec3::UnitZ();   // unit normal (plane, disk, rectangle) or axis (cylinder, cone)
  Vec3 u = Vec3::UnitX();      // rectangle: first in-plane unit direction (v = axis x u)
  double radius = 0;           // disk, cylinder, sphere shell; cone: radius at origin
  double radius2 = 0;          // cone: radius at origin + length*axis
  double length = 0;           // cylinder/cone: extent along axis (<= 0: infinite cylinder)
  double half_u = 0, half_v = 0;  // rectangle half extents along u and v
  bool inner = true;           // cylinder/cone/sphere: grains live inside (true) or outside
  int law_material = 0;        // index of the wall's material (its eps, and friction unless set)
};

// Periodic boundaries in x and/or y (docs/model.md §11): the box
// [lo, lo + length) repeats along each periodic axis. A pair list entry
// holds the image of its partner nearest to its owner (image code
// sx + 3 sy, sx, sy in {-1, 0, 1}: the partner's position plus
// (sx length.x, sy length.y, 0)); grains are wrapped into the box at every
// list build.
struct Periodic {
  bool x = false, y = false;
  Vec3 lo = Vec3::Zero();      // box start along x and y, m (z unused)
  Vec3 length = Vec3::Zero();  // box lengths along x and y, m (z unused)
  bool any() const { return x || y; }
  // The shift of image code c (in [-4, 4]), m.
  Vec3 shift(int c) const {
    const int sx = (c + 4) % 3 - 1, sy = (c - sx) / 3;
    return Vec3(sx * length.x(), sy * length.y(), 0);
  }
};

// Guard thresholds: a run that crosses them stops with a diagnostic.
// Sleeping of quiescent regions (docs/model.md §16). Grains are binned in
// cubic sleep cells; a cell whose grains stay slow and whose contact forces
// stay steady for a while falls asleep: its grains leave the step (neither
// integrated nor searched against each other) and keep their springs. A
// cell wakes when something moving reaches a neighbouring cell (a grain, a
// body), when the force on one of its grains from awake neighbours, walls or
// bodies changes by more than a fraction of its weight, or when gravity
// changes. Thresholds scale with the bed: speed with sqrt(|g| d), time with
// sqrt(d / |g|), force with the grain's weight (d: mean grain diameter).
struct SleepParams {
  bool enabled = false;
  double speed = 0.1;     // cell RMS speed below speed * sqrt(|g| d) counts as quiet; a grain above it moves
  double time = 0.05;     // quiet for time * sqrt(d / |g|) before a cell falls asleep
  double force = 0.5;     // force change above force * m |g| on a grain wakes (sleeping) or keeps awake
  double cell = 0;        // sleep cell side, m (<= 0: 2 (2 r_max + skin)); at least 2 r_max + skin
  int check_every = 20;   // at most this many steps between checks (fewer when grains or bodies move fast)
  bool at_start = true;   // cells quiet at the first check fall asleep at once (a relaxed bed)
};

// Free flight (docs/model.md §18): a grain with no list entry at a full list
// build (no grain, wall or body within the skin) gets a reach: the smallest gap
// to any grain (within reach_cells cells), wall or body shape. It then leaves
// the skin criterion of the rebuild test and triggers a rebuild only when its
// own displacement plus the largest displacement of anything (grain or body
// point) could close that reach. Exact: no contact is missed, whatever moves.
struct FreeFlightParams {
  bool enabled = false;
  int reach_cells = 2;     // search depth for the reach, in cells of 2 r_max + skin
};

// Stiffness schedule (docs/model.md §17): the scene's k_n is designed for the
// largest expected relative speed (contact.v_max). When nothing moves that
// fast any more, k_n follows the fastest possible approach, v_fast (twice the
// fastest grain, or the fastest body point plus the fastest grain), by the
// same rule: target = (margin v_fast / speed)^2 in [floor, 1] of k_scene,
// and Δt = Δt_scene / sqrt(k_n / k_scene) (the same steps per contact).
// The deepest contact asks for the factor that brings its overlap to the
// design overlap; it holds k_n up (no lowering below it) but only speeds
// raise k_n. k_n is set to twice the target when the target passes it
// (raised at once: the live contacts' springs are shortened so that their
// forces stay the same, and the energy the raise puts into their overlaps is
// measured, reported and bounded by max_injected), or when the target has
// stayed below a quarter of it for three durations of the longest contact
// (lowered: the energy taken out of live contacts is reported too).
struct ScheduleParams {
  bool enabled = false;
  double speed = 0;        // design speed of the scene's k_n, m/s (<= 0: contact.v_max)
  double margin = 1.2;     // on v_fast
  double floor = 1e-4;     // smallest factor on the scene's k_n (Δt at most 100x the scene's)
  double after = 0;        // s of simulated time from the run's start before the first lowering
  int check_every = 10;    // steps between checks of the grains' speeds (bodies: every step)
  // The run stops with a diagnostic once the raises have added more than this
  // fraction of the largest kinetic energy seen (ScheduleState::kinetic_ref); 0: off.
  double max_injected = 0.05;
};

struct Guards {
  double max_overlap_ratio = 0.25;  // overlap / smaller radius of the pair
  double min_steps_per_contact_warn = 10;
  double min_steps_per_contact_refuse = 4;
  bool allow_under_resolved = false;
  // A free body may move at most this fraction of body_step_limit (docs/model.md §13) in one step (<= 0: off).
  double max_body_step_ratio = 1.0;
  // A grain without a free-flight reach may move at most this fraction of the list skin in one step (<= 0: off).
  double max_grain_step_ratio = 1.0;
  // Body–body: deepest point over the half thickness of the thinner shape of the pair (<= 0: off).
  double max_body_overlap_ratio = 1.0;
  // Touching contacts of one grain (grains, walls, bodies) at most this many; 0: the geometric
  // bound of the scene's radii and max_overlap_ratio (docs/model.md §13); < 0: off.
  int max_contacts_per_grain = 0;
  // Passive scenes (no field, wrench, schedule, held grains or gravity ramp): the total energy may rise
  // above its lowest value by at most this fraction of the scene's energy scale (<= 0: off),
  // checked every energy_check_every steps (docs/model.md §13).
  double max_energy_growth = 0.1;
  int energy_check_every = 1000;
};

// Bullet collision objects of the bodies' shapes (defined in body_collision.cpp).
struct BodyGeometry;

struct Model {
  // --- grains (indexed by grain id; the State keeps its own sorted copies) ---
  int n_grains = 0;
  std::vector<double> grain_radius;    // r, m (n_grains)
  std::vector<double> grain_mass;      // m, kg (n_grains)
  std::vector<int> grain_material;     // material index (n_grains)
  std::vector<uint8_t> grain_hold;     // policies holding the grain at rest, 0 = free (core/hold.hpp) (n_grains)
  std::vector<double> grain_inv_mass;     // 1/m, 1/kg; 0 for held grains (n_grains)
  std::vector<double> grain_inv_inertia;  // 1/I, 1/(kg m^2); 0 for held grains (n_grains)

  // --- materials and the pair-law table ---
  ContactModel contact_model = ContactModel::Linear;
  std::vector<Material> materials;     // grain and wall materials
  std::vector<PairLaw> pair_law;       // (n_materials x n_materials), symmetric
  int n_materials() const { return static_cast<int>(materials.size()); }
  const PairLaw& law(int a, int b) const { return pair_law[a * materials.size() + b]; }

  // --- environment ---
  std::vector<Wall> walls;
  std::vector<BodyModel> bodies;       // rigid bodies (docs/model.md §6)
  double body_kn = 0;                  // body–body normal stiffness of one shape pair, N/m (<= 0: the scene k_n);
                                       // k_t, C_n, C_t of body–body contacts scale with it (docs/model.md §6)
  // Bullet shapes of every body shape for the body–body narrow phase: built by
  // build_body_geometry() (called from finalize_model, and lazily by
  // body_body_forces if missing or out of date). Shared by copies of the Model;
  // a cache, not part of the description. It holds scratch used during a
  // query, so a Model and its copies must run body_body_forces on one thread
  // at a time (a concurrent call throws std::logic_error).
  mutable std::shared_ptr<BodyGeometry> body_geometry;
  Vec3 gravity = Vec3(0, 0, -9.81);    // m/s^2
  Periodic periodic;                   // none by default
  // Per-grain force fields added after the contacts (field.hpp), in this
  // order. Shared, immutable: copies of the Model share them. Empty: none.
  std::vector<std::shared_ptr<const Field>> fields;
  // Contacts between two free (not glued) grains on (the default). Off: free
  // grains touch glued grains, walls and bodies only, never each other (the
  // collisionless plume, docs/scenes.md D).
  bool mobile_contacts = true;

  // --- integration ---
  double dt = 1e-5;                    // s
  double kn = 0;                       // scene normal stiffness of the linear law, N/m
  double skin = 0;                     // neighbour-list skin, m (<= 0: chosen by finalize_model)
  double body_step_limit = 0;          // largest safe drift of a body point in one step, m (finalize_model; 0: none)
  int partitions = 4;                  // fixed work partitions of the force pass: results are
                                       // bit-identical for any thread count <= partitions
  int parallel_min_grains = 3000;      // smaller scenes run on one thread (same result)
  bool any_resistance = false;         // some pair type has rolling or twisting resistance
  int single_grain_material = -1;      // the material of every grain if they share one, else -1
  Guards guards;
  SleepParams sleep;
  ScheduleParams schedule;
  FreeFlightParams free_flight;

  double max_radius = 0, min_radius = 0;  // extreme grain radii, m
};

// Append a grain (radius r, material index) to the model; returns its id.
int add_grain(Model& m, double radius, int material, bool fixed = false);

// Derive masses, inverse masses, the pair-law table, radius extremes and the
// default skin. Call once after materials, grains, walls, kn and dt are set.
// Throws InputError on inconsistent parameters.
void finalize_model(Model& m);

// pkdgrav stiffness rule k_n = m_p (v_max / x_max)^2 (docs/model.md §4).
double kn_rule(double grain_mass, double v_max, double x_max);
// Time step dt = pi sqrt(m_p / (2 k_n)) / N.
double dt_rule(double grain_mass, double kn, double steps_per_contact);
// Duration of an isolated linear contact, sqrt(m* (pi^2 + ln^2 eps) / k_n).
double linear_contact_time(double mstar, double kn, double eps_n);
// Damping coefficient of the linear law: C = coef * sqrt(m*), coef = -2 ln eps sqrt(k/(pi^2+ln^2 eps)).
double linear_damping_coef(double k, double eps);
// Hertz contact duration for an elastic impact at speed v (2.868 (m*^2/(R E*^2 v))^(1/5)).
double hertz_contact_time(double mstar, double reff, double e_star, double v);

// Steps per contact of every live pair type (docs/model.md §4).
struct PairResolution {
  std::string label;      // e.g. "grain-grain (moderate, smallest grains)"
  double contact_time;    // s
  double steps;           // contact_time / dt
};
std::vector<PairResolution> pair_resolution(const Model& m, double v_ref);

}  // namespace rt
