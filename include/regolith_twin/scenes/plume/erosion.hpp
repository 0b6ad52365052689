// Plume erosion (a fix, run/fix.hpp; docs/scenes.md D): two horizontal planes that
// follow the eroding bed, the grains above the upper one counted every step.
//
// The anchoring plane (below it the gas does not act: GasField reads its
// height from State::field_values[anchor_slot]) starts `penetration` below the
// bed top; the erosion plane starts `erosion_height` above it. After every
// step both planes move by -N_lost V_p / (phi_bed A) with N_lost the net
// (upward minus downward), the upward, or no crossings of the erosion plane
// (PlaneMotion), so that they keep their depths relative to the eroding
// surface. Recorded each step: N (grains above the erosion plane), upward and
// downward crossings, grain–grain contacts among the grains above it and the
// grains among them that touch another; from these the moving averages over
// `window` steps, the erosion rate (slope of one least-squares line through
// N(t) up to depletion), and the phases (erosion only, erosion and
// sedimentation, depleted: N at least depleted_fraction of the grains; the
// time every grain is above is reported too).
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/run/fix.hpp"

namespace rt {

enum class PlaneMotion { Net, Upward, Fixed };

struct ErosionPlanes {
  double anchor = 0;           // anchoring plane's start height, m
  double erosion = 0;          // erosion plane's start height, m
  double grain_volume = 0;     // V_p, m^3
  double bed_fraction = 0.6;   // phi_bed
  double area = 0;             // box area A, m^2
  PlaneMotion motion = PlaneMotion::Net;
  int anchor_slot = 0, erosion_slot = 1;  // entries of State::field_values
  int window = 1000;           // steps of the moving averages
  // Depleted once N reaches this fraction of the grains (on a smooth floor
  // the last layer slides with the gas below the erosion plane: docs/scenes.md D).
  double depleted_fraction = 0.9;
  int sample_every = 1;        // steps between rows of erosion.csv
  // Collisionless study: grains below the anchoring plane are held at rest
  // (the bed the gas does not reach stays in place); a held grain is freed
  // when the plane passes below its centre, a free one held again where it
  // sinks below the plane (deposited).
  bool hold_below_anchor = false;
};

// One row of erosion.csv.
struct ErosionRow {
  double t = 0;
  long step = 0;
  int above = 0;               // N
  double anchor = 0, erosion = 0;  // plane heights, m
  double up = 0, down = 0;     // crossings per step, moving average
  double pairs_per_grain = 0;  // contacts among grains above / N, moving average
  double touching_fraction = 0;  // grains above in contact with another above / N, moving average
};

class ErosionFix : public Fix {
 public:
  explicit ErosionFix(const ErosionPlanes& p) : p_(p) {}
  void prepare(Model& m, State& s) override;
  void start(Model& m, State& s) override;
  void after_measures(Model& m, State& s) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void finish(Model& m, State& s) override;
  void summary(JsonObject& out) const override;
  std::string progress(const Model& m, const State& s) const override;

  // Results (after finish()).
  int above() const { return above_now_; }
  double depleted_at() const { return t_depleted_; }      // s, < 0 if never
  double all_above_at() const { return t_all_; }           // s every grain was first above, < 0 if never
  double sedimentation_from() const { return t_first_down_; }  // s of the first downward crossing, < 0 if none
  double rate() const { return rate_; }                   // grains/s, least-squares slope of N(t)
  double rate_per_area() const { return rate_ / p_.area; }  // grains/(s m^2)
  int total_up() const { return total_up_; }
  int total_down() const { return total_down_; }
  const std::vector<ErosionRow>& rows() const { return rows_; }
  void write_csv(const std::string& path) const;

 private:
  void count(const Model& m, const State& s, int& pairs, int& touching) const;
  void hold(Model& m, State& s, bool first);
  ErosionPlanes p_;
  std::vector<uint8_t> is_above_;
  mutable std::vector<uint8_t> touched_;  // count()'s scratch, sized once
  // Least-squares sums of N(t) up to depletion (t from the start).
  double t0_ = 0, fit_sx_ = 0, fit_sy_ = 0, fit_sxx_ = 0, fit_sxy_ = 0;
  long fit_n_ = 0;
  void add_fit_point(double t, int n);
  ErosionRow last_;                  // this step's row (series.csv reads it)
  // Ring buffers of the last `window` steps.
  std::vector<int> ring_up_, ring_down_, ring_pairs_, ring_touch_, ring_n_;
  long ring_pos_ = 0;
  long sum_up_ = 0, sum_down_ = 0, sum_pairs_ = 0, sum_touch_ = 0, sum_n_ = 0;
  int above_now_ = 0, total_up_ = 0, total_down_ = 0, n_grains_ = 0;
  long steps_ = 0;
  double t_depleted_ = -1, t_all_ = -1, t_first_down_ = -1, rate_ = 0, rate_intercept_ = 0;
  double max_pairs_per_grain_ = 0, max_up_ = 0;
  std::vector<ErosionRow> rows_;
};

}  // namespace rt
