// Measurements of the sampler shot around the projectile's impact
// (docs/scenes.md B.4): the impact clock, ejection angles and speeds, the
// energy partition by spring type, the attenuation of the impact wave and
// Z-model fits of the excavation flow at set times. "After impact" times
// count from the projectile's first contact, as seen by the ImpactClock; the
// other observers take a pointer to it and must come after it in the run's
// observer list (so they see the impact on the step it happens). Each does
// its work only on the steps it samples; between them a step costs a
// comparison. Pass a clock that outlives the observer.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "regolith_twin/core/contact_law.hpp"
#include "regolith_twin/run/observer.hpp"
#include "regolith_twin/scenes/sampler/zmodel.hpp"

namespace rt {

// --- impact clock ------------------------------------------------------------------

// The step at which the projectile grain first touches anything: a
// grain–grain pair with the touching flag set, or a grain–wall or grain–body
// contact. Checked after every step until it has happened (and in start(),
// for a state that begins in contact); only the list entries of the
// projectile are read, found again after each list rebuild.
class ImpactClock : public Observer {
 public:
  explicit ImpactClock(int projectile) : projectile0_(projectile), projectile_(projectile) {}
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  void summary(JsonObject& out) const override;

  bool hit() const { return hit_; }
  double t_impact() const { return t_impact_; }      // s (run time), NaN before the impact
  long impact_step() const { return impact_step_; }  // -1 before the impact
  double impact_ticks() const { return impact_ticks_; }  // State::ticks at the impact
  int projectile() const { return projectile_; }     // current index; -1 once it left the run
  // Projectile centre and velocity at the impact step.
  const Vec3& impact_position() const { return impact_pos_; }
  const Vec3& impact_velocity() const { return impact_vel_; }
  // Time after impact, s (negative before it).
  double after(const State& s) const { return hit_ ? s.time - t_impact_ : -1.0; }

 private:
  bool touching(const Model& m, const State& s);
  void mark(const State& s);
  int projectile0_, projectile_;
  bool hit_ = false;
  double t_impact_;
  long impact_step_ = -1;
  double impact_ticks_ = 0;
  Vec3 impact_pos_ = Vec3::Zero(), impact_vel_ = Vec3::Zero();
  // Pair-list entries holding the projectile, valid for one list build.
  std::vector<int> entries_;
  long entries_rebuilds_ = -1;
  int entries_size_ = -1;
};

// --- ejection angles -----------------------------------------------------------------

// One ejected grain at its launch (the first sample with its centre above h_s).
struct EjectaLaunch {
  double t = 0;          // s after impact
  int grain = 0;         // index when launched
  Vec3 pos = Vec3::Zero(), vel = Vec3::Zero();
  double r = 0;          // horizontal distance from the impact axis, m
  double speed = 0;      // m/s
  double angle_deg = 0;  // of the velocity from the horizontal, positive up, in [-90, 90]
  double volume = 0;     // m^3
};

// Bed grains (not the projectile) whose centre rises above the highest
// pre-impact surface grain centre h_s. Checked every `every` steps from the
// impact step on (not between samples, and the crossing is not interpolated:
// a launch is recorded at the first sample that finds the centre above h_s,
// with the velocity it has then). Grains already above h_s at start() never
// count.
class EjectionAngles : public Observer {
 public:
  static constexpr double kBinDeg = 6;  // histogram bins over 0-90 deg
  static constexpr int kBins = 15;
  // axis: the vertical impact axis through (axis.x, axis.y); R: container
  // radius (m); g: gravity magnitude (m/s^2); both normalise launch figures.
  EjectionAngles(const ImpactClock* clock, double surface_height, const Vec3& axis, double container_radius,
                 double g, int every);
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void grains_removed(const std::vector<int>& old_to_new) override;
  // Grains added during the run (a second projectile) are not bed grains.
  void grains_added(const Model& m, const State& s, int first) override { done_.resize(m.n_grains, 1); }
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void summary(JsonObject& out) const override;

  const std::vector<EjectaLaunch>& launches() const { return launches_; }  // in launch order
  long count() const { return long(launches_.size()); }
  double volume() const { return volume_; }  // m^3
  // Launches per 6 deg bin over [0, 90] (90 in the last bin); angles outside are in outside().
  std::vector<long> histogram() const;
  long outside() const;
  double mean_angle_deg() const;    // over all launches; NaN without any
  double median_angle_deg() const;  // (mean of the middle two for an even count)
  // ejecta.csv: t (s after impact), x_launch (m from the axis), r_launch/R,
  // speed (m/s), speed/sqrt(gR), angle (deg); one row per launch.
  void write_csv(const std::string& path) const;

 private:
  const ImpactClock* clock_;
  double h_s_;
  Vec3 axis_;
  double R_, g_;
  int every_;
  std::vector<uint8_t> done_;  // launched, or above h_s at the start
  std::vector<EjectaLaunch> launches_;
  double volume_ = 0;
};

// --- energy partition ------------------------------------------------------------------

// Energies of one sample, J: kinetic energy of the bed grains and of the
// projectile, and elastic energy by spring type of bed–bed contacts, of
// projectile–grain contacts and of grain–wall and grain–body contacts
// (the projectile's included).
struct EnergyParts {
  double t = 0;  // s after impact (the run time for energy_parts())
  double bed_trans = 0, bed_rot = 0, proj_trans = 0, proj_rot = 0;
  ElasticSplit bed_bed, proj_grain, grain_wall;
  double kinetic() const { return bed_trans + bed_rot + proj_trans + proj_rot; }
  double elastic() const { return bed_bed.total() + proj_grain.total() + grain_wall.total(); }
  double total() const { return kinetic() + elastic(); }
};

// The energy parts of a state (free grains only; projectile -1: none).
// Elastic terms come from for_each_elastic_contact (core/energy.hpp), i.e.
// with the stiffnesses of the force pass.
EnergyParts energy_parts(const Model& m, const State& s, int projectile);

// Over the first `window` s after impact, sampled every `every` steps from
// the impact step on, and once more at the first step at or after the end of
// the window: the energy parts normalised by the projectile's kinetic energy
// (translation + rotation) at start().
class EnergyPartition : public Observer {
 public:
  EnergyPartition(const ImpactClock* clock, int every, double window = 2e-4);
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void summary(JsonObject& out) const override;

  double initial_energy() const { return e0_; }                   // J
  const std::vector<EnergyParts>& samples() const { return samples_; }  // J
  bool window_complete() const { return complete_; }
  // energy_partition.csv: t (s after impact) and every term over the
  // initial energy, then their sum.
  void write_csv(const std::string& path) const;

 private:
  const ImpactClock* clock_;
  int every_;
  double window_;
  double e0_ = 0;
  bool complete_ = false;
  std::vector<EnergyParts> samples_;
};

// --- wave attenuation --------------------------------------------------------------------

constexpr double kWaveNaN = std::numeric_limits<double>::quiet_NaN();

struct WaveOptions {
  Vec3 impact = Vec3::Zero();            // impact point on the surface, m
  std::vector<double> times = {1.2e-5, 6.2e-5};  // s after impact
  double bin = 2.5e-3;                   // distance bin, m
  double half_angle_deg = 60;            // downward cone under the impact point
  double rest_rms = -1;                  // bed RMS speed at rest, m/s (< 0: measured at start())
  double floor_factor = 10;              // noise floor = floor_factor * rest_rms
};

// One capture: the largest grain speed per distance bin in the cone, the
// wave front and the power-law fit over the bins from the projectile out to
// the front (docs/scenes.md B.4).
struct WaveProfile {
  double t = 0;                // s after impact, asked
  double t_actual = 0;         // s after impact of the step captured
  std::vector<double> max_speed;  // per bin k = [k bin, (k+1) bin), m/s (0 if empty)
  std::vector<int> grains;        // grains per bin
  double contact = 0;          // distance of the projectile's far side from the impact point, m
  double floor = 0;            // noise floor, m/s
  int first_bin = 0;           // first bin wholly beyond the projectile: the fit's first bin
  int signal_end = -1;         // last bin above the floor (-1: none)
  bool front_found = false;    // a break was found (else the front is the signal end)
  int front_bin = -1;          // last bin of the wave (-1: none)
  double front = kWaveNaN;     // outer edge of the front bin, (front_bin + 1) bin, m
  double break_ratio = kWaveNaN;  // least squares of the two pieces over that of one line (NaN: no search)
  int last_bin = -1;           // last bin of the fit (the front bin)
  std::vector<int> used;       // bins in the fit: first_bin..last_bin above the floor
  std::vector<int> precursor;  // bins above the floor beyond the front
  double precursor_median = kWaveNaN, precursor_max = kWaveNaN;  // of their max speeds, m/s
  double slope = kWaveNaN, intercept = kWaveNaN;  // ln v = intercept + slope ln d (NaN with fewer than 2 bins)
};

// The front and the fit of a profile whose max_speed, floor and first_bin are
// set (bins of width `bin`, m): the bins from first_bin on above the floor are
// the signal, up to the last one (signal_end). With at least six, they are cut
// into an inner and an outer run of at least three bins each where two
// straight lines fitted by least squares to (ln d_mid, ln v_max), one per
// run, leave the least squared residual; the cut is the front if it leaves
// less than half the residual of one line over all of them and the outer
// run's median max speed is below the inner line at the last inner bin (a drop
// to a slower precursor). Otherwise the front is the signal end and there is
// no precursor. The power law is then fitted over first_bin..front_bin.
void fit_wave_profile(WaveProfile& w, double bin);

// At each time after impact (at the first step at or after it), for the bed
// grains (not the projectile) in the downward cone of the given half-apex
// angle with its apex at the impact point: the largest speed in each bin of
// distance from the impact point, fitted by fit_wave_profile from the first
// bin entirely beyond the projectile (its centre's distance plus its radius)
// to the wave front.
class WaveAttenuation : public Observer {
 public:
  WaveAttenuation(const ImpactClock* clock, const WaveOptions& opt);
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void summary(JsonObject& out) const override;

  double rest_rms() const { return rest_rms_; }
  const std::vector<WaveProfile>& profiles() const { return profiles_; }  // captured so far, in time order
  // wave.csv: t (s after impact, captured), bin, distance from and to, mid
  // distance (m), max speed (m/s), grains, in_fit (0/1), precursor (0/1).
  void write_csv(const std::string& path) const;

 private:
  void capture(const Model& m, const State& s, double t);
  const ImpactClock* clock_;
  WaveOptions opt_;
  double rest_rms_;
  std::vector<WaveProfile> profiles_;
};

// --- Z-model fits ---------------------------------------------------------------------------

// One time after impact: the three fits of the bed's velocity field.
struct ZSample {
  double t = 0, t_actual = 0;  // s after impact, asked and captured
  double speed_min = 0;        // m/s
  ZFit fixed_h0;               // H₀ = options' h0 (0 by default)
  ZFit fitted_h0;              // H₀ fitted too
  ZFit surface;                // top layer of cells only, H₀ as fixed_h0
};

// At each time after impact (first step at or after it) the positions and
// velocities of the bed grains (not the projectile) go to fit_zmodel
// (zmodel.hpp) three times: H₀ fixed, H₀ fitted, surface layer only. Grains
// at or below factor × rest RMS speed are left out.
class ZModelSampler : public Observer {
 public:
  // base: impact point, region, cell and search settings (its speed_min,
  // fit_h0 and surface_only are set here); rest_rms < 0: measured at start().
  ZModelSampler(const ImpactClock* clock, const ZFitOptions& base, double rest_rms,
                std::vector<double> times = {45e-6, 1.25e-3, 12.5e-3}, double factor = 10);
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void summary(JsonObject& out) const override;

  double rest_rms() const { return rest_rms_; }
  const std::vector<ZSample>& samples() const { return samples_; }
  // zmodel.csv: t (s after impact, captured), variant (fixed_h0, fitted_h0,
  // surface), Z, H0 (m), misfit mean, SD and RMS (deg), cells, grains, speed_min (m/s).
  void write_csv(const std::string& path) const;

 private:
  const ImpactClock* clock_;
  ZFitOptions base_;
  double rest_rms0_, rest_rms_;
  std::vector<double> times_;
  double factor_;
  std::vector<ZSample> samples_;
};

// RMS speed of the free grains other than `skip`, m/s (the rest level of a bed).
double rms_speed(const Model& m, const State& s, int skip);

}  // namespace rt
