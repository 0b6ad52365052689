// The plume-erosion scene kind (see plume_scene.hpp; docs/scenes.md D).
#include "regolith_twin/scenes/plume/plume_scene.hpp"
#include "regolith_twin/core/types.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/field.hpp"
#include "regolith_twin/run/bed_cache.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {


class PlumeKind : public SceneKind {
 public:
  std::string name() const override { return "plume"; }
  std::unique_ptr<Scene> prepare(const YAML::Node& root, const std::string& file,
                                 const SceneOptions& opt) const override;
};

PlumeSpec parse_plume(const YAML::Node& n, const std::string& src) {
  PlumeSpec sp;
  const YamlReader rd(src);
  const std::string p = "plume";
  if (!n || !n.IsMap()) rd.fail(p, "missing or not a mapping");
  rd.only(n, p,
          {"penetration_depth", "erosion_height", "duration", "plane_motion", "steps_per_contact", "collisionless",
           "window", "depleted_fraction", "row_every", "sample_every", "splash"});
  sp.penetration_depth = rd.number(n, p, "penetration_depth", sp.penetration_depth, 0, 1000);
  sp.erosion_height = rd.number(n, p, "erosion_height", sp.erosion_height, 0, 1000);
  sp.duration = rd.number(n, p, "duration", sp.duration, 0, 1e4, true);
  const std::string motion = rd.text(n, p, "plane_motion", "net");
  if (motion == "net")
    sp.plane_motion = PlaneMotion::Net;
  else if (motion == "upward")
    sp.plane_motion = PlaneMotion::Upward;
  else if (motion == "fixed")
    sp.plane_motion = PlaneMotion::Fixed;
  else
    rd.fail(p + ".plane_motion", "expected net, upward or fixed, got '" + motion + "'");
  sp.steps_per_contact = rd.number(n, p, "steps_per_contact", sp.steps_per_contact, 4, 1e6);
  sp.collisionless = rd.boolean(n, p, "collisionless", sp.collisionless);
  sp.window = int(rd.integer(n, p, "window", sp.window, 1, 100000000));
  sp.depleted_fraction = rd.number(n, p, "depleted_fraction", sp.depleted_fraction, 0, 1, true);
  sp.row_every = rd.number(n, p, "row_every", sp.row_every, 0, 1e3, true);
  sp.sample_every = rd.number(n, p, "sample_every", sp.sample_every, 0, 1e3, true);
  if (const YAML::Node sn = YamlReader::get(n, "splash")) {
    const std::string q = p + ".splash";
    if (!sn.IsMap()) rd.fail(q, "expected a mapping {speed, angle_deg, height}");
    rd.only(sn, q, {"speed", "angle_deg", "height"});
    sp.splash = true;
    sp.splash_speed = rd.number(sn, q, "speed", sp.splash_speed, 0, 1e4, true);
    sp.splash_angle_deg = rd.number(sn, q, "angle_deg", sp.splash_angle_deg, 0, 90, true);
    sp.splash_height = rd.number(sn, q, "height", sp.splash_height, 0, 1000, true);
  }
  return sp;
}

const GasField* gas_of(const Model& m) {
  for (const auto& f : m.fields)
    if (const auto* g = dynamic_cast<const GasField*>(f.get())) return g;
  return nullptr;
}

const char* motion_name(PlaneMotion p) {
  return p == PlaneMotion::Net ? "net" : p == PlaneMotion::Upward ? "upward" : "fixed";
}

}  // namespace

PlumeRun::PlumeRun(const PlumeScene& scene, const Model& m)
    : SceneRun("plume"),
      scene_(scene),
      impulse_(scene.planes.anchor_slot, scene.planes.erosion_slot, scene.spec.erosion_height * scene.diameter),
      erosion_(scene.planes) {}

std::unique_ptr<SceneRun> PlumeScene::begin(Run& run) const { return std::make_unique<PlumeRun>(*this, run.model()); }

void PlumeRun::write_summary(const std::string& path, const Model& m, const State& s, const RunReport& rep,
                             int threads) const {
  const PlumeScene& sc = scene_;
  const PlumeSpec& sp = sc.spec;
  JsonObject j = summary_head(sc.sc.name, sc.file, rep);
  JsonObject in;
  in.num("penetration_depth_d", sp.penetration_depth).num("erosion_height_d", sp.erosion_height);
  in.num("duration", sp.duration).str("plane_motion", motion_name(sp.plane_motion));
  in.boolean("collisionless", sp.collisionless).num("steps_per_contact", sp.steps_per_contact);
  in.num("window_steps", sp.window).num("depleted_fraction", sp.depleted_fraction).num("gravity", m.gravity.norm());
  if (sp.splash)
    in.num("splash_speed", sp.splash_speed).num("splash_angle_deg", sp.splash_angle_deg).num("splash_height_d",
                                                                                                 sp.splash_height);
  j.obj("input", in);
  JsonObject bed;
  bed.num("grains", sc.bed_grains).num("diameter", sc.diameter).num("top", sc.top);
  bed.num("depth_d", sc.top / sc.diameter).num("solid_fraction", sc.bed_fraction);
  bed.num("box_x", m.periodic.x ? m.periodic.length.x() : 0).num("box_y", m.periodic.y ? m.periodic.length.y() : 0);
  bed.str("cache", sc.bed_cache);
  j.obj("bed", bed);
  JsonObject gas;
  gas.num("velocity_at_top", sc.gas_at_top).num("shear_at_top", sc.shear_at_top);
  gas.num("anchoring_plane_start", sc.planes.anchor).num("erosion_plane_start", sc.planes.erosion);
  j.obj("gas", gas);
  add_run_and_observers(j, m, rep, threads);
  j.write(path);
}

void PlumeRun::write_files(const std::string& dir, const Model& m, const State& s, const RunReport& rep) const {
  erosion_.write_csv(dir + "/erosion.csv");
  impulse_.write_csv(dir + "/crossings.csv");
  const GasField* gas = gas_of(m);
  if (!gas || m.n_grains == 0) return;
  // The gas against the weight by height (docs/scenes.md D), for a grain of the bed's size.
  const PlumeScene& sc = scene_;
  const double d = sc.diameter, r = 0.5 * d, weight = m.grain_mass[0] * m.gravity.norm();
  std::vector<double> heights;
  for (int k = 1; k <= 2 * int(std::lround(sc.spec.penetration_depth + 20)); ++k) heights.push_back(0.5 * k * d);
  write_file(dir + "/gas_forces.csv",
             gas_force_table_csv(*gas, r, weight, sc.top - sc.planes.anchor,
                                 heights, {0, 0.25, 0.5, 0.75, 0.9}));
  // The grains left below the erosion plane at the end: where they are, how fast, what the gas does to them.
  const double anchor = s.field_values[sc.planes.anchor_slot], erosion = s.field_values[sc.planes.erosion_slot];
  std::ostringstream o;
  o << "# grains below the erosion plane at t = " << s.time << " s (anchoring plane " << anchor / d
    << " d, erosion plane " << erosion / d << " d above z = 0): height of the centre (d), above the anchoring plane "
    << "(d), velocity (m/s), U(h) (m/s), the gas force at that velocity over the weight\n";
  o << "grain,z_d,h_d,vx,vy,vz,u,gas_x_over_weight,gas_z_over_weight\n";
  o.precision(6);
  for (int i = 0; i < m.n_grains; ++i) {
    if (s.pos[i].z() > erosion) continue;
    const double h = s.pos[i].z() - anchor, w = m.grain_mass[i] * m.gravity.norm();
    const Vec3 f = h > 0 ? gas->force_at(m.grain_radius[i], h, s.pos[i], s.vel[i]) : Vec3(Vec3::Zero());
    o << i << ',' << s.pos[i].z() / d << ',' << h / d << ',' << s.vel[i].x() << ',' << s.vel[i].y() << ','
      << s.vel[i].z() << ',' << (h > 0 ? gas->params().velocity(h) : 0.0) << ',' << f.x() / w << ',' << f.z() / w
      << '\n';
  }
  write_file(dir + "/below_end.csv", o.str());
}

std::vector<std::pair<std::string, std::string>> PlumeRun::files() const {
  std::vector<std::pair<std::string, std::string>> f = {{"summary", "summary.json"},
                                                        {"time series", "series.csv"},
                                                        {"erosion, every step averaged", "erosion.csv"},
                                                        {"upward crossings and their impulses", "crossings.csv"}};
  if (!scene_.spec.splash) {
    f.push_back({"gas against weight by height", "gas_forces.csv"});
    f.push_back({"grains below the erosion plane at the end", "below_end.csv"});
  }
  return f;
}

std::string PlumeRun::result_line(const Model& m, const State& s, const RunReport& rep) const {
  char b[400];
  const ErosionFix& e = erosion_;
  char dep[64] = "not depleted";
  if (e.depleted_at() >= 0) std::snprintf(dep, sizeof dep, "depleted at %.4g s", e.depleted_at());
  std::snprintf(b, sizeof b,
                "plume %s: %d of %d grains above the erosion plane after %.4g s, %s; erosion rate %.4g grains/s "
                "(%.4g /s/m^2); %d up and %d down crossings (%.0f s wall)",
                scene_.sc.name.c_str(), e.above(), scene_.bed_grains, s.time, dep, e.rate(), e.rate_per_area(),
                e.total_up(), e.total_down(), rep.wall_seconds);
  return b;
}

// "materials.a, materials.b": the materials of the scene's grains, for messages.
static std::string material_keys(const Scenario& sc) {
  std::string t;
  for (const Material& mat : sc.model.materials)
    if (!mat.structure) t += (t.empty() ? "" : ", ") + std::string("materials.") + mat.name;
  return t;
}

std::unique_ptr<Scene> PlumeKind::prepare(const YAML::Node& doc, const std::string& file,
                                          const SceneOptions& opt) const {
  auto ps = std::make_unique<PlumeScene>();
  ps->file = file;
  YAML::Node root = YAML::Clone(doc);
  ps->spec = parse_plume(root["plume"], file);
  const PlumeSpec& sp = ps->spec;
  root.remove("plume");
  const YamlReader rd(file);

  // The step from the contact time with damping: read once for the grains'
  // mass and the scene k_n, then with contact.dt = t_c / steps_per_contact.
  {
    const Scenario probe = parse_scenario(root, file);
    const Model& m = probe.model;
    if (m.n_grains == 0) rd.fail("grains", "the plume scene needs a bed");
    if (m.contact_model != ContactModel::Linear) rd.fail("contact.model", "the plume scene uses the linear law");
    if (!m.periodic.x || !m.periodic.y) rd.fail("periodic", "the plume scene needs a box periodic in x and y");
    double mass = 0;
    for (int i = 0; i < m.n_grains; ++i) mass += m.grain_mass[i];
    mass /= m.n_grains;
    const double eps = m.materials[m.grain_material[0]].eps_n;
    if (!root["contact"]) root["contact"] = YAML::Node(YAML::NodeType::Map);
    root["contact"]["dt"] = linear_contact_time(mass / 2, m.kn, eps) / sp.steps_per_contact;
  }
  ps->sc = parse_scenario(root, file);
  Scenario& sc = ps->sc;
  Model& m = sc.model;
  if (!(m.gravity.norm() >= 1e-6))
    rd.fail("gravity", "the plume's figures are ratios to the grains' weight: gravity must be at least 1e-6 m/s^2");
  for (const auto& w : sc.warnings) std::fprintf(stderr, "[plume] warning: %s\n", w.c_str());
  const GasField* gas = gas_of(m);
  if (!gas && !sp.splash) rd.fail("gas", "the plume scene needs a gas (or plume.splash for the test without one)");
  const GasFlowParams gp = gas ? gas->params() : GasFlowParams();
  m.fields.clear();  // added back below, anchored to the moving plane
  if (!opt.quiet)
    std::fprintf(stderr, "[plume] %d grains, dt = %.4g s, k_n = %.4g N/m, g = %.4g m/s^2, box %.4g x %.4g m\n",
                 m.n_grains, m.dt, m.kn, m.gravity.norm(), m.periodic.length.x(), m.periodic.length.y());

  // 1. The settled bed (cached).
  RelaxedBed bed = relax_bed(sc, sc.initial, {}, opt, "plume");
  State s = std::move(bed.state);
  ps->bed_cache = bed.cache;
  ps->bed_grains = m.n_grains;

  // 2. Its top: the mean top of the highest A/d^2 grains (about one layer);
  // its solid fraction: grain centres from 2 d above the floor's lowest
  // grain to 2 d below the top, over that slab.
  double d = 0, vol = 0, zmin = 1e300;
  for (int i = 0; i < m.n_grains; ++i) {
    d += 2 * m.grain_radius[i];
    zmin = std::min(zmin, s.pos[i].z() - m.grain_radius[i]);
  }
  d /= m.n_grains;
  ps->diameter = d;
  const double area = m.periodic.length.x() * m.periodic.length.y();
  std::vector<double> tops(m.n_grains);
  for (int i = 0; i < m.n_grains; ++i) tops[i] = s.pos[i].z() + m.grain_radius[i];
  std::sort(tops.begin(), tops.end(), std::greater<double>());
  const int layer = std::clamp(int(std::lround(area / (d * d))), 1, m.n_grains);
  double top = 0;
  for (int k = 0; k < layer; ++k) top += tops[k];
  top /= layer;
  ps->top = top;
  const double lo = zmin + 2 * d, hi = top - 2 * d;
  for (int i = 0; i < m.n_grains; ++i)
    if (s.pos[i].z() > lo && s.pos[i].z() <= hi) vol += 4.0 / 3.0 * kPi * std::pow(m.grain_radius[i], 3);
  ps->bed_fraction = hi > lo ? vol / (area * (hi - lo)) : 0;
  if (!(ps->bed_fraction > 0.05))
    throw InputError(file + ": the settled bed is too shallow to measure its solid fraction (top " +
                     std::to_string(top / d) + " d above the floor; at least 5 d needed): its depth comes from the "
                     "grains (grains[0].fill, grains[0].radius), their material (" + material_keys(sc) +
                     "), the box (periodic.x, periodic.y), gravity and the seed");

  // 3. The planes and the gas, anchored to the state's first field value.
  ErosionPlanes& pl = ps->planes;
  pl.anchor = top - sp.penetration_depth * d;
  pl.erosion = top + sp.erosion_height * d;
  pl.grain_volume = kPi / 6 * d * d * d;
  pl.bed_fraction = ps->bed_fraction;
  pl.area = area;
  pl.motion = sp.splash ? PlaneMotion::Fixed : sp.plane_motion;
  pl.anchor_slot = 0;
  pl.erosion_slot = 1;
  pl.window = sp.window;
  pl.depleted_fraction = sp.depleted_fraction;
  pl.sample_every = std::max(1, int(std::lround(sp.row_every / m.dt)));
  pl.hold_below_anchor = sp.collisionless;
  s.field_values.assign(2, 0.0);
  s.field_values[0] = pl.anchor;
  s.field_values[1] = pl.erosion;
  if (gas && !sp.splash) {
    GasFlowParams g = gp;
    g.anchor_slot = 0;
    m.fields.push_back(std::make_shared<GasField>(g));
    const double h = top - pl.anchor;
    ps->gas_at_top = g.velocity(h);
    ps->shear_at_top = ps->gas_at_top != 0 ? std::abs(g.gradient(h)) * d / std::abs(ps->gas_at_top) : 0;
  }
  if (sp.collisionless) m.mobile_contacts = false;

  // 4. The splash grain: one more grain of the bed's size and material.
  if (sp.splash) {
    const double a = sp.splash_angle_deg * kPi / 180;
    const Vec3 p0(m.periodic.lo.x() + 0.5 * m.periodic.length.x(), m.periodic.lo.y() + 0.5 * m.periodic.length.y(),
                  top + sp.splash_height * d + 0.5 * d);
    const Vec3 v0(sp.splash_speed * std::cos(a), 0, -sp.splash_speed * std::sin(a));
    ps->splash_grain = add_grain(m, s, 0.5 * d, m.grain_material[0], p0, v0, Vec3::Zero());
  }
  finalize_model(m);
  restart_at_zero(s);
  if (!opt.quiet)
    std::fprintf(stderr,
                 "[plume] bed: %d grains, top %.2f d, solid fraction %.3f; anchoring plane %.2f d, erosion plane "
                 "%.2f d; gas %.4g m/s at the top (omega* %.3g)%s\n",
                 ps->bed_grains, top / d, ps->bed_fraction, pl.anchor / d, pl.erosion / d, ps->gas_at_top,
                 ps->shear_at_top, sp.collisionless ? "; collisionless" : sp.splash ? "; splash, no gas" : "");
  ps->start = std::move(s);
  ps->plan = RunPlan::open_ended(sc.name, sp.splash ? "splash" : "plume");
  ps->plan.stages[0].duration = sp.duration;
  ps->sample_every = sp.sample_every;
  return ps;
}

std::shared_ptr<const SceneKind> plume_kind() { return std::make_shared<PlumeKind>(); }

}  // namespace rt
