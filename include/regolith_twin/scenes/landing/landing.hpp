// Lander scenes (docs/scenes.md A): placing the lander for an attitude,
// impact angle and speed; perturbed beds; and the landing outcome with the
// published definitions (trim plane, run end, ballistic extrapolation,
// corners), tracked from the lander's state alone.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/state.hpp"
#include "regolith_twin/observers/body_contacts.hpp"
#include "regolith_twin/run/observer.hpp"

namespace YAML {
class Node;
}

namespace rt {

enum class Attitude { Flat, BCF, FCF };

struct LandingSpec {
  std::string lander;            // name of the lander body
  double rim = 0.30;             // trim plane height (z), m: the surface reference
  double container_radius = 0.75;  // m (far-field ring and perturbation)
  Attitude attitude = Attitude::BCF;
  double pitch_deg = 20;         // corner tilts: about the horizontal axis normal to the motion, deg
  double roll_deg = 10;          // ... and about the direction of motion, deg (a corner, not an edge, first)
  double angle_deg = 30;         // impact angle from the vertical (trim-plane normal), deg
  double heading_deg = 0;        // direction of horizontal motion (azimuth about z), deg
  double speed = 0.19;           // impact speed, m/s
  double clearance = 0.002;      // lowest lander point above the surface at the start, m
  Vec3 aim = Vec3::Zero();       // aim point on the trim plane (x, y used), m
  double slope_deg = 0;          // gravity tilted about the horizontal axis normal to the motion; + = upslope
  double g = 2.5e-4;             // gravity magnitude, m/s^2
  double after_liftoff = 1.0;    // run end: this long after lift-off, s
  double max_after_contact = 60; // ... or this long after first contact, s
  double max_time = 600;         // safety net: no contact at all within this time, s
  // A run without lift-off also ends once the lander is trapped: its kinetic
  // energy (translation + rotation) has stayed below half the potential
  // energy it needs to lift off for this long (s; 0: never, run to
  // max_after_contact). Lift-off needs every corner above the trim plane, so
  // the centre of mass at least (smallest half-extent of the box - offset of
  // the box from the centre of mass) above it. V_out = 0 either way.
  double trapped_hold = 1.0;
  double far_ring = 0.05;        // width of the outer ring for the far-field quiet check, m
  double sphere_radius = 0.155;  // volume-equivalent sphere radius for the travel distance, m
  long repeat = 0;               // perturbed bed number (0: the bed as prepared)
  unsigned long perturb_seed = 1;  // seed of the perturbation of repeat > 0
  double sample_every = 0.01;    // s between time-series rows
  // Active zone: grains farther than this (horizontally) from the lander stay
  // frozen where the relaxed bed left them; the zone follows the lander and
  // a grain once woken stays free. 0: every grain is free. The RMS speed in
  // the zone's outer ring is reported, so a run shows whether the frozen bed
  // beyond it was indeed at rest.
  double active_radius = 0;
};

// Read a `landing:` block (every error names the file and the key).
LandingSpec parse_landing(const YAML::Node& node, const std::string& source);

// Gravity vector of the spec (magnitude g, tilted for slopes).
Vec3 landing_gravity(const LandingSpec& spec);


// Perturbation of repeat r: bed rotation angle (rad) and aim offset (m,
// within one mean grain diameter), drawn from the seed.
struct Perturbation {
  double angle = 0;
  Vec3 aim_offset = Vec3::Zero();
};
Perturbation perturbation(const LandingSpec& spec, double mean_radius);

// Place the lander body (index b) for the spec: attitude, the lowest point
// `clearance` above the trim plane on the line of approach through the aim
// point, velocity `speed` at `angle_deg` from the vertical, no spin. Grains
// stick out of the trim plane (trimming keeps every centre below it), so the
// lander is then moved back along the approach line until every grain is at
// least `clearance` away from it.
void place_lander(const Model& m, State& s, int b, const LandingSpec& spec);

// World positions of the eight corners of the lander's largest box shape.
std::vector<Vec3> lander_corners(const Model& m, const State& s, int b);
std::vector<Vec3> lander_corners(const BodyModel& bm, const BodyState& bs);

// The lander's figures at the end of its collision (docs/scenes.md A.9).
struct Departure {
  double t = 0;                  // s
  double v_out = 0;              // centre-of-mass speed, m/s
  double e_lin_out = 0, e_rot_out = 0;  // J
  double angle_out_deg = 0;      // outgoing velocity from the trim-plane normal, deg
  double spin_out = 0;           // |omega|, rad/s
  double h_liftoff = 0;          // centre-of-mass height above the trim plane, m
  double travel_distance = 0;    // ballistic, to the next impact, m (0 if not moving away)
  double travel_time = 0;        // s
  double second_impact_speed = 0;      // m/s
  double second_impact_angle_deg = 0;  // from the normal, deg
};

struct LandingOutcome {
  bool contact = false;          // the lander touched the bed
  // Lift-off (the published definition, the primary figures): after first
  // contact, once a corner has been below the trim plane (the top of the
  // bed cut at the rim), the first moment all eight corners are above it;
  // V_out is the centre-of-mass speed then, and the collision lasts from
  // first contact to then. A lander that never puts a corner under the
  // plane (a bounce off a boulder or a cliff) lifts off at its clear
  // lift-off.
  bool lifted_off = false;
  // Clear lift-off (the variant, which also ends the run): all eight corners
  // above the trim plane, no contact left and the centre of mass moving away
  // from the surface. A contact with the bed within the after_liftoff window
  // cancels it (the lander had not left: corners of a tilted lander can all
  // be above the plane in mid-collision while it turns, on grains that stand
  // above the plane); touches by ejected grains (centre more than one mean
  // radius above the plane) do not.
  bool lifted_off_clear = false;
  int relandings = 0;            // clear lift-offs cancelled by a renewed contact
  std::string ended_by;          // after_liftoff | trapped | max_after_contact | max_time
  double t_contact = 0, t_liftoff = 0, t_liftoff_clear = 0, t_end = 0;  // s
  double v_in = 0, v_out = 0;    // centre-of-mass speed at first contact and at lift-off, m/s
  double speed_ratio = 0;        // v_out / v_in
  double e_lin_in = 0, e_rot_in = 0, e_lin_out = 0, e_rot_out = 0;  // J
  double rot_out_over_lin_in = 0, rot_out_over_lin_out = 0, energy_ratio = 0;
  double angle_out_deg = 0;      // outgoing velocity from the trim-plane normal, deg
  double spin_out = 0;           // |omega| at lift-off, rad/s
  double collision_duration = 0; // first contact to lift-off, s
  Departure clear;               // the figures at the clear lift-off (variant)
  double speed_ratio_clear = 0, collision_duration_clear = 0;
  double max_penetration = 0;    // deepest corner below the trim plane from first contact to the clear lift-off, m
  double h_liftoff = 0;          // centre-of-mass height above the trim plane at lift-off, m
  double travel_distance = 0;    // ballistic, to the next impact, m
  double travel_time = 0;        // s
  double second_impact_speed = 0;      // m/s
  double second_impact_angle_deg = 0;  // from the normal, deg
  double ejected_volume = 0;     // volume of grains whose centre ever rose > one mean radius above the plane, m^3
  long ejected_grains = 0;
  double far_field_rms = 0;      // RMS grain speed in the outer ring at the end, m/s
  double active_edge_rms = 0;    // RMS speed of free grains in the outer far_ring of the active zone at the end,
                                 // ejected grains left out (they land anywhere), m/s
  long active_grains = 0;        // grains free at the end (all grains without an active zone)
  double max_overlap_ratio = 0;
  long steps = 0;
  double wall_seconds = 0;
  std::string status = "ok";     // ok | blow_up
  std::string message;
};

// The part of the outcome that follows from the lander's own state: first
// contact, lift-off, ratios, penetration, ballistic travel and the run end.
// Fed the lander's state and contacts after every step, it needs nothing
// else, so a recorded run (body states with contact counts) gives the same
// numbers when fed again (regolith_bag_outcome).
class LandingTracker {
 public:
  LandingTracker(const BodyModel& bm, const LandingSpec& sp, const Vec3& gravity, double t_start = 0);
  // After a step at time t. Returns true once the run has ended (ended_by set).
  bool update(double t, const BodyState& bs, const BodyContacts& c);
  // Ratios and durations at the end of the run (time t).
  void finish(double t);
  bool ended() const { return !o_.ended_by.empty(); }
  const LandingOutcome& outcome() const { return o_; }
  const char* phase() const;  // approach | collision | flight
  double lowest_corner(const BodyState& bs) const;  // lowest corner above the trim plane, m
  // Simulated time left to the run end as expected from the lander's state
  // at time t (an estimate for the progress line, not a figure; < 0: none).
  // In flight it is exact. Before the clear lift-off the centre of mass must
  // still rise by a share between the lowest corner's depth below the trim
  // plane (the attitude kept) and the depth of the plane below the centre
  // plus the corners' reach (the worst attitude: kWorstShare of it once the
  // lander rises, kWorstShareSinking while it still sinks or approaches), at
  // its rising speed but not below kReboundFraction of its normal speed at
  // first contact; then after_liftoff. The constants were chosen on recorded
  // landings; docs/scenes.md A.9 gives the measured accuracy.
  double expected_time_left(double t, const BodyState& bs) const;
  static constexpr double kReboundFraction = 0.08, kWorstShare = 0.4, kWorstShareSinking = 0.7;

 private:
  bool trapped(double t, const BodyState& bs);
  Departure depart(double t, const BodyState& bs) const;
  BodyModel bm_;
  LandingSpec sp_;
  Vec3 g_;
  double t_start_ = 0;
  double liftoff_com_ = 0;      // lowest centre-of-mass height above the plane with every corner above it
  double trapped_since_ = -1;
  double reach_ = 0;            // largest distance of a corner from the centre of mass, m
  double vn_in_ = 0;            // normal speed into the plane at first contact, m/s
  bool went_under_ = false;     // a corner has been below the trim plane since first contact
  LandingOutcome o_;
};

// The tracker as an observer of a run: the lander's state and contacts after
// every step, its columns of series.csv, the progress text and the run end.
class LandingTrackerObserver : public Observer {
 public:
  // bed_top: grains above it are not bed (their touches do not count as bed contacts).
  LandingTrackerObserver(int lander, const LandingSpec& sp, double bed_top) : b_(lander), sp_(sp), bed_top_(bed_top) {}
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  // The tracker's end figures and the far-field check (RMS grain speed in the container's outer ring).
  void finish(const Model& m, const State& s) override;
  std::string progress(const Model& m, const State& s) const override;
  double time_left(const State& s) const override;
  double expected_time_left(const State& s) const override;

  const LandingTracker& tracker() const { return *tracker_; }
  double max_overlap_ratio() const { return max_overlap_; }
  double far_field_rms() const { return far_field_rms_; }

 private:
  int b_;
  LandingSpec sp_;
  double bed_top_;
  std::unique_ptr<LandingTracker> tracker_;
  double max_overlap_ = 0;
  double far_field_rms_ = 0;
};

struct LandingOptions {
  std::string out_dir;           // series.csv, summary.json, surface.csv (empty: nothing written)
  double progress_every = 2.0;   // wall seconds between progress lines (<= 0: none)
};

// The outcome's figures as JSON (summary.json "outcome", regolith_bag_outcome).
class JsonObject;
void landing_outcome_json(const LandingOutcome& o, JsonObject& out);

// Run the landing from the placed state to the run end (through the run
// loop, with the landing's observers), writing series.csv and surface.csv
// into opt.out_dir. The model is changed only by the active zone (grains
// frozen and woken).
LandingOutcome run_landing(Model& m, State& s, int b, const LandingSpec& spec, const LandingOptions& opt);

}  // namespace rt
