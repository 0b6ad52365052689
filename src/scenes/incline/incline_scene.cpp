// The inclined-plane scene kind (see incline_scene.hpp; docs/scenes.md C.2).
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/scenes/incline/incline_scene.hpp"
#include "regolith_twin/core/types.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <sstream>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {


class InclineKind : public SceneKind {
 public:
  std::string name() const override { return "incline"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override;
};

InclineSpec parse_incline(const YAML::Node& n, const std::string& src) {
  InclineSpec sp;
  const YamlReader rd(src);
  const std::string p = "incline";
  if (!n || !n.IsMap()) rd.fail(p, "missing or not a mapping");
  rd.only(n, p, {"mode", "angle_deg", "start_deg", "step_deg", "max_deg", "hold", "flow_speed", "duration", "average",
                 "layer", "sample_every", "rest_speed", "rest_hold"});
  const std::string mode = rd.text(n, p, "mode", "steady");
  if (mode != "steady" && mode != "onset" && mode != "rain")
    rd.fail(p + ".mode", "expected steady, onset or rain, got '" + mode + "'");
  sp.onset = mode == "onset";
  sp.rain = mode == "rain";
  sp.angle_deg = rd.number(n, p, "angle_deg", sp.angle_deg, 0, 89);
  sp.start_deg = rd.number(n, p, "start_deg", sp.start_deg, 0, 89);
  sp.step_deg = rd.number(n, p, "step_deg", sp.step_deg, 0.01, 10);
  sp.max_deg = rd.number(n, p, "max_deg", sp.max_deg, sp.start_deg, 89);
  sp.hold = rd.number(n, p, "hold", sp.hold, 1e-3, 1e3);  // s: a step must last some steps
  sp.flow_speed = rd.number(n, p, "flow_speed", sp.flow_speed, 0, 10, true);
  sp.duration = rd.number(n, p, "duration", sp.duration, 1e-3, 1e4);
  sp.average = rd.number(n, p, "average", sp.average, 0, 1e4, true);
  if (sp.average > sp.duration)
    rd.fail(p + ".average", "the averaging window is longer than the run (" + p + ".duration): shorten it or lengthen the run");
  sp.layer = rd.number(n, p, "layer", sp.layer, 1e-4, 1);  // m: profiles of at most ~1e4 layers
  sp.sample_every = rd.number(n, p, "sample_every", sp.sample_every, 1e-6, 1e3);
  sp.rest_speed = rd.number(n, p, "rest_speed", sp.rest_speed, 0, 10);
  sp.rest_hold = rd.number(n, p, "rest_hold", sp.rest_hold, 0, sp.duration, true);
  if (sp.rest_speed > 0 && mode != "rain") rd.fail(p + ".rest_speed", "applies to mode rain only");
  return sp;
}

}  // namespace

double bagnold_amplitude(const std::vector<double>& z, const std::vector<double>& v, double h, double* rms) {
  double sff = 0, sfv = 0;
  for (size_t k = 0; k < z.size(); ++k) {
    if (!(z[k] < h) || !(z[k] > 0)) continue;
    const double f = 1 - std::pow(1 - z[k] / h, 1.5);
    sff += f * f;
    sfv += f * v[k];
  }
  const double a = sff > 0 ? sfv / sff : 0;
  if (rms) {
    double r2 = 0;
    int n = 0;
    for (size_t k = 0; k < z.size(); ++k) {
      if (!(z[k] < h) || !(z[k] > 0)) continue;
      const double r = v[k] - a * (1 - std::pow(1 - z[k] / h, 1.5));
      r2 += r * r;
      ++n;
    }
    *rms = n ? std::sqrt(r2 / n) : 0;
  }
  return a;
}

double bagnold_inertial_number(double a, double d, double h, double phi, double g, double theta) {
  return 3 * d * a / (2 * std::pow(h, 1.5) * std::sqrt(phi * g * std::cos(theta)));
}

double trend(const std::vector<double>& t, const std::vector<double>& v) {
  const size_t n = t.size();
  if (n < 2) return 0;
  double mt = 0, mv = 0;
  for (size_t k = 0; k < n; ++k) {
    mt += t[k];
    mv += v[k];
  }
  mt /= n;
  mv /= n;
  double stt = 0, stv = 0;
  for (size_t k = 0; k < n; ++k) {
    stt += (t[k] - mt) * (t[k] - mt);
    stv += (t[k] - mt) * (v[k] - mv);
  }
  return stt > 0 ? stv / stt : 0;
}

bool onset_flowing(double v_end, double dvdt_end, double hold, double threshold) {
  return v_end > threshold && v_end + dvdt_end * hold > threshold;
}

// --- the fix ------------------------------------------------------------------------

void InclineFix::tilt(Model& m, State& s, double deg) {
  applied_deg_ = deg;
  const double t = deg * kPi / 180;
  m.gravity = Vec3(g_ * std::sin(t), 0, -g_ * std::cos(t));
  s.forces_valid = false;
}

void InclineFix::prepare(Model& m, State& s) { tilt(m, s, sp_.onset ? sp_.start_deg : sp_.angle_deg); }

void InclineFix::after_step(const Stage&, Model& m, State& s) {
  if (!sp_.rain) return;
  // Every free grain that touches the plane is glued where it is (docs/scenes.md C.2).
  bool glued = false;
  for (int i = 0; i < m.n_grains; ++i)
    if (!held(m, i) && s.pos[i].z() - m.grain_radius[i] < floor_) {
      hold_grain(m, s, i, kHoldGlued);
      glued = true;
    }
  if (glued) s.rebuild_requested = true;  // pair constants (m*) and partitions follow
}

void InclineFix::after_measures(Model& m, State& s) {
  if (measure_.theta_deg() != applied_deg_) tilt(m, s, measure_.theta_deg());  // the onset protocol's next step
}

// --- the measure --------------------------------------------------------------------

void InclineObserver::start(const Model& m, const State& s) {
  theta_deg_ = sp_.onset ? sp_.start_deg : sp_.angle_deg;
  hold_from_ = s.time;
  const int layers = std::max(1, int(std::ceil((top_ - base_) / sp_.layer)) + 2);
  sum_vx_.assign(layers, 0);
  sum_vol_.assign(layers, 0);
  count_.assign(layers, 0);
}

double InclineObserver::mean_vx(const Model& m, const State& s) const {
  double v = 0;
  long n = 0;
  for (int i = 0; i < m.n_grains; ++i)
    if (!held(m, i)) {
      v += s.vel[i].x();
      ++n;
    }
  return n ? v / n : 0;
}

bool InclineObserver::after_step(const Model& m, const State& s) {
  if (sp_.onset) {
    const double held = s.time - hold_from_;
    if (!marked_ && held >= (1 - kTrendWindow) * sp_.hold - 0.5 * m.dt) {
      marked_ = true;  // the start of the window the hold-end trend is read over
      mark_t_ = s.time;
      mark_v_ = mean_vx(m, s);
    }
    if (held < sp_.hold - 0.5 * m.dt) return false;
    const double v = mean_vx(m, s);
    const double dvdt = s.time > mark_t_ ? (v - mark_v_) / (s.time - mark_t_) : 0;
    holds_.push_back({theta_deg_, v, dvdt});
    if (onset_flowing(v, dvdt, sp_.hold, sp_.flow_speed * std::sqrt(g_ * d_))) {
      onset_deg_ = theta_deg_;
      return true;  // flowing at the end of its hold, and not dying out: the onset angle
    }
    if (theta_deg_ + sp_.step_deg > sp_.max_deg + 1e-9) return true;
    theta_deg_ += sp_.step_deg;  // the next hold, one step steeper (InclineFix tilts gravity)
    hold_from_ = s.time;
    marked_ = false;
    return false;
  }
  const long every = std::max(1L, std::lround(0.01 / m.dt));
  if (sp_.rain && sp_.rest_speed > 0 && s.step % every == 0 && at_rest_check(m, s)) return true;
  // Steady and rain: sample the layers every sample interval over the last `average` s.
  const double t_end = sp_.duration;
  if (s.time < t_end - sp_.average) return false;
  if (s.step % every != 0) return false;
  if (sp_.rain) {
    if (!window_started_) find_layers(m, s);
    win_t_.push_back(s.time);
    win_v_.push_back(mean_vx(m, s));
  }
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    const int k = int(std::floor((s.pos[i].z() - base_) / sp_.layer));
    if (k < 0 || k >= int(sum_vx_.size())) continue;
    const double r = m.grain_radius[i];
    sum_vx_[k] += s.vel[i].x();
    sum_vol_[k] += 4.0 / 3.0 * kPi * r * r * r;
    ++count_[k];
  }
  ++samples_;
  return false;
}

bool InclineObserver::at_rest_check(const Model& m, const State& s) {
  const double limit = sp_.rest_speed * std::sqrt(g_ * d_);
  double v2 = 0;
  for (int i = 0; i < m.n_grains; ++i)
    if (!held(m, i)) v2 = std::max(v2, s.vel[i].squaredNorm());
  if (!(v2 < limit * limit)) {
    rest_t_.clear();
    rest_v_.clear();
    return false;
  }
  rest_t_.push_back(s.time);
  rest_v_.push_back(mean_vx(m, s));
  if (s.time - rest_t_.front() < sp_.rest_hold - 0.5 * m.dt) return false;
  rested_ = true;
  rest_time_ = s.time;
  return true;
}

void InclineObserver::find_layers(const Model& m, const State& s) {
  // The base: the glued grains' highest top; the bed's top: the mean top of its highest A/d^2 free grains.
  window_started_ = true;
  double base = floor_;
  std::vector<double> tops;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) base = std::max(base, s.pos[i].z() + m.grain_radius[i]);
    else tops.push_back(s.pos[i].z() + m.grain_radius[i]);
  }
  std::sort(tops.begin(), tops.end(), std::greater<double>());
  const int layer = std::clamp(int(std::lround(area_ / (d_ * d_))), 1, std::max(1, int(tops.size())));
  double top = 0;
  for (int k = 0; k < layer && k < int(tops.size()); ++k) top += tops[k];
  base_ = base;
  top_ = tops.empty() ? base : top / std::min(layer, int(tops.size()));
  const int layers = std::max(1, int(std::ceil((top_ - base_) / sp_.layer)) + 2);
  sum_vx_.assign(layers, 0);
  sum_vol_.assign(layers, 0);
  count_.assign(layers, 0);
}

void InclineObserver::finish(const Model& m, const State& s) {
  if (sp_.rain) {  // the rain scene starts without glued grains (InclineFix glues them)
    glued_ = 0;
    for (int i = 0; i < m.n_grains; ++i) glued_ += held(m, i);
  }
  if (sp_.rain && rested_) {
    // Every free grain at rest for rest_hold s: not flowing; the end state is read over that hold.
    end_vx_ = rest_v_.back();
    end_dvdt_ = trend(rest_t_, rest_v_);
    flowing_ = false;
  } else if (sp_.rain && !win_t_.empty()) {
    end_vx_ = win_v_.back();
    end_dvdt_ = trend(win_t_, win_v_);
    flowing_ = onset_flowing(end_vx_, end_dvdt_, sp_.average, sp_.flow_speed * std::sqrt(g_ * d_));
  }
  if (sp_.onset || samples_ == 0) return;
  Profile& p = prof_;
  p.height = top_ - base_;
  double phi_sum = 0;
  int phi_n = 0;
  for (size_t k = 0; k < sum_vx_.size(); ++k) {
    const double zc = (k + 0.5) * sp_.layer;
    p.z.push_back(zc);
    p.vx.push_back(count_[k] ? sum_vx_[k] / count_[k] : 0);
    p.packing.push_back(sum_vol_[k] / (samples_ * area_ * sp_.layer));
    if (zc + 0.5 * sp_.layer <= p.height - sp_.layer) {
      phi_sum += p.packing.back();
      ++phi_n;
    }
  }
  p.packing_mean = phi_n ? phi_sum / phi_n : 0;
  p.bagnold_a = bagnold_amplitude(p.z, p.vx, p.height, &p.fit_rms);
  p.inertial_number = p.packing_mean > 0 ? bagnold_inertial_number(p.bagnold_a, d_, p.height, p.packing_mean, g_,
                                                                    theta_deg_ * kPi / 180)
                                         : std::numeric_limits<double>::quiet_NaN();  // undefined: null in the summary
}

void InclineObserver::columns(std::vector<std::string>& out) const {
  out.push_back("theta_deg");
  out.push_back("mean_vx");
}

void InclineObserver::row(const Model& m, const State& s, std::vector<double>& out) const {
  out.push_back(theta_deg_);
  out.push_back(mean_vx(m, s));
}

void InclineObserver::summary(JsonObject& out) const {
  JsonObject o;
  o.str("mode", sp_.onset ? "onset" : sp_.rain ? "rain" : "steady").num("theta_deg", theta_deg_);
  if (sp_.rain) {
    o.num("glued_grains", glued_).num("end_mean_vx", end_vx_).num("end_dvdt", end_dvdt_);
    o.boolean("flowing", flowing_).num("base_top", base_).num("bed_top", top_);
    if (sp_.rest_speed > 0) o.boolean("stopped_at_rest", rested_).num("rest_time", rested_ ? rest_time_ : -1);
  }
  if (sp_.onset) {
    o.num("onset_deg", onset_deg_);
    std::vector<double> th, v, a;
    for (const auto& h : holds_) {
      th.push_back(h.theta_deg);
      v.push_back(h.v_end);
      a.push_back(h.dvdt_end);
    }
    o.nums("hold_angles_deg", th).nums("hold_end_mean_vx", v).nums("hold_end_dvdt", a);
  } else {
    o.num("flow_height", prof_.height).num("packing_mean", prof_.packing_mean);
    o.num("bagnold_a", prof_.bagnold_a).num("bagnold_fit_rms", prof_.fit_rms);
    o.num("inertial_number", prof_.inertial_number).num("mu", std::tan(theta_deg_ * kPi / 180));
    o.num("samples", double(samples_));
  }
  out.obj("incline", o);
}

std::string InclineObserver::progress(const Model& m, const State& s) const {
  char b[120];
  std::snprintf(b, sizeof b, "theta %.1f deg, mean v_x %.3g m/s", theta_deg_, mean_vx(m, s));
  return b;
}

void InclineObserver::write_csv(const std::string& dir) const {
  if (sp_.onset) return;
  std::ostringstream f;
  f << "# layer centre above the base (m), mean v_x (m/s), solid fraction; Bagnold fit v = A (1 - (1 - z/h)^1.5)\n";
  f << "z,vx,packing,bagnold\n";
  f.precision(9);
  const Profile& p = prof_;
  for (size_t k = 0; k < p.z.size(); ++k) {
    const double fit = p.z[k] < p.height ? p.bagnold_a * (1 - std::pow(1 - p.z[k] / p.height, 1.5)) : 0;
    f << p.z[k] << ',' << p.vx[k] << ',' << p.packing[k] << ',' << fit << '\n';
  }
  write_file(dir + "/profile.csv", f.str());
}

// --- one run ------------------------------------------------------------------------

InclineRun::InclineRun(const InclineScene& sc, const Model& m)
    : SceneRun("incline"),
      scene_(sc),
      obs_(sc.spec, sc.base_top, sc.top, sc.diameter, sc.area, m.gravity.norm(), sc.floor_z),
      fix_(sc.spec, obs_, m.gravity.norm(), sc.floor_z) {}

std::unique_ptr<SceneRun> InclineScene::begin(Run& run) const { return std::make_unique<InclineRun>(*this, run.model()); }

void InclineRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                               int threads) const {
  const InclineScene& sc = scene_;
  JsonObject j = summary_head(sc.sc.name, sc.file, rep);
  JsonObject bed;
  bed.num("grains", sc.grains).num("base_grains", sc.base_grains).num("diameter", sc.diameter);
  bed.num("base_top", sc.base_top).num("top", sc.top).num("depth_d", (sc.top - sc.base_top) / sc.diameter);
  bed.num("packing", sc.packing).str("cache", sc.bed_cache);
  j.obj("bed", bed);
  add_run_and_observers(j, m, rep, threads);
  j.write(path);
}

void InclineRun::write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {
  obs_.write_csv(dir);
}

std::vector<std::pair<std::string, std::string>> InclineRun::files() const {
  if (scene_.spec.onset) return {{"summary", "summary.json"}, {"time series", "series.csv"}};
  return {{"summary", "summary.json"}, {"time series", "series.csv"}, {"profiles", "profile.csv"}};
}

std::string InclineRun::result_line(const Model& m, const State& s, const RunReport& rep) const {
  char b[300];
  const InclineObserver& o = obs_;
  if (scene_.spec.onset)
    std::snprintf(b, sizeof b, "incline %s: onset of flow at %.1f deg (%.0f s wall)", scene_.sc.name.c_str(),
                  o.onset_deg(), rep.wall_seconds);
  else if (scene_.spec.rain)
    std::snprintf(b, sizeof b,
                  "incline %s: rained at %.1f deg: %s (mean v_x %.4g m/s, trend %.3g m/s^2; %d grains glued), "
                  "Bagnold A = %.4g m/s, I = %.4g (%.0f s wall)",
                  scene_.sc.name.c_str(), o.theta_deg(),
                  o.flowing() ? "flowing" : o.rested() ? "at rest (every grain slow; run ended)" : "at rest or stopping",
                  o.end_vx(), o.end_dvdt(), o.glued(), o.profile().bagnold_a, o.profile().inertial_number,
                  rep.wall_seconds);
  else
    std::snprintf(b, sizeof b,
                  "incline %s: %.1f deg, Bagnold A = %.4g m/s over h = %.4g m, Phi = %.3f, I = %.4g (%.0f s wall)",
                  scene_.sc.name.c_str(), o.theta_deg(), o.profile().bagnold_a, o.profile().height,
                  o.profile().packing_mean, o.profile().inertial_number, rep.wall_seconds);
  return b;
}

std::unique_ptr<Scene> InclineKind::prepare(const YAML::Node& doc, const std::string& file,
                                            const SceneOptions& opt) const {
  auto is = std::make_unique<InclineScene>();
  is->file = file;
  YAML::Node root = YAML::Clone(doc);
  is->spec = parse_incline(root["incline"], file);
  root.remove("incline");
  const YamlReader rd(file);
  is->sc = parse_scenario(root, file);
  Scenario& sc = is->sc;
  Model& m = sc.model;
  for (const auto& w : sc.warnings) std::fprintf(stderr, "[incline] warning: %s\n", w.c_str());
  if (!m.periodic.x || !m.periodic.y) rd.fail("periodic", "the incline scene needs a box periodic in x and y");
  if (m.n_grains == 0) rd.fail("grains", "the incline scene needs a bed");
  if (is->spec.rain) {
    // The published protocol: the generated grains rain onto the plane already tilted; no relaxation.
    bool floor = false;
    for (const Wall& w : m.walls)
      if (w.type == WallType::Plane && w.axis.z() > 1 - 1e-9) {
        is->floor_z = w.origin.z();
        floor = true;
      }
    if (!floor) rd.fail("walls", "mode rain needs a plane floor (normal +z) to glue the first grains to");
    for (int i = 0; i < m.n_grains; ++i)
      if (held(m, i)) rd.fail("grains", "mode rain forms its own base: no glued ('fixed') grains");
    State s = sc.initial;
    double d = 0;
    for (int i = 0; i < m.n_grains; ++i) d += 2 * m.grain_radius[i];
    is->grains = m.n_grains;
    is->diameter = d / m.n_grains;
    is->area = m.periodic.length.x() * m.periodic.length.y();
    is->base_top = is->top = is->floor_z;
    restart_at_zero(s);
    if (!opt.quiet)
      std::fprintf(stderr, "[incline] %d grains rained onto the plane tilted at %.1f deg\n", is->grains,
                   is->spec.angle_deg);
    is->start = std::move(s);
    is->plan = RunPlan::open_ended(sc.name, "rain");
    is->plan.stages[0].duration = is->spec.duration;
    is->sample_every = is->spec.sample_every;
    return is;
  }
  RelaxedBed bed = relax_bed(sc, sc.initial, {}, opt, "incline");
  State s = std::move(bed.state);
  is->bed_cache = bed.cache;
  is->area = m.periodic.length.x() * m.periodic.length.y();
  // The base: the glued grains' highest top; the bed: its free grains.
  double d = 0, vol = 0, base = 0;
  std::vector<double> tops;
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    if (held(m, i)) {
      base = std::max(base, s.pos[i].z() + r);
      ++is->base_grains;
      continue;
    }
    d += 2 * r;
    vol += 4.0 / 3.0 * kPi * r * r * r;
    tops.push_back(s.pos[i].z() + r);
    ++is->grains;
  }
  if (is->grains == 0) rd.fail("grains", "the incline scene needs free grains above its glued base");
  d /= is->grains;
  std::sort(tops.begin(), tops.end(), std::greater<double>());
  const int layer = std::clamp(int(std::lround(is->area / (d * d))), 1, is->grains);
  double top = 0;
  for (int k = 0; k < layer; ++k) top += tops[k];
  top /= layer;
  is->diameter = d;
  is->base_top = base;
  is->top = top;
  is->packing = top > base ? vol / (is->area * (top - base)) : 0;
  restart_at_zero(s);
  if (!opt.quiet)
    std::fprintf(stderr, "[incline] %d grains on %d glued, depth %.1f d, packing %.3f; %s\n", is->grains,
                 is->base_grains, (top - base) / d, is->packing,
                 is->spec.onset ? "onset of flow" : "steady flow");
  is->start = std::move(s);
  is->plan = RunPlan::open_ended(sc.name, is->spec.onset ? "onset" : "flow");
  is->plan.stages[0].duration =
      is->spec.onset ? (is->spec.max_deg - is->spec.start_deg) / is->spec.step_deg * is->spec.hold + 2 * is->spec.hold
                     : is->spec.duration;
  is->sample_every = is->spec.sample_every;
  return is;
}

std::shared_ptr<const SceneKind> incline_kind() { return std::make_shared<InclineKind>(); }

}  // namespace rt
