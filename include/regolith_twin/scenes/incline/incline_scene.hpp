// The inclined-plane scene kind (`incline:` block, docs/scenes.md C.2): a
// bed settled in a box periodic in x and y on a rough base of glued grains;
// gravity is then tilted by theta about the y axis (flow along +x).
//   mode onset:  theta raised from `start_deg` in `step_deg` steps, each held
//                `hold` s; the onset angle is the first at which the bed is
//                still flowing at the end of its hold (mean v_x of the free
//                grains above `flow_speed` sqrt(g d)) and not dying out: the
//                trend dv/dt over the hold's last quarter, carried over one
//                more hold, must leave it above that speed (a transient
//                surge that is decelerating to rest is not onset);
//   mode steady: theta fixed; over the last `average` s of the run, the
//                velocity and packing profiles in horizontal layers, the
//                Bagnold fit v_x(z) = A [1 - (1 - z/h)^(3/2)] and the inertial
//                number it implies, I = 3 d A / (2 h^(3/2) sqrt(Phi g cos theta));
//   mode rain:   the published protocol: theta fixed from the start, the
//                grains (generated loose above the plane, not settled) rain
//                onto the tilted plane; every grain that touches the plane is
//                glued where it touches (the first to land form the rough
//                base); at the end the bed is flowing if its mean v_x over the
//                last `average` s ends above `flow_speed` sqrt(g d) and, at
//                its trend over that window, stays above it for one more
//                window; the profiles and Bagnold fit as in steady mode.
//                With `rest_speed` > 0 the run ends early once every free
//                grain has stayed slower than `rest_speed` sqrt(g d) for
//                `rest_hold` s (checked every 0.01 s): the deposit is at rest,
//                not flowing, and its end state is read over that hold.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/run/scene.hpp"

namespace rt {

struct InclineSpec {
  bool onset = false;          // mode: onset (true) or steady
  bool rain = false;           // mode: rain (the published protocol)
  double angle_deg = 25;       // steady: the tilt
  double start_deg = 15, step_deg = 1, max_deg = 45, hold = 1.0;  // onset
  double flow_speed = 0.01;    // onset: flowing above this many sqrt(g d)
  double duration = 4.0;       // steady: s
  double average = 1.0;        // steady: the last s averaged
  double layer = 0.01;         // layer thickness of the profiles, m
  double sample_every = 0.01;  // s between rows of series.csv
  double rest_speed = 0;       // rain: end once every free grain is slower than this many sqrt(g d) (0: never)
  double rest_hold = 0.25;     // rain: ... for this long, s
};

// Velocity and packing profiles (layers from the base's top) and the Bagnold fit.
struct Profile {
  std::vector<double> z, vx, packing;  // layer centres above the base (m), mean v_x (m/s), solid fraction
  double height = 0;                   // flowing depth h above the base, m
  double packing_mean = 0;             // Phi over the layers below h - layer
  double bagnold_a = 0;                // A of the fit, m/s
  double inertial_number = 0;          // I from A, h, Phi, theta
  double fit_rms = 0;                  // m/s
};

// Least-squares A of v(z) = A [1 - (1 - z/h)^(3/2)] over layers with z < h.
double bagnold_amplitude(const std::vector<double>& z, const std::vector<double>& v, double h, double* rms);
// I = 3 d A / (2 h^(3/2) sqrt(Phi g cos theta)).
double bagnold_inertial_number(double a, double d, double h, double phi, double g, double theta);
// Least-squares slope of v against t.
double trend(const std::vector<double>& t, const std::vector<double>& v);
// The onset test at the end of a hold: v_end above `threshold`, and still above it after one more hold
// at the hold-end trend, v_end + dvdt_end hold (m/s, m/s^2, s).
bool onset_flowing(double v_end, double dvdt_end, double hold, double threshold);

class InclineObserver : public Observer {
 public:
  // rain: base_top and bed_top are found at the start of the averaging window; floor_z is the plane's height.
  InclineObserver(const InclineSpec& sp, double base_top, double bed_top, double diameter, double area,
                  double g, double floor_z = 0)
      : sp_(sp), base_(base_top), top_(bed_top), d_(diameter), area_(area), g_(g), floor_(floor_z) {}
  void start(const Model& m, const State& s) override;
  bool after_step(const Model& m, const State& s) override;
  void finish(const Model& m, const State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void summary(JsonObject& out) const override;
  std::string progress(const Model& m, const State& s) const override;
  void write_csv(const std::string& dir) const;

  double theta_deg() const { return theta_deg_; }  // the tilt asked for now (InclineFix applies it)
  double onset_deg() const { return onset_deg_; }  // < 0: none up to max_deg
  const Profile& profile() const { return prof_; }
  double mean_vx(const Model& m, const State& s) const;
  // rain: the end state (mean v_x at the end and its trend over the last `average` s) and the verdict.
  double end_vx() const { return end_vx_; }
  double end_dvdt() const { return end_dvdt_; }
  bool flowing() const { return flowing_; }
  int glued() const { return glued_; }  // grains glued to the plane at the end
  // rain with rest_speed > 0: whether the run ended with the deposit at rest, and when (s).
  bool rested() const { return rested_; }
  double rest_time() const { return rest_time_; }

 private:
  void find_layers(const Model& m, const State& s);  // rain: base and top at the start of the window
  bool at_rest_check(const Model& m, const State& s);  // rain: true once every free grain is slow for rest_hold s
  InclineSpec sp_;
  double base_, top_, d_, area_, g_, floor_;
  int glued_ = 0;                 // rain: grains glued to the plane
  bool window_started_ = false;   // rain: base and top found
  std::vector<double> win_t_, win_v_;  // rain: mean v_x every 0.01 s over the window
  double end_vx_ = 0, end_dvdt_ = 0;
  bool flowing_ = false;
  std::vector<double> rest_t_, rest_v_;  // rain: mean v_x every 0.01 s since every free grain became slow
  bool rested_ = false;
  double rest_time_ = 0;
  static constexpr double kTrendWindow = 0.25;  // onset: the hold-end trend is read over this fraction of the hold
  struct Hold {
    double theta_deg, v_end, dvdt_end;  // the tilt, mean v_x at the end of its hold, and its trend there
  };
  double theta_deg_ = 0, onset_deg_ = -1, hold_from_ = 0;
  bool marked_ = false;
  double mark_t_ = 0, mark_v_ = 0;
  std::vector<Hold> holds_;
  std::vector<double> sum_vx_, sum_vol_;
  std::vector<long> count_;
  long samples_ = 0;
  Profile prof_;
};

// What the scene does to its run (a fix, run/fix.hpp): gravity tilted by the
// measure's angle (from the start, and at each step of the onset protocol),
// and, raining, every free grain that touches the plane glued where it is.
class InclineFix : public Fix {
 public:
  InclineFix(const InclineSpec& sp, const InclineObserver& measure, double g, double floor_z)
      : sp_(sp), measure_(measure), g_(g), floor_(floor_z) {}
  void prepare(Model& m, State& s) override;
  void after_step(const Stage& st, Model& m, State& s) override;
  void after_measures(Model& m, State& s) override;

 private:
  void tilt(Model& m, State& s, double deg);
  InclineSpec sp_;
  const InclineObserver& measure_;
  double g_, floor_;
  double applied_deg_ = 0;
};

class InclineScene : public Scene {
 public:
  std::string kind() const override { return "incline"; }
  double bed_top() const override { return top; }
  std::unique_ptr<SceneRun> begin(Run& run) const override;

  std::string file;
  InclineSpec spec;
  double base_top = 0, top = 0, diameter = 0, area = 0, packing = 0;
  double floor_z = 0;  // rain: the plane the grains are glued to
  int grains = 0, base_grains = 0;
  std::string bed_cache;
};

class InclineRun : public SceneRun {
 public:
  InclineRun(const InclineScene& scene, const Model& m);
  std::vector<Observer*> observers() override { return {&obs_}; }
  std::vector<Fix*> fixes() override { return {&fix_}; }
  void write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                     int threads) const override;
  void write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const override;
  std::vector<std::pair<std::string, std::string>> files() const override;
  std::string result_line(const Model& m, const State& s, const RunReport& rep) const override;
  const InclineObserver& observer() const { return obs_; }

 private:
  const InclineScene& scene_;
  InclineObserver obs_;
  InclineFix fix_;
};

std::shared_ptr<const SceneKind> incline_kind();

}  // namespace rt
