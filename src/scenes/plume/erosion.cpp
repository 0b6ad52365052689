// Plume erosion measurement (see erosion.hpp; docs/scenes.md D).
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/scenes/plume/erosion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/model.hpp"
#include "regolith_twin/run/series.hpp"

namespace rt {

void ErosionFix::prepare(Model& m, State& s) {
  const int need = std::max(p_.anchor_slot, p_.erosion_slot) + 1;
  if (int(s.field_values.size()) < need) s.field_values.resize(need, 0.0);
  s.field_values[p_.anchor_slot] = p_.anchor;
  s.field_values[p_.erosion_slot] = p_.erosion;
  n_grains_ = m.n_grains;
  if (p_.hold_below_anchor) {
    hold(m, s, true);
  }
}

// Collisionless study: hold the grains below the anchoring plane, free those above it.
void ErosionFix::hold(Model& m, State& s, bool first) {
  const double a = s.field_values[p_.anchor_slot];
  bool changed = false;
  for (int i = 0; i < m.n_grains; ++i) {
    if (m.grain_hold[i] & kHoldGlued) continue;  // glued by the scene: stays glued
    const bool below = s.pos[i].z() <= a, anchored = m.grain_hold[i] & kHoldAnchored;
    if (below && !anchored) {
      hold_grain(m, s, i, kHoldAnchored);
      changed = true;
    } else if (!below && anchored) {
      release_grain(m, i, kHoldAnchored);
      changed = true;
    }
  }
  if (changed) {
    s.rebuild_requested = true;
    if (first) s.forces_valid = false;
  }
}

void ErosionFix::start(Model& m, State& s) {
  const double e = s.field_values[p_.erosion_slot];
  is_above_.assign(m.n_grains, 0);
  above_now_ = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    is_above_[i] = s.pos[i].z() > e;
    above_now_ += is_above_[i];
  }
  const int w = std::max(1, p_.window);
  ring_up_.assign(w, 0);
  ring_down_.assign(w, 0);
  ring_pairs_.assign(w, 0);
  ring_touch_.assign(w, 0);
  ring_n_.assign(w, 0);
  touched_.assign(m.n_grains, 0);
  t0_ = s.time;
  fit_sx_ = fit_sy_ = fit_sxx_ = fit_sxy_ = 0;
  fit_n_ = 0;
  add_fit_point(s.time, above_now_);
  ErosionRow r;
  r.t = s.time;
  r.step = s.step;
  r.above = above_now_;
  r.anchor = s.field_values[p_.anchor_slot];
  r.erosion = e;
  rows_.assign(1, r);
  last_ = r;
}

void ErosionFix::add_fit_point(double t, int n) {
  const double x = t - t0_, y = n;
  fit_sx_ += x;
  fit_sy_ += y;
  fit_sxx_ += x * x;
  fit_sxy_ += x * y;
  ++fit_n_;
}

void ErosionFix::count(const Model& m, const State& s, int& pairs, int& touching) const {
  pairs = 0;
  touching = 0;
  if (above_now_ == 0 || !m.mobile_contacts || s.pairs.row_start.size() != size_t(m.n_grains) + 1) return;
  std::vector<uint8_t>& touched = touched_;
  const PairList& pl = s.pairs;
  for (int i = 0; i < m.n_grains; ++i) {
    if (!is_above_[i]) continue;
    for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k) {
      const int j = pl.partner[k];
      if (!pl.touching[k] || !is_above_[j]) continue;
      ++pairs;
      touched[i] = touched[j] = 1;
    }
  }
  for (int i = 0; i < m.n_grains; ++i) {
    touching += touched[i];
    touched[i] = 0;
  }
}

void ErosionFix::after_measures(Model& m, State& s) {
  double& anchor = s.field_values[p_.anchor_slot];
  double& erosion = s.field_values[p_.erosion_slot];
  int up = 0, down = 0;
  above_now_ = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    const uint8_t a = s.pos[i].z() > erosion;
    up += a && !is_above_[i];
    down += !a && is_above_[i];
    is_above_[i] = a;
    above_now_ += a;
  }
  int pairs = 0, touching = 0;
  count(m, s, pairs, touching);
  total_up_ += up;
  total_down_ += down;
  if (down > 0 && t_first_down_ < 0) t_first_down_ = s.time;
  if (above_now_ >= p_.depleted_fraction * n_grains_ && t_depleted_ < 0) t_depleted_ = s.time;
  if (above_now_ == n_grains_ && t_all_ < 0) t_all_ = s.time;
  // Both planes follow the surface (erosion.hpp).
  const int lost = p_.motion == PlaneMotion::Net ? up - down : p_.motion == PlaneMotion::Upward ? up : 0;
  if (lost != 0) {
    const double dz = lost * p_.grain_volume / (p_.bed_fraction * p_.area);
    anchor -= dz;
    erosion -= dz;
  }
  if (p_.hold_below_anchor) hold(m, s, false);
  // Moving sums over the last `window` steps.
  const size_t k = size_t(ring_pos_ % long(ring_up_.size()));
  sum_up_ += up - ring_up_[k];
  sum_down_ += down - ring_down_[k];
  sum_pairs_ += pairs - ring_pairs_[k];
  sum_touch_ += touching - ring_touch_[k];
  sum_n_ += above_now_ - ring_n_[k];
  ring_up_[k] = up;
  ring_down_[k] = down;
  ring_pairs_[k] = pairs;
  ring_touch_[k] = touching;
  ring_n_[k] = above_now_;
  ++ring_pos_;
  ++steps_;
  if (t_depleted_ < 0 || s.time <= t_depleted_) add_fit_point(s.time, above_now_);  // up to depletion
  const long w = std::min<long>(ring_pos_, long(ring_up_.size()));
  ErosionRow r;
  r.t = s.time;
  r.step = s.step;
  r.above = above_now_;
  r.anchor = anchor;
  r.erosion = erosion;
  r.up = double(sum_up_) / w;
  r.down = double(sum_down_) / w;
  r.pairs_per_grain = sum_n_ > 0 ? double(sum_pairs_) / sum_n_ : 0;
  r.touching_fraction = sum_n_ > 0 ? double(sum_touch_) / sum_n_ : 0;
  max_pairs_per_grain_ = std::max(max_pairs_per_grain_, r.pairs_per_grain);
  max_up_ = std::max(max_up_, r.up);
  last_ = r;
  if (steps_ % std::max(1, p_.sample_every) == 0) rows_.push_back(r);
}

void ErosionFix::columns(std::vector<std::string>& out) const {
  for (const char* c : {"above", "anchor_plane", "erosion_plane", "up_per_step", "down_per_step", "pairs_per_grain",
                        "touching_fraction"})
    out.push_back(c);
}

void ErosionFix::row(const Model& m, const State& s, std::vector<double>& out) const {
  const ErosionRow& r = last_;
  out.push_back(above_now_);
  out.push_back(s.field_values.size() > size_t(p_.anchor_slot) ? s.field_values[p_.anchor_slot] : p_.anchor);
  out.push_back(s.field_values.size() > size_t(p_.erosion_slot) ? s.field_values[p_.erosion_slot] : p_.erosion);
  out.push_back(r.up);
  out.push_back(r.down);
  out.push_back(r.pairs_per_grain);
  out.push_back(r.touching_fraction);
}

void ErosionFix::finish(Model& m, State& s) {
  if (!rows_.empty() && rows_.back().step != last_.step) rows_.push_back(last_);  // the last step's row
  // Erosion rate: one least-squares line through N(t) over the non-depleted phase.
  const double n = double(fit_n_), sx = fit_sx_, sy = fit_sy_, sxx = fit_sxx_, sxy = fit_sxy_;
  const double den = n * sxx - sx * sx;
  rate_ = n > 1 && den > 0 ? (n * sxy - sx * sy) / den : 0;
  rate_intercept_ = n > 0 ? (sy - rate_ * sx) / n : 0;
  if (p_.hold_below_anchor) {  // the model's masses back as they were
    for (int i = 0; i < m.n_grains; ++i) release_grain(m, i, kHoldAnchored);
    s.rebuild_requested = true;
    s.forces_valid = false;
  }
}

void ErosionFix::summary(JsonObject& out) const {
  JsonObject o;
  o.num("grains_above", above_now_).num("grains", n_grains_);
  o.num("depleted_at", t_depleted_).num("depleted_fraction", p_.depleted_fraction).num("all_above_at", t_all_);
  o.num("sedimentation_from", t_first_down_);
  o.num("erosion_rate", rate_).num("erosion_rate_per_area", rate_per_area()).num("fit_intercept", rate_intercept_);
  o.num("upward_crossings", total_up_).num("downward_crossings", total_down_);
  o.num("max_up_per_step", max_up_).num("max_pairs_per_grain", max_pairs_per_grain_);
  o.num("window_steps", p_.window);
  out.obj("erosion", o);
}

std::string ErosionFix::progress(const Model& m, const State& s) const {
  char b[120];
  std::snprintf(b, sizeof b, "%d of %d grains above the erosion plane", above_now_, n_grains_);
  return b;
}

void ErosionFix::write_csv(const std::string& path) const {
  std::ostringstream f;
  f << "# t (s), step, N above the erosion plane, anchoring and erosion planes (m), upward and downward crossings "
       "per step, contacts among the grains above per grain above, fraction of them in contact (moving averages "
       "over "
    << p_.window << " steps), phase (0 erosion only, 1 erosion and sedimentation, 2 depleted)\n";
  f << "t,step,above,anchor_plane,erosion_plane,up_per_step,down_per_step,pairs_per_grain,touching_fraction,phase\n";
  f.precision(9);
  for (const ErosionRow& r : rows_) {
    const int phase = t_depleted_ >= 0 && r.t >= t_depleted_ ? 2 : t_first_down_ >= 0 && r.t >= t_first_down_ ? 1 : 0;
    f << r.t << ',' << r.step << ',' << r.above << ',' << r.anchor << ',' << r.erosion << ',' << r.up << ',' << r.down
      << ',' << r.pairs_per_grain << ',' << r.touching_fraction << ',' << phase << '\n';
  }
  write_file(path, f.str());
}

}  // namespace rt
