// Measurements around the sampler projectile's impact (docs/scenes.md B.4).
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <limits>
#include <stdexcept>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/energy.hpp"

namespace rt {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const ImpactClock* need_clock(const ImpactClock* c, const char* who) {
  if (!c) throw std::invalid_argument(std::string(who) + ": needs an impact clock");
  return c;
}

// A time after impact t is reached at the first step whose time after impact
// is at least t, to rounding of the accumulated time (a millionth of a step).
bool reached(const Model& m, double after, double t) { return after >= t - 1e-6 * m.dt; }

// A CSV file's text, written whole with write_file at the end (docs/files.md, outputs).
std::ostringstream csv_text() {
  std::ostringstream f;
  f.precision(10);
  return f;
}

}  // namespace

double rms_speed(const Model& m, const State& s, int skip) {
  double sum = 0;
  long n = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (i == skip || held(m, i)) continue;
    sum += s.vel[i].squaredNorm();
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

// --- impact clock (docs/scenes.md B.4) ----------------------------------------------------

void ImpactClock::start(const Model& m, const State& s) {
  projectile_ = projectile0_;
  if (projectile_ < 0 || projectile_ >= m.n_grains)
    throw InputError("impact clock: projectile grain " + std::to_string(projectile_) + " is not in the scene");
  hit_ = false;
  t_impact_ = kNaN;
  impact_step_ = -1;
  entries_.clear();
  entries_rebuilds_ = -1;
  if (touching(m, s)) mark(s);
}

bool ImpactClock::after_step(const Model& m, const State& s) {
  if (!hit_ && projectile_ >= 0 && touching(m, s)) mark(s);
  return false;
}

void ImpactClock::mark(const State& s) {
  hit_ = true;
  t_impact_ = s.time;
  impact_step_ = s.step;
  impact_ticks_ = s.ticks;
  impact_pos_ = s.pos[projectile_];
  impact_vel_ = s.vel[projectile_];
}

bool ImpactClock::touching(const Model& m, const State& s) {
  if (!s.lists_valid) return false;
  const int p = projectile_;
  const PairList& pl = s.pairs;
  // The pair entries of the projectile: its own row (partners above it) and
  // the entries of lower rows naming it, found once per list build.
  if (entries_rebuilds_ != s.rebuilds || entries_size_ != pl.size()) {
    entries_.clear();
    for (int k = 0; k < pl.size(); ++k)
      if (pl.partner[k] == p) entries_.push_back(k);
    if (p + 1 < int(pl.row_start.size()))
      for (int k = pl.row_start[p]; k < pl.row_start[p + 1]; ++k) entries_.push_back(k);
    entries_rebuilds_ = s.rebuilds;
    entries_size_ = pl.size();
  }
  for (int k : entries_)
    if (pl.touching[k]) return true;
  // Wall and body lists are sorted by grain.
  const WallList& wl = s.wall_pairs;
  for (auto it = std::lower_bound(wl.grain.begin(), wl.grain.end(), p); it != wl.grain.end() && *it == p; ++it)
    if (wl.touching[it - wl.grain.begin()]) return true;
  const BodyGrainList& bl = s.body_grains;
  for (auto it = std::lower_bound(bl.grain.begin(), bl.grain.end(), p); it != bl.grain.end() && *it == p; ++it)
    if (bl.touching[it - bl.grain.begin()]) return true;
  return false;
}

void ImpactClock::grains_removed(const std::vector<int>& old_to_new) {
  if (projectile_ >= 0) projectile_ = projectile_ < int(old_to_new.size()) ? old_to_new[projectile_] : -1;
  entries_rebuilds_ = -1;  // the lists were renumbered
}

void ImpactClock::summary(JsonObject& out) const {
  out.boolean("impact", hit_);
  if (!hit_) return;
  out.num("t_impact", t_impact_).num("impact_step", double(impact_step_)).num("impact_speed", impact_vel_.norm());
  out.nums("impact_position", {impact_pos_.x(), impact_pos_.y(), impact_pos_.z()});
}

// --- ejection angles (docs/scenes.md B.4) ---------------------------------------------------

EjectionAngles::EjectionAngles(const ImpactClock* clock, double surface_height, const Vec3& axis,
                               double container_radius, double g, int every)
    : clock_(need_clock(clock, "ejection angles")),
      h_s_(surface_height),
      axis_(axis),
      R_(container_radius),
      g_(g),
      every_(every) {
  if (!(R_ > 0) || !(g_ > 0) || every_ < 1)
    throw std::invalid_argument("ejection angles: container radius and g must be > 0, every >= 1");
}

void EjectionAngles::start(const Model& m, const State& s) {
  done_.assign(m.n_grains, 0);
  for (int i = 0; i < m.n_grains; ++i) done_[i] = s.pos[i].z() > h_s_;  // never counted
  launches_.clear();
  volume_ = 0;
}

bool EjectionAngles::after_step(const Model& m, const State& s) {
  if (!clock_->hit() || !ticks_crossed(s, every_, clock_->impact_ticks())) return false;
  const int p = clock_->projectile();
  const double t = clock_->after(s);
  for (int i = 0; i < m.n_grains; ++i) {
    if (done_[i] || i == p || s.pos[i].z() <= h_s_) continue;
    done_[i] = 1;
    EjectaLaunch e;
    e.t = t;
    e.grain = i;
    e.pos = s.pos[i];
    e.vel = s.vel[i];
    e.r = std::hypot(e.pos.x() - axis_.x(), e.pos.y() - axis_.y());
    e.speed = e.vel.norm();
    e.angle_deg = std::atan2(e.vel.z(), std::hypot(e.vel.x(), e.vel.y())) * 180 / kPi;
    e.volume = 4.0 / 3.0 * kPi * std::pow(m.grain_radius[i], 3);
    volume_ += e.volume;
    launches_.push_back(e);
  }
  return false;
}

void EjectionAngles::grains_removed(const std::vector<int>& old_to_new) { renumber_grains(done_, old_to_new); }

void EjectionAngles::columns(std::vector<std::string>& out) const {
  out.push_back("ejected_grains");
  out.push_back("ejected_volume");
}

void EjectionAngles::row(const Model& m, const State& s, std::vector<double>& out) const {
  out.push_back(double(launches_.size()));
  out.push_back(volume_);
}

std::vector<long> EjectionAngles::histogram() const {
  std::vector<long> h(kBins, 0);
  for (const EjectaLaunch& e : launches_) {
    if (e.angle_deg < 0 || e.angle_deg > 90) continue;
    h[std::min(kBins - 1, int(e.angle_deg / kBinDeg))]++;
  }
  return h;
}

long EjectionAngles::outside() const {
  long n = 0;
  for (const EjectaLaunch& e : launches_) n += e.angle_deg < 0 || e.angle_deg > 90;
  return n;
}

double EjectionAngles::mean_angle_deg() const {
  if (launches_.empty()) return kNaN;
  double sum = 0;
  for (const EjectaLaunch& e : launches_) sum += e.angle_deg;
  return sum / double(launches_.size());
}

double EjectionAngles::median_angle_deg() const {
  if (launches_.empty()) return kNaN;
  std::vector<double> a;
  a.reserve(launches_.size());
  for (const EjectaLaunch& e : launches_) a.push_back(e.angle_deg);
  std::sort(a.begin(), a.end());
  const size_t n = a.size();
  return n % 2 ? a[n / 2] : 0.5 * (a[n / 2 - 1] + a[n / 2]);
}

void EjectionAngles::summary(JsonObject& out) const {
  std::vector<double> h;
  for (long c : histogram()) h.push_back(double(c));
  JsonObject o;
  o.num("count", double(launches_.size())).num("volume", volume_).num("surface_height", h_s_);
  o.num("mean_angle_deg", mean_angle_deg()).num("median_angle_deg", median_angle_deg());
  o.num("bin_deg", kBinDeg).nums("angle_histogram", h).num("outside_0_90", double(outside()));
  out.obj("ejection", o);
}

void EjectionAngles::write_csv(const std::string& path) const {
  std::ostringstream f = csv_text();
  const double v_ref = std::sqrt(g_ * R_);
  f << "t,x_launch,r_launch_over_R,speed,speed_over_sqrt_gR,angle\n";
  for (const EjectaLaunch& e : launches_)
    f << e.t << ',' << e.r << ',' << e.r / R_ << ',' << e.speed << ',' << e.speed / v_ref << ',' << e.angle_deg
      << '\n';
  write_file(path, f.str());
}

// --- energy partition (docs/scenes.md B.4) ---------------------------------------------------

EnergyParts energy_parts(const Model& m, const State& s, int projectile) {
  EnergyParts e;
  e.t = s.time;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    const double trans = 0.5 * m.grain_mass[i] * s.vel[i].squaredNorm();
    const double rot = 0.5 * (1.0 / m.grain_inv_inertia[i]) * s.omega[i].squaredNorm();
    if (i == projectile) {
      e.proj_trans += trans;
      e.proj_rot += rot;
    } else {
      e.bed_trans += trans;
      e.bed_rot += rot;
    }
  }
  for_each_elastic_contact(m, s, [&](const ElasticContact& c) {
    if (c.kind != ElasticContact::GrainGrain)
      e.grain_wall += c.energy;
    else if (c.i == projectile || c.j == projectile)
      e.proj_grain += c.energy;
    else
      e.bed_bed += c.energy;
  });
  return e;
}

EnergyPartition::EnergyPartition(const ImpactClock* clock, int every, double window)
    : clock_(need_clock(clock, "energy partition")), every_(every), window_(window) {
  if (every_ < 1 || !(window_ >= 0)) throw std::invalid_argument("energy partition: every >= 1 and window >= 0");
}

void EnergyPartition::start(const Model& m, const State& s) {
  const int p = clock_->projectile();
  if (p < 0 || p >= m.n_grains) throw InputError("energy partition: no projectile grain");
  e0_ = 0.5 * m.grain_mass[p] * s.vel[p].squaredNorm() +
        0.5 * (1.0 / m.grain_inv_inertia[p]) * s.omega[p].squaredNorm();
  if (!(e0_ > 0)) throw InputError("energy partition: the projectile has no kinetic energy at the start");
  complete_ = false;
  samples_.clear();
}

bool EnergyPartition::after_step(const Model& m, const State& s) {
  if (complete_ || !clock_->hit()) return false;
  const double t = clock_->after(s);
  const bool end = reached(m, t, window_);
  if (!end && !ticks_crossed(s, every_, clock_->impact_ticks())) return false;
  samples_.push_back(energy_parts(m, s, clock_->projectile()));
  samples_.back().t = t;
  complete_ = end;
  return false;
}

namespace {

void parts_values(const EnergyParts& e, double scale, std::vector<double>& v) {
  v = {e.bed_trans, e.bed_rot, e.proj_trans, e.proj_rot};
  for (const ElasticSplit* x : {&e.bed_bed, &e.proj_grain, &e.grain_wall})
    for (double y : {x->normal, x->tangential, x->rolling, x->twisting}) v.push_back(y);
  v.push_back(e.total());
  for (double& y : v) y *= scale;
}

const char* const kPartNames[] = {
    "ke_bed_trans",      "ke_bed_rot",           "ke_proj_trans",       "ke_proj_rot",
    "bed_bed_normal",    "bed_bed_tangential",   "bed_bed_rolling",     "bed_bed_twisting",
    "proj_grain_normal", "proj_grain_tangential", "proj_grain_rolling", "proj_grain_twisting",
    "wall_normal",       "wall_tangential",      "wall_rolling",        "wall_twisting",
    "total"};

}  // namespace

void EnergyPartition::summary(JsonObject& out) const {
  JsonObject o;
  o.num("initial_energy", e0_).num("window", window_).boolean("window_complete", complete_);
  if (!samples_.empty()) {
    const EnergyParts& e = samples_.back();
    std::vector<double> v;
    parts_values(e, 1.0 / e0_, v);
    o.num("t", e.t);
    for (size_t k = 0; k < v.size(); ++k) o.num(kPartNames[k], v[k]);
  }
  out.obj("energy_partition", o);
}

void EnergyPartition::write_csv(const std::string& path) const {
  std::ostringstream f = csv_text();
  f << 't';
  for (const char* n : kPartNames) f << ',' << n;
  f << '\n';
  std::vector<double> v;
  for (const EnergyParts& e : samples_) {
    parts_values(e, 1.0 / e0_, v);
    f << e.t;
    for (double y : v) f << ',' << y;
    f << '\n';
  }
  write_file(path, f.str());
}

// --- wave attenuation (docs/scenes.md B.4) -----------------------------------------------------

WaveAttenuation::WaveAttenuation(const ImpactClock* clock, const WaveOptions& opt)
    : clock_(need_clock(clock, "wave attenuation")), opt_(opt), rest_rms_(opt.rest_rms) {
  if (!(opt_.bin > 0) || !(opt_.half_angle_deg > 0 && opt_.half_angle_deg <= 90) || !(opt_.floor_factor > 0))
    throw std::invalid_argument("wave attenuation: bin > 0, half angle in (0, 90], floor factor > 0");
  std::sort(opt_.times.begin(), opt_.times.end());
}

void WaveAttenuation::start(const Model& m, const State& s) {
  rest_rms_ = opt_.rest_rms >= 0 ? opt_.rest_rms : rms_speed(m, s, clock_->projectile());
  profiles_.clear();
}

bool WaveAttenuation::after_step(const Model& m, const State& s) {
  if (!clock_->hit()) return false;
  const double t = clock_->after(s);
  while (profiles_.size() < opt_.times.size() && reached(m, t, opt_.times[profiles_.size()]))
    capture(m, s, opt_.times[profiles_.size()]);
  return false;
}

namespace {

// Least-squares line y = a + s x over points [i, j) of xs, ys; its squared residual.
struct Line {
  double slope = kNaN, intercept = kNaN, sse = kNaN;
};

Line fit_line(const std::vector<double>& xs, const std::vector<double>& ys, size_t i, size_t j) {
  Line l;
  if (j < i + 2) return l;
  const double n = double(j - i);
  double mx = 0, my = 0;
  for (size_t q = i; q < j; ++q) mx += xs[q], my += ys[q];
  mx /= n;
  my /= n;
  double cxx = 0, cxy = 0;
  for (size_t q = i; q < j; ++q) {
    cxx += (xs[q] - mx) * (xs[q] - mx);
    cxy += (xs[q] - mx) * (ys[q] - my);
  }
  l.slope = cxy / cxx;
  l.intercept = my - l.slope * mx;
  l.sse = 0;
  for (size_t q = i; q < j; ++q) {
    const double r = ys[q] - l.intercept - l.slope * xs[q];
    l.sse += r * r;
  }
  return l;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

void fit_wave_profile(WaveProfile& w, double bin) {
  constexpr size_t kMinRun = 3;  // bins in each piece of the front search
  w.signal_end = w.front_bin = w.last_bin = -1;
  w.front_found = false;
  w.front = w.break_ratio = w.precursor_median = w.precursor_max = w.slope = w.intercept = kNaN;
  w.used.clear();
  w.precursor.clear();
  std::vector<int> sig;           // bins above the floor from first_bin on
  std::vector<double> xs, ys;     // their ln d_mid, ln v_max
  for (int k = std::max(0, w.first_bin); k < int(w.max_speed.size()); ++k)
    if (w.max_speed[k] > w.floor && w.max_speed[k] > 0) {
      sig.push_back(k);
      xs.push_back(std::log((k + 0.5) * bin));
      ys.push_back(std::log(w.max_speed[k]));
    }
  if (sig.empty()) return;
  w.signal_end = sig.back();
  size_t cut = sig.size();  // bins [0, cut) of sig are the wave
  if (sig.size() >= 2 * kMinRun) {
    const Line one = fit_line(xs, ys, 0, sig.size());
    size_t best = 0;
    double best_sse = std::numeric_limits<double>::infinity();
    for (size_t j = kMinRun; j + kMinRun <= sig.size(); ++j) {
      const double e = fit_line(xs, ys, 0, j).sse + fit_line(xs, ys, j, sig.size()).sse;
      if (e < best_sse) best_sse = e, best = j;
    }
    // One line's residual at rounding level: a power law, nothing to cut.
    w.break_ratio = one.sse > 1e-20 * double(sig.size()) ? best_sse / one.sse : 1.0;
    const Line in = fit_line(xs, ys, 0, best);
    std::vector<double> outer;
    for (size_t q = best; q < sig.size(); ++q) outer.push_back(w.max_speed[sig[q]]);
    const double at_front = std::exp(in.intercept + in.slope * xs[best - 1]);
    if (w.break_ratio < 0.5 && median_of(outer) < at_front) {
      cut = best;
      w.front_found = true;
    }
  }
  w.front_bin = w.last_bin = sig[cut - 1];
  w.front = (w.front_bin + 1) * bin;
  w.used.assign(sig.begin(), sig.begin() + cut);
  w.precursor.assign(sig.begin() + cut, sig.end());
  if (!w.precursor.empty()) {
    std::vector<double> pv;
    for (int k : w.precursor) pv.push_back(w.max_speed[k]);
    w.precursor_median = median_of(pv);
    w.precursor_max = *std::max_element(pv.begin(), pv.end());
  }
  const Line fit = fit_line(xs, ys, 0, cut);
  w.slope = fit.slope;
  w.intercept = fit.intercept;
}

void WaveAttenuation::capture(const Model& m, const State& s, double t) {
  WaveProfile w;
  w.t = t;
  w.t_actual = clock_->after(s);
  w.floor = opt_.floor_factor * rest_rms_;
  const int p = clock_->projectile();
  const double cos_half = std::cos(opt_.half_angle_deg * kPi / 180);
  for (int i = 0; i < m.n_grains; ++i) {
    if (i == p) continue;
    const Vec3 d = s.pos[i] - opt_.impact;
    const double dist = d.norm();
    if (-d.z() < cos_half * dist) continue;  // outside the downward cone
    const size_t k = size_t(dist / opt_.bin);
    if (k >= w.max_speed.size()) {
      w.max_speed.resize(k + 1, 0.0);
      w.grains.resize(k + 1, 0);
    }
    w.max_speed[k] = std::max(w.max_speed[k], s.vel[i].norm());
    w.grains[k]++;
  }
  w.contact = p >= 0 ? (s.pos[p] - opt_.impact).norm() + m.grain_radius[p] : 0.0;
  w.first_bin = int(w.contact / opt_.bin) + 1;
  fit_wave_profile(w, opt_.bin);
  profiles_.push_back(std::move(w));
}

void WaveAttenuation::summary(JsonObject& out) const {
  JsonObject o;
  o.num("rest_rms_speed", rest_rms_).num("bin", opt_.bin).num("half_angle_deg", opt_.half_angle_deg);
  for (size_t q = 0; q < profiles_.size(); ++q) {
    const WaveProfile& w = profiles_[q];
    JsonObject c;
    std::vector<double> dist, used, pre, grains;
    for (size_t k = 0; k < w.max_speed.size(); ++k) {
      dist.push_back((k + 0.5) * opt_.bin);
      grains.push_back(double(w.grains[k]));
    }
    for (int k : w.used) used.push_back(double(k));
    for (int k : w.precursor) pre.push_back(double(k));
    c.num("t", w.t).num("t_actual", w.t_actual).num("slope", w.slope).num("intercept", w.intercept);
    c.num("contact", w.contact).num("floor", w.floor);
    c.num("first_bin", w.first_bin).num("last_bin", w.last_bin);
    c.num("fit_from", w.first_bin * opt_.bin).num("fit_to", w.last_bin >= 0 ? (w.last_bin + 1) * opt_.bin : kNaN);
    c.num("front", w.front).num("front_bin", w.front_bin).str("front_method", w.front_found ? "break" : "signal_end");
    c.num("break_ratio", w.break_ratio).num("signal_end", w.signal_end);
    c.num("precursor_median", w.precursor_median).num("precursor_max", w.precursor_max);
    c.nums("bins_used", used).nums("precursor_bins", pre);
    c.nums("distance", dist).nums("max_speed", w.max_speed).nums("grains", grains);
    o.obj("t" + std::to_string(q), c);
  }
  out.obj("wave", o);
}

void WaveAttenuation::write_csv(const std::string& path) const {
  std::ostringstream f = csv_text();
  f << "t,bin,distance_from,distance_to,distance_mid,max_speed,grains,in_fit,precursor\n";
  for (const WaveProfile& w : profiles_)
    for (size_t k = 0; k < w.max_speed.size(); ++k) {
      const bool in = std::find(w.used.begin(), w.used.end(), int(k)) != w.used.end();
      const bool pre = std::find(w.precursor.begin(), w.precursor.end(), int(k)) != w.precursor.end();
      f << w.t_actual << ',' << k << ',' << k * opt_.bin << ',' << (k + 1) * opt_.bin << ',' << (k + 0.5) * opt_.bin
        << ',' << w.max_speed[k] << ',' << w.grains[k] << ',' << int(in) << ',' << int(pre) << '\n';
    }
  write_file(path, f.str());
}

// --- Z-model fits (docs/scenes.md B.2, B.4) -----------------------------------------------------

ZModelSampler::ZModelSampler(const ImpactClock* clock, const ZFitOptions& base, double rest_rms,
                             std::vector<double> times, double factor)
    : clock_(need_clock(clock, "Z-model sampler")),
      base_(base),
      rest_rms0_(rest_rms),
      rest_rms_(rest_rms),
      times_(std::move(times)),
      factor_(factor) {
  if (!(factor_ > 0)) throw std::invalid_argument("Z-model sampler: factor must be > 0");
  std::sort(times_.begin(), times_.end());
  zmodel_cells({}, {}, base_);  // refuses an invalid region now rather than at the first fit
}

void ZModelSampler::start(const Model& m, const State& s) {
  rest_rms_ = rest_rms0_ >= 0 ? rest_rms0_ : rms_speed(m, s, clock_->projectile());
  samples_.clear();
}

bool ZModelSampler::after_step(const Model& m, const State& s) {
  if (!clock_->hit()) return false;
  const double t = clock_->after(s);
  if (samples_.size() >= times_.size() || !reached(m, t, times_[samples_.size()])) return false;
  std::vector<Vec3> pos, vel;
  const int p = clock_->projectile();
  pos.reserve(m.n_grains);
  vel.reserve(m.n_grains);
  for (int i = 0; i < m.n_grains; ++i)
    if (i != p) {
      pos.push_back(s.pos[i]);
      vel.push_back(s.vel[i]);
    }
  while (samples_.size() < times_.size() && reached(m, t, times_[samples_.size()])) {
    ZSample z;
    z.t = times_[samples_.size()];
    z.t_actual = t;
    z.speed_min = factor_ * rest_rms_;
    ZFitOptions o = base_;
    o.speed_min = z.speed_min;
    o.surface_only = false;
    o.fit_h0 = false;
    z.fixed_h0 = fit_zmodel(pos, vel, o);
    o.fit_h0 = true;
    z.fitted_h0 = fit_zmodel(pos, vel, o);
    o.fit_h0 = false;
    o.surface_only = true;
    z.surface = fit_zmodel(pos, vel, o);
    samples_.push_back(z);
  }
  return false;
}

namespace {

JsonObject zfit_json(const ZFit& f) {
  JsonObject o;
  o.num("z", f.z).num("h0", f.h0).num("misfit_mean_deg", f.misfit_mean_deg).num("misfit_sd_deg", f.misfit_sd_deg);
  o.num("misfit_rms_deg", f.misfit_rms_deg).num("cells", f.cells).num("grains", f.grains);
  return o;
}

}  // namespace

void ZModelSampler::summary(JsonObject& out) const {
  JsonObject o;
  o.num("rest_rms_speed", rest_rms_).num("factor", factor_);
  for (size_t q = 0; q < samples_.size(); ++q) {
    const ZSample& z = samples_[q];
    JsonObject c;
    c.num("t", z.t).num("t_actual", z.t_actual).num("speed_min", z.speed_min);
    c.obj("fixed_h0", zfit_json(z.fixed_h0)).obj("fitted_h0", zfit_json(z.fitted_h0));
    c.obj("surface", zfit_json(z.surface));
    o.obj("t" + std::to_string(q), c);
  }
  out.obj("zmodel", o);
}

void ZModelSampler::write_csv(const std::string& path) const {
  std::ostringstream f = csv_text();
  f << "t,variant,z,h0,misfit_mean_deg,misfit_sd_deg,misfit_rms_deg,cells,grains,speed_min\n";
  for (const ZSample& z : samples_)
    for (const auto& [name, fit] : {std::pair<const char*, const ZFit*>{"fixed_h0", &z.fixed_h0},
                                    {"fitted_h0", &z.fitted_h0},
                                    {"surface", &z.surface}})
      f << z.t_actual << ',' << name << ',' << fit->z << ',' << fit->h0 << ',' << fit->misfit_mean_deg << ','
        << fit->misfit_sd_deg << ',' << fit->misfit_rms_deg << ',' << fit->cells << ',' << fit->grains << ','
        << z.speed_min << '\n';
  write_file(path, f.str());
}

}  // namespace rt
