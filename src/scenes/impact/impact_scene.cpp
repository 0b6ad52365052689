// The bucket-impact scene kind (see impact_scene.hpp; docs/scenes.md C.1).
#include "regolith_twin/scenes/impact/impact_scene.hpp"
#include "regolith_twin/core/types.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

class ImpactKind : public SceneKind {
 public:
  std::string name() const override { return "impact"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override;
};

ImpactSpec parse_impact(const YAML::Node& n, const std::string& src) {
  ImpactSpec sp;
  const YamlReader rd(src);
  const std::string p = "impact";
  if (!n || !n.IsMap()) rd.fail(p, "missing or not a mapping");
  rd.only(n, p, {"impactor", "speed", "aim", "gap", "duration", "rest_speed", "rest_time", "fit_every", "sample_every"});
  sp.impactor = rd.text(n, p, "impactor", sp.impactor);
  sp.speed = rd.number(n, p, "speed", sp.speed, 0, 100, true);
  if (n["aim"]) {
    const YAML::Node a = n["aim"];
    if (!a.IsSequence() || a.size() != 2) rd.fail(p + ".aim", "expected [x, y] in m");
    sp.aim = Vec3(rd.number(a[0], p + ".aim[0]", -kInf, kInf), rd.number(a[1], p + ".aim[1]", -kInf, kInf), 0);
  }
  sp.gap = rd.number(n, p, "gap", sp.gap, 0, 1);
  sp.duration = rd.number(n, p, "duration", sp.duration, 0, 1e4, true);
  sp.rest_speed = rd.number(n, p, "rest_speed", sp.rest_speed, 0, 10, true);
  sp.rest_time = rd.number(n, p, "rest_time", sp.rest_time, 0, 100);
  sp.fit_every = rd.number(n, p, "fit_every", sp.fit_every, 0, 1, true);
  sp.sample_every = rd.number(n, p, "sample_every", sp.sample_every, 0, 1e3, true);
  return sp;
}

}  // namespace

// --- the tracker ------------------------------------------------------------------

void ImpactTracker::start(const Model& m, const State& s) {
  mass_ = m.bodies[body_].mass;
  min_bottom_ = s.bodies[body_].pos.z() - radius_;
  rows_.push_back({s.time, min_bottom_ - surface_, s.bodies[body_].vel.z(), -g_});
}

bool ImpactTracker::after_step(const Model& m, const State& s) {
  const BodyState& b = s.bodies[body_];
  const double v = b.vel.z(), bottom = b.pos.z() - radius_;
  const double a = b.force.z() / mass_ - g_;  // contact force of the step, and gravity
  min_bottom_ = std::min(min_bottom_, bottom);
  rebound_ = std::max(rebound_, bottom - min_bottom_);  // a rise above the lowest point reached so far
  if (t_contact_ < 0 && b.force.squaredNorm() > 0) {
    t_contact_ = s.time;
    fit_t0_ = s.time;
    fit_v0_ = v;
  }
  if (t_contact_ >= 0) {
    if (t_1cm_ < 0 && std::abs(v) < 0.01) t_1cm_ = s.time;
    if (t_1mm_ < 0 && std::abs(v) < 0.001) t_1mm_ = s.time;
    max_up_ = std::max(max_up_, v);
    // Force-law samples while the sphere still moves down faster than 1 cm/s:
    // the mean acceleration over fit_every, at the mean speed.
    if (t_1cm_ < 0 && s.time - fit_t0_ >= spec_.fit_every - 1e-12) {
      fit_a_.push_back((v - fit_v0_) / (s.time - fit_t0_));
      fit_v_.push_back(0.5 * (v + fit_v0_));
      fit_t0_ = s.time;
      fit_v0_ = v;
    }
    if (b.vel.norm() < spec_.rest_speed) {
      if (t_rest_from_ < 0) t_rest_from_ = s.time;
    } else {
      t_rest_from_ = -1;
    }
  }
  if (s.time - rows_.back().t >= 1e-4 - 1e-12) rows_.push_back({s.time, bottom - surface_, v, a});
  return t_rest_from_ >= 0 && s.time - t_rest_from_ >= spec_.rest_time;  // at rest: the run ends
}

void ImpactTracker::finish(const Model& m, const State& s) {
  // m a = -m g + f0 + m v^2 / d1: least squares of a + g = f0 / m + v^2 / d1.
  const size_t n = fit_v_.size();
  if (n >= 2) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t k = 0; k < n; ++k) {
      const double x = fit_v_[k] * fit_v_[k], y = fit_a_[k] + g_;
      sx += x;
      sy += y;
      sxx += x * x;
      sxy += x * y;
    }
    const double den = n * sxx - sx * sx;
    if (den > 0) {
      inv_d1_ = (n * sxy - sx * sy) / den;
      f0_ = mass_ * (sy - inv_d1_ * sx) / n;
      double r2 = 0;
      for (size_t k = 0; k < n; ++k) {
        const double r = fit_a_[k] + g_ - f0_ / mass_ - inv_d1_ * fit_v_[k] * fit_v_[k];
        r2 += r * r;
      }
      fit_rms_ = std::sqrt(r2 / n);
    }
  }
}

void ImpactTracker::columns(std::vector<std::string>& out) const {
  for (const char* c : {"depth", "vz", "az"}) out.push_back(c);
}

void ImpactTracker::row(const Model& m, const State& s, std::vector<double>& out) const {
  const BodyState& b = s.bodies[body_];
  out.push_back(surface_ - (b.pos.z() - radius_));
  out.push_back(b.vel.z());
  out.push_back(b.force.z() / mass_ - g_);
}

void ImpactTracker::summary(JsonObject& out) const {
  JsonObject o;
  o.num("stopping_depth", stopping_depth()).num("contact_at", t_contact_);
  o.num("duration_1cm_s", duration_1cm()).num("duration_1mm_s", duration_1mm());
  o.num("stopping_depth_mean_top", stopping_depth_mean_top());
  o.boolean("bounced", bounced()).num("rebound", rebound_).boolean("bounced_1mm_s", bounced_1mm_s());
  o.num("max_upward_speed", max_up_);
  o.num("f0", f0_).num("inv_d1", inv_d1_).num("fit_rms", fit_rms_).num("fit_samples", double(fit_v_.size()));
  out.obj("impact", o);
}

std::string ImpactTracker::progress(const Model& m, const State& s) const {
  char b[160];
  std::snprintf(b, sizeof b, "depth %.4g m, v_z %.3g m/s%s", surface_ - (s.bodies[body_].pos.z() - radius_),
                s.bodies[body_].vel.z(), t_contact_ < 0 ? " (falling)" : "");
  return b;
}

void ImpactTracker::write_csv(const std::string& path) const {
  std::ostringstream f;
  f << "# t (s), depth of the sphere's bottom below the bed's nominal surface (m), v_z (m/s), a_z (m/s^2; "
       "contact force / m - g), every 0.1 ms\n";
  f << "t,depth,vz,az\n";
  f.precision(9);
  for (const Row& r : rows_) f << r.t << ',' << -r.depth << ',' << r.v << ',' << r.a << '\n';
  write_file(path, f.str());
}

// --- one run ------------------------------------------------------------------------

ImpactRun::ImpactRun(const ImpactScene& sc, const Model& m)
    : SceneRun("impact"),
      scene_(sc),
      tracker_(sc.body, sc.radius, sc.surface, sc.mean_top, m.gravity.norm(), sc.spec) {}

std::unique_ptr<SceneRun> ImpactScene::begin(Run& run) const { return std::make_unique<ImpactRun>(*this, run.model()); }

void ImpactRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                              int threads) const {
  const ImpactScene& sc = scene_;
  JsonObject j = summary_head(sc.sc.name, sc.file, rep);
  JsonObject in;
  in.num("speed", sc.spec.speed).num("gap", sc.spec.gap).num("sphere_radius", sc.radius);
  in.num("aim_x", sc.spec.aim.x()).num("aim_y", sc.spec.aim.y());
  in.num("sphere_mass", m.bodies[sc.body].mass).num("gravity", m.gravity.norm());
  const double h = sc.spec.speed * sc.spec.speed / (2 * m.gravity.norm());
  in.num("free_fall_height", h);
  j.obj("input", in);
  JsonObject bed;
  bed.num("grains", sc.bed_grains).num("grain_diameter", sc.grain_diameter).num("surface", sc.surface);
  bed.num("mean_top", sc.mean_top);
  bed.num("mass", sc.bed_mass).num("bulk_density", sc.bulk_density).num("packing_fraction", sc.packing);
  bed.num("container_radius", sc.container_radius).num("first_touch", sc.first_touch).str("cache", sc.bed_cache);
  j.obj("bed", bed);
  JsonObject res;
  const ImpactTracker& t = tracker_;
  res.num("stopping_depth", t.stopping_depth()).num("total_drop_height", h + t.stopping_depth());
  res.num("stopping_depth_mean_top", t.stopping_depth_mean_top());
  res.num("duration_1cm_s", t.duration_1cm()).num("duration_1mm_s", t.duration_1mm());
  res.boolean("bounced", t.bounced()).num("rebound", t.rebound()).boolean("bounced_1mm_s", t.bounced_1mm_s());
  res.num("f0", t.f0()).num("inv_d1", t.inv_d1());
  j.obj("result", res);
  add_run_and_observers(j, m, rep, threads);
  j.write(path);
}

void ImpactRun::write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {
  tracker_.write_csv(dir + "/impact.csv");
}

std::vector<std::pair<std::string, std::string>> ImpactRun::files() const {
  return {{"summary", "summary.json"}, {"time series", "series.csv"}, {"sphere every 0.1 ms", "impact.csv"}};
}

std::string ImpactRun::result_line(const Model& m, const State& s, const RunReport& rep) const {
  char b[400];
  const ImpactTracker& t = tracker_;
  std::snprintf(b, sizeof b,
                "impact %s: %.3g m/s into %d grains: stopping depth %.4g m, collision %.4g s (to 1 cm/s), %.4g s "
                "(to 1 mm/s), %s; f0 = %.4g N, 1/d1 = %.4g 1/m (%.0f s wall)",
                scene_.sc.name.c_str(), scene_.spec.speed, scene_.bed_grains, t.stopping_depth(), t.duration_1cm(),
                t.duration_1mm(), t.bounced() ? "bounced" : "no bounce", t.f0(), t.inv_d1(), rep.wall_seconds);
  return b;
}

std::unique_ptr<Scene> ImpactKind::prepare(const YAML::Node& doc, const std::string& file,
                                           const SceneOptions& opt) const {
  auto is = std::make_unique<ImpactScene>();
  is->file = file;
  YAML::Node root = YAML::Clone(doc);
  is->spec = parse_impact(root["impact"], file);
  ImpactSpec& sp = is->spec;
  root.remove("impact");
  const YamlReader rd(file);
  is->sc = parse_scenario(root, file);
  Scenario& sc = is->sc;
  Model& m = sc.model;
  for (const auto& w : sc.warnings) std::fprintf(stderr, "[impact] warning: %s\n", w.c_str());
  for (size_t k = 0; k < m.bodies.size(); ++k)
    if (m.bodies[k].name == sp.impactor) is->body = int(k);
  if (is->body < 0) rd.fail("impact.impactor", "no body named '" + sp.impactor + "' (" + body_names_text(is->sc.model) + ")");
  const BodyModel& bm = m.bodies[is->body];
  if (bm.fixed || bm.shapes.size() != 1 || bm.shapes[0].type != ShapeType::Sphere)
    rd.fail("impact.impactor", "the impactor must be a free body of one sphere shape");
  is->radius = bm.shapes[0].size.x();
  if (m.n_grains == 0) rd.fail("grains", "the impact scene needs a bed");
  for (const Wall& w : m.walls)
    if (w.type == WallType::Cylinder) is->container_radius = w.radius;
  if (!(is->container_radius > 0)) rd.fail("walls", "the impact scene needs the container's cylinder wall");

  // 1. The bed: poured, settled and cut by the stages (cached), the sphere parked far above: it falls
  // freely meanwhile, so 100 m above the height it falls through in the stages' whole duration.
  double relax_time = 0;
  for (const Stage& st : sc.stages) relax_time += st.duration;
  State s = sc.initial;
  s.bodies[is->body].pos = Vec3(0, 0, 100.0 + 0.5 * m.gravity.norm() * relax_time * relax_time);
  RelaxedBed bed = relax_bed(sc, s, {is->body}, opt, "impact");
  s = std::move(bed.state);
  is->bed_cache = bed.cache;

  // 2. Surface: the mean top of the highest A/d^2 grains (about one layer).
  double d = 0, vol = 0, mass = 0;
  std::vector<double> tops(m.n_grains);
  for (int i = 0; i < m.n_grains; ++i) {
    const double r = m.grain_radius[i];
    d += 2 * r;
    vol += 4.0 / 3.0 * kPi * r * r * r;
    mass += m.grain_mass[i];
    tops[i] = s.pos[i].z() + r;
  }
  d /= m.n_grains;
  std::sort(tops.begin(), tops.end(), std::greater<double>());
  const double area = kPi * is->container_radius * is->container_radius;
  const int layer = std::clamp(int(std::lround(area / (d * d))), 1, m.n_grains);
  double top = 0;
  for (int k = 0; k < layer; ++k) top += tops[k];
  top /= layer;
  is->mean_top = top;
  // The nominal surface H: the height of the last cut, at the beads' tops
  // (trim_tops), or its centre plane plus the largest radius; without a cut,
  // the mean top.
  is->surface = top;
  double r_max = 0;
  for (int i = 0; i < m.n_grains; ++i) r_max = std::max(r_max, m.grain_radius[i]);
  for (const Stage& st : sc.stages)
    if (st.trim) is->surface = st.trim_above + (st.trim_tops ? 0.0 : r_max);
  is->grain_diameter = d;
  is->bed_grains = m.n_grains;
  is->bed_mass = mass;
  is->bulk_density = mass / (area * is->surface);
  is->packing = vol / (area * is->surface);

  // 3. The sphere on the axis, its bottom `gap` above the height at which it
  // would first touch a bead (first touch: a bead at a distance rho from the
  // axis meets the descending sphere when its bottom is at
  // z_i + sqrt((R + r_i)^2 - rho^2) - R), moving down so that it reaches that
  // height at `speed` (gap at most V^2 / 4g).
  double touch = -kInf;
  for (int i = 0; i < m.n_grains; ++i) {
    const double reach = is->radius + m.grain_radius[i];
    const double rho = std::hypot(s.pos[i].x() - sp.aim.x(), s.pos[i].y() - sp.aim.y());
    if (rho < reach) touch = std::max(touch, s.pos[i].z() + std::sqrt(reach * reach - rho * rho) - is->radius);
  }
  if (touch == -kInf) touch = top;
  is->first_touch = touch;
  const double g = m.gravity.norm();
  sp.gap = std::min(sp.gap, 0.25 * sp.speed * sp.speed / g);
  const double v0 = std::sqrt(sp.speed * sp.speed - 2 * g * sp.gap);
  BodyState& b = s.bodies[is->body];
  b.q = bm.ref_rot.normalized();
  if (std::hypot(sp.aim.x(), sp.aim.y()) + is->radius >= is->container_radius)
    rd.fail("impact.aim", "the sphere must fit inside the container (" + std::to_string(is->container_radius) +
                              " m radius) on that vertical");
  b.pos = Vec3(sp.aim.x(), sp.aim.y(), touch + sp.gap + is->radius);
  set_body_velocity(bm, b, Vec3(0, 0, -v0), Vec3::Zero());
  restart_at_zero(s);
  if (!opt.quiet)
    std::fprintf(stderr,
                 "[impact] bed: %d grains of %.3g mm, surface %.4g m (mean top %.4g m), bulk %.0f kg/m^3 (packing "
                 "%.3f); sphere %.3g kg, radius %.3g m, %.3g m/s at the surface\n",
                 m.n_grains, d * 1e3, is->surface, top, is->bulk_density, is->packing, bm.mass, is->radius, sp.speed);
  is->start = std::move(s);
  is->plan = RunPlan::open_ended(sc.name, "impact");
  is->plan.stages[0].duration = sp.duration;
  is->sample_every = sp.sample_every;
  return is;
}

std::shared_ptr<const SceneKind> impact_kind() { return std::make_shared<ImpactKind>(); }

}  // namespace rt
