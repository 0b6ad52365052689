// Evolving state of a DEM scene: grain kinematics, accumulated forces, the
// neighbour list with its per-contact spring history, and run counters.
// Everything is stored as separate dense arrays indexed by grain id
// (structure of arrays). Buffers are sized once by init_state(); the step
// itself never allocates, except when a neighbour list outgrows its reserve.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "regolith_twin/core/model.hpp"

namespace rt {

// Half neighbour list in CSR form: row i holds partners j > i within
// r_i + r_j + skin, sorted by j. Contact history lives beside each entry, so
// it persists for as long as the pair stays in the list.
struct PairList {
  std::vector<int> row_start;   // first entry of row i (n_grains + 1)
  std::vector<int> partner;     // j of each entry
  std::vector<int> owner;       // i of each entry (derived from row_start by partition_work)
  std::vector<double> sqrt_mstar;  // sqrt of the pair's reduced mass, sqrt(kg)
  std::vector<Vec3> spring_t;   // tangential spring S, m (oriented from i to j)
  std::vector<Vec3> spring_r;   // rolling spring delta_R, rad
  std::vector<double> spring_w; // twisting spring delta_T along n, rad
  std::vector<uint8_t> touching; // 1 while the pair overlaps (its springs are live)
  // Periodic boxes: the image code of each entry's partner (Periodic::shift);
  // empty otherwise.
  std::vector<int8_t> image;
  int size() const { return static_cast<int>(partner.size()); }
};

// Grain–wall candidates within r_i + skin, sorted by (grain, wall), with history.
struct WallList {
  std::vector<int> grain;       // grain index of each entry
  std::vector<int> wall;        // wall index of each entry
  std::vector<Vec3> spring_t;   // tangential spring, m
  std::vector<Vec3> spring_r;   // rolling spring, rad
  std::vector<double> spring_w; // twisting spring, rad
  std::vector<uint8_t> touching; // 1 while the grain overlaps the wall
  int size() const { return static_cast<int>(grain.size()); }
};

// History of one contact of a grain with a mesh shape (docs/model.md §6.3).
// A (grain, mesh shape) entry touches the mesh at up to kMeshSlots features
// at once; each contact keeps its springs in the slot whose normal (body
// frame) is closest to its own, so the history follows it across triangles.
constexpr int kMeshSlots = 4;
struct MeshSlot {
  Vec3 normal = Vec3::Zero();   // unit normal from the grain towards the mesh at the last force pass, body frame
  Vec3 spring_t = Vec3::Zero(); // tangential spring, m
  Vec3 spring_r = Vec3::Zero(); // rolling spring, rad
  double spring_w = 0;          // twisting spring, rad
  int32_t touching = 0;         // 1 while the slot holds a live contact
  int32_t unused = 0;           // (no padding bytes: checkpoints store slots as bytes)
};

// Grain–body candidates within r_i + skin of a body shape, sorted by
// (grain, body, shape), with history. A mesh shape's entry keeps its
// contacts' springs in kMeshSlots slots (mesh_first) and leaves the entry's
// own springs at zero; its touching flag is set while any slot is live.
struct BodyGrainList {
  std::vector<int> grain;       // grain index of each entry
  std::vector<int> body;        // body index
  std::vector<int> shape;       // shape index within the body
  std::vector<double> sqrt_mstar;  // sqrt(m_i M / (m_i + M)), sqrt(kg)
  std::vector<Vec3> spring_t;   // tangential spring, m
  std::vector<Vec3> spring_r;   // rolling spring, rad
  std::vector<double> spring_w; // twisting spring, rad
  std::vector<uint8_t> touching;
  std::vector<int> mesh_first;  // first of the entry's kMeshSlots slots in mesh_slots (mesh shapes), else -1
  std::vector<MeshSlot> mesh_slots;
  int size() const { return static_cast<int>(grain.size()); }
};

// Contact point between two bodies with its tangential history. Points are
// identified from step to step by their position on each body (body frames),
// as a persistent contact manifold does.
struct BodyPointContact {
  int a = 0, b = 0;             // bodies, a < b
  int shape_a = 0, shape_b = 0; // shapes of a and b
  Vec3 local_a = Vec3::Zero();  // contact point on a, a's body frame, m
  Vec3 local_b = Vec3::Zero();  // contact point on b, b's body frame, m
  Vec3 spring_t = Vec3::Zero(); // tangential spring, m
  double overlap = 0;           // penetration depth at the last force pass, m
  Vec3 normal = Vec3::UnitZ();  // unit normal from a to b at the last force pass (world)
  Vec3 point = Vec3::Zero();    // contact point at the last force pass (world), m
  Vec3 force_a = Vec3::Zero();  // force on a at the last force pass, N
};

// One evaluated contact, recorded only while State::log_contacts is set
// (verification and diagnostics; the normal step records nothing).
struct ContactRecord {
  int i, j;            // grains; j = -1 - wall index for a wall contact
  double overlap;      // m
  double fn;           // normal force used for the limits, N
  double ft;           // |F_T|, N
  double mr, mt;       // |M_R|, |M_T|, N m
  double mu_s, mu_r, mu_t, beta, reff;  // law constants of the pair
};

// Accumulators of one work partition of the force pass (merged in partition order).
struct ThreadScratch {
  std::vector<Vec3> force;      // force on grains, N (thread 0 writes State::force)
  std::vector<Vec3> torque;     // torque, N m
  int touched_lo = 0, touched_hi = 0;  // index range written by this partition
  std::vector<int> touched;       // with sleeping: the grains this partition writes, ascending (merged by list)
  double max_overlap_ratio = 0;
  int max_overlap_grain = -1;
  long contacts = 0;
  std::vector<ContactRecord> log;  // filled only while State::log_contacts
  Vec3 wall_force = Vec3::Zero();  // force of this partition's wall contacts on grains, N
  std::vector<Vec3> body_force;    // grain–body reaction on each body, N (n_bodies)
  std::vector<Vec3> body_torque;   // about each body's centre of mass, N m
  std::vector<int> list_partners;  // list build: partners of this block of rows (capacity kept)
  std::vector<int> mesh_tris;      // grain–mesh contacts: triangles near the grain (capacity kept)
  std::vector<MeshHit> mesh_hits;  // grain–mesh contacts: touched features (capacity kept)
};

struct StepStats {
  double max_overlap_ratio = 0;  // max over contacts of overlap / smaller radius
  int max_overlap_grain = -1;    // a grain of the contact with that overlap
  long contacts = 0;             // grain–grain contacts with overlap > 0
  long wall_contacts = 0;        // grain–wall contacts with overlap > 0
  long body_contacts = 0;        // grain–body contacts with overlap > 0
  long body_body_contacts = 0;   // body–body contact points
  bool finite = true;            // every velocity finite after the last kick
  int bad_body = -1;             // a free body whose state became non-finite (-1: none)
  double max_body_step = 0;      // largest displacement of a point of a free body in the last drift, m
  int max_body_step_body = -1;   // the body of that displacement
  double max_grain_step = 0;     // largest drift of a grain without a reach in the last step, m
  double max_body_overlap_ratio = 0;  // deepest body–body point over the thinner shape's half thickness
  int body_overlap_a = -1, body_overlap_b = -1;  // the bodies of that point
  bool lists_built = false;      // the grain lists were rebuilt in the last step (contacts per grain are counted)
  int max_contacts = 0;          // most touching contacts of one grain, counted when lists_built
  int max_contacts_grain = -1;   // that grain
  double max_disp2 = 0;          // squared max displacement since the last list build, m^2
                                 // (with free flight: of the grains without a reach)
  double max_free_disp2 = 0;     // free flight: squared max displacement of the grains with a reach, m^2
  double free_margin = 1e300;    // free flight: smallest reach minus own displacement since the build, m
};

// Sleep state of the grains and cells (core/sleep.hpp). The per-grain arrays
// and the cells' quiet times are state (checkpointed); awake, watch and the
// force pass's entry segments are derived from them.
struct SleepState {
  bool initialized = false;
  Vec3 lo = Vec3::Zero();       // low corner of the cell grid, m
  double cell = 0;              // cell side, m
  double d_mean = 0;            // mean grain diameter when sleeping started, m (the thresholds' scale)
  int nx = 0, ny = 0, nz = 0;   // cells per axis
  std::vector<uint8_t> asleep;  // 1 while grain i sleeps (n_grains)
  std::vector<Vec3> f_ref;      // sleeping grains: force of the evaluated contacts at the first pass after the
                                // evaluated set last changed, N (n_grains)
  std::vector<Vec3> f_last;     // awake grains: force at the last check, N (n_grains)
  std::vector<double> quiet;    // per cell: time its awake grains have been quiet, s
  Vec3 gravity = Vec3::Zero();  // gravity the sleeping grains rest under
  long next_check = 0;          // step of the next check
  double last_check = 0;        // time of the last check, s
  bool ref_pending = true;      // f_ref is taken at the next force pass
  // statistics
  long fell_asleep = 0, woke = 0;  // grain transitions
  long checks = 0;
  double awake_grain_steps = 0;    // sum over steps of the awake grains (their mean: work done)
  double discarded_energy = 0;     // kinetic energy zeroed when grains fell asleep, J
  double discarded_max_speed = 0;  // fastest grain put to sleep, m/s
  // derived (not checkpointed)
  std::vector<int> awake;          // ids of the awake grains, ascending
  std::vector<int> watch;          // sleeping grains with an evaluated contact (checked every step)
  std::vector<int> cell_scratch;   // per grain cell index (checks)
  std::vector<uint8_t> cell_flags; // per cell flags (checks)
  std::vector<double> cell_sum;    // per cell sum of squared speeds (checks)
  std::vector<int> cell_count;     // per cell awake grains (checks)
  std::vector<uint8_t> woken;      // grains woken by this update (scratch)
  std::vector<uint8_t> touch;      // grains touching a grain, wall or body (checks)
};

// Stiffness schedule state (model.hpp ScheduleParams, docs/model.md §17).
struct ScheduleState {
  double scale = 1;              // current factor on the scene's k_n (Δt = scene Δt / sqrt(scale))
  double min_scale = 1;          // smallest factor reached
  double dt_min = 0, dt_max = 0; // smallest and largest Δt taken under the schedule, s (0: none yet)
  long lowered = 0, raised = 0;  // changes of k_n
  double injected = 0;           // elastic energy added to live contacts by raising k_n, J
  double released = 0;           // elastic energy taken from live contacts by lowering k_n, J
  double max_injected_fraction = 0;  // largest injection relative to the kinetic energy then
  double kinetic_ref = 0;        // largest kinetic energy seen at the start and at every change, J
  long raised_grains = 0, raised_body = 0;  // raises by what set v_fast: the fastest grain, a body
  bool started = false;          // the schedule has run (its base is the scene's k_n and Δt)
  double t_start = 0;            // simulated time it started, s
  double v_grains = 0;           // fastest grain at the last check, m/s
  long low_since = -1;           // step since which the target has stayed low (-1: it has not)
};

struct State {
  double time = 0;              // simulated time, s
  long step = 0;                // steps taken
  // Elapsed steps counted in steps of the scene's Δt: each step adds
  // tick_len (1 unless a stiffness schedule has changed Δt, then Δt / Δt_scene).
  // Observers that sample every N steps sample when ticks cross a multiple of
  // N, so their sampling stays fixed in simulated time under a schedule.
  double ticks = 0;
  double tick_len = 1;
  ScheduleState schedule;

  std::vector<Vec3> pos;        // grain centre, m (n_grains)
  std::vector<Vec3> vel;        // velocity, m/s
  std::vector<Vec3> omega;      // angular velocity, rad/s
  std::vector<Vec3> vel_mid;    // mid-step velocity v(n+1/2) while vel holds the predicted v(n+1), m/s
  std::vector<Vec3> omega_mid;  // mid-step angular velocity, rad/s
  std::vector<Vec3> force;      // total force of the last force pass, N
  std::vector<Vec3> torque;     // total torque of the last force pass, N m
  Vec3 wall_force = Vec3::Zero();  // total force of the walls on the grains in the last force pass, N
                                   // (partition sums added in partition order: docs/model.md §12)

  std::vector<BodyState> bodies;  // rigid bodies (n_bodies)
  // External wrench on each body's centre of mass, world frame (operator
  // input: thrusters, a mobility arm, a what-if push). Empty: none. An input,
  // not state: checkpoints do not hold it.
  std::vector<Vec3> body_applied_force, body_applied_torque;  // N, N m (n_bodies or empty)

  // Evolving parameters of the fields (a gas field's anchoring plane, m), set
  // and moved by the scene that owns them; checkpointed.
  std::vector<double> field_values;

  std::vector<uint8_t> wall_on;  // 1 while wall w takes part (a lifted cylinder is 0) (n_walls)

  // Neighbour bookkeeping.
  PairList pairs;
  WallList wall_pairs;
  std::vector<Vec3> pos_at_build;  // positions when the lists were last built
  std::vector<int> contact_count;  // touching contacts per grain at the last count (scratch, step.hpp)
  // Free flight (model.hpp FreeFlightParams, docs/model.md §18): per grain, the
  // gap guaranteed at the last full build to everything it has no list entry
  // with (0: it has an entry, or free flight is off); empty until a build.
  std::vector<double> reach;
  std::vector<Vec3> body_pos_at_full;  // body poses at the last full build
  std::vector<Quat> body_q_at_full;
  long free_grains = 0, free_grains_max = 0;  // grains with a reach at the last build, and at most
  std::vector<uint8_t> reach_listed;  // scratch of the reach build: grain has a list entry
  long rebuilds = 0;
  bool lists_valid = false;
  bool rebuild_requested = false;  // rebuild at the next step (walls switched on/off)
  bool forces_valid = false;

  // Thread partition of the pair rows, fixed between rebuilds (deterministic).
  std::vector<int> thread_row_begin;  // (n_threads + 1)
  std::vector<int> thread_wall_begin; // (partitions + 1) wall entries of grains [n q/P, n (q+1)/P)
  std::vector<int> thread_body_begin; // grain–body entries, split at grain boundaries
  // Entry segments [seg_begin, seg_end) of the pair list evaluated by each
  // partition: partition p takes segments [thread_seg_begin[p], thread_seg_begin[p+1]).
  // Without sleeping, one segment per partition (its rows' entries).
  std::vector<int> seg_begin, seg_end, thread_seg_begin;
  std::vector<ThreadScratch> scratch;

  // Cell-list scratch (reused by every rebuild).
  std::vector<int> cell_start, cell_items, cell_of;
  PairList pairs_next;              // double buffer for rebuilds
  WallList wall_pairs_next;

  // Grain–body candidates and body–body contact points with their history.
  BodyGrainList body_grains, body_grains_next;
  double body_list_grain_disp = 0;  // max grain displacement (since pos_at_build) when body_grains was built, m
  long body_rebuilds = 0;
  // body_points, body_points_next: capacity for every point the bodies'
  // shape pairs can have (make_state), so the step does not allocate.
  std::vector<BodyPointContact> body_points, body_points_next;
  // Set by prime() during its force pass: body_body_forces stores the spring
  // each point carried into the pass, not the advanced one (the pass
  // evaluates forces without moving the contact history forward).
  bool hold_body_springs = false;

  StepStats stats;
  SleepState sleep;
  bool log_contacts = false;  // record every contact of each force pass in scratch[p].log
  bool scalar_kernel = false;  // evaluate contacts one at a time (reference for the batched kernel)
};

// True when the last step crossed a multiple of `every` ticks counted from
// `origin` (every step with every = 1; without a schedule: (step - origin) % every == 0).
inline bool ticks_crossed(const State& s, long every, double origin = 0) {
  const double a = (s.ticks - origin) / double(every), b = (s.ticks - s.tick_len - origin) / double(every);
  return std::floor(a) != std::floor(b);
}

// Sleeping is on and its state initialised (core/sleep.hpp).
inline bool sleep_active(const Model& m, const State& s) { return m.sleep.enabled && s.sleep.initialized; }

// Multiplies every stored contact spring (tangential, rolling, twisting; grain
// pairs, grain–wall, grain–body with their mesh slots, body–body points) by f.
// With every spring stiffness scaled by 1/f at the same time, the springs'
// forces are unchanged (the stiffness schedule's raise, docs/model.md §17).
void scale_contact_springs(State& s, double f);

// A state for model m: zero kinematics (callers set pos, vel, omega), every
// buffer sized, lists built at the first step.
State make_state(const Model& m);

}  // namespace rt
