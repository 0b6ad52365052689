// Lander scenes: placement, perturbed beds and the landing outcome
// (docs/scenes.md A). See landing.hpp.
#include "regolith_twin/scenes/landing/landing.hpp"
#include "regolith_twin/core/types.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <random>

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/yaml_reader.hpp"
#include "regolith_twin/scenes/landing/landing_scene.hpp"

namespace rt {
namespace {

constexpr double kDeg = kPi / 180.0;

// Horizontal direction of motion.
Vec3 heading_dir(const LandingSpec& sp) { return Vec3(std::cos(sp.heading_deg * kDeg), std::sin(sp.heading_deg * kDeg), 0); }

// Points of a shape that can be lowest (box corners, rims, support points), body frame.
void extreme_points(const BodyModel& b, const Shape& sh, const Quat& q_world, std::vector<Vec3>& out) {
  auto add = [&](const Vec3& p_shape) { out.push_back(sh.pos + sh.rot * p_shape); };
  switch (sh.type) {
    case ShapeType::Box:
      for (int c = 0; c < 8; ++c)
        add(Vec3((c & 1 ? 1 : -1) * sh.size.x(), (c & 2 ? 1 : -1) * sh.size.y(), (c & 4 ? 1 : -1) * sh.size.z()));
      break;
    case ShapeType::Cylinder:
      for (int k = 0; k < 72; ++k) {
        const double a = 2 * kPi * k / 72;
        add(Vec3(sh.size.x() * std::cos(a), sh.size.x() * std::sin(a), sh.size.z()));
        add(Vec3(sh.size.x() * std::cos(a), sh.size.x() * std::sin(a), -sh.size.z()));
      }
      break;
    case ShapeType::Sphere:
    case ShapeType::Ellipsoid: {
      // Support point in the world -z direction: x = E^2 d / sqrt(d' E^2 d).
      const Vec3 d = (q_world * sh.rot).conjugate() * Vec3(0, 0, -1);
      const Vec3 e2 = sh.size.cwiseProduct(sh.size);
      add(e2.cwiseProduct(d) / std::sqrt(d.dot(e2.cwiseProduct(d))));
      break;
    }
    case ShapeType::Mesh:
      for (const Vec3& v : b.meshes[sh.mesh].vertices) add(v);
      break;
  }
}

int largest_box(const BodyModel& b) {
  int best = -1;
  double vol = 0;
  for (size_t k = 0; k < b.shapes.size(); ++k)
    if (b.shapes[k].type == ShapeType::Box && b.shapes[k].size.prod() > vol) {
      vol = b.shapes[k].size.prod();
      best = int(k);
    }
  return best;
}

LandingSpec interpret_landing(const YAML::Node& n, const std::string& src) {
  LandingSpec sp;
  const YamlReader rd(src);
  const std::string p = "landing";
  if (!n || !n.IsMap()) rd.fail(p, "missing or not a mapping");
  rd.only(n, p,
          {"lander", "rim", "container_radius", "attitude", "pitch_deg", "roll_deg", "angle_deg", "heading_deg",
           "speed", "clearance", "aim", "slope_deg", "g", "after_liftoff", "max_after_contact", "max_time",
           "far_ring", "sphere_radius", "repeat", "perturb_seed", "sample_every", "active_radius", "trapped_hold"});
  if (!n["lander"]) rd.fail(p + ".lander", "missing (name of the lander body under 'bodies')");
  sp.lander = rd.text(n, p, "lander", "");
  sp.rim = rd.number(n, p, "rim", sp.rim, -1e3, 1e3);
  sp.container_radius = rd.number(n, p, "container_radius", sp.container_radius, 0.01, 1e3);
  const std::string a = rd.choice(n, p, "attitude", "BCF", {"Flat", "flat", "BCF", "bcf", "FCF", "fcf"});
  sp.attitude = (a == "Flat" || a == "flat") ? Attitude::Flat : (a == "BCF" || a == "bcf") ? Attitude::BCF : Attitude::FCF;
  sp.pitch_deg = rd.number(n, p, "pitch_deg", sp.pitch_deg, 0, 80);
  sp.roll_deg = rd.number(n, p, "roll_deg", sp.roll_deg, 0, 80);
  sp.angle_deg = rd.number(n, p, "angle_deg", sp.angle_deg, 0, 85);
  sp.heading_deg = rd.number(n, p, "heading_deg", sp.heading_deg, -360, 360);
  sp.speed = rd.number(n, p, "speed", sp.speed, 1e-6, 1e4);
  sp.clearance = rd.number(n, p, "clearance", sp.clearance, 0, 10);
  if (const YAML::Node aim = n["aim"]) {
    if (!aim.IsSequence() || aim.size() != 2) rd.fail(p + ".aim", "expected [x, y] on the trim plane, m");
    sp.aim = Vec3(rd.number(aim[0], p + ".aim[0]", -1e3, 1e3), rd.number(aim[1], p + ".aim[1]", -1e3, 1e3), 0);
  }
  sp.slope_deg = rd.number(n, p, "slope_deg", sp.slope_deg, -60, 60);
  sp.g = rd.number(n, p, "g", sp.g, 1e-6, 100);  // m/s^2: Ryugu 1.2e-4; the hop figures need g > 0
  sp.after_liftoff = rd.number(n, p, "after_liftoff", sp.after_liftoff, 0, 1e4);
  sp.max_after_contact = rd.number(n, p, "max_after_contact", sp.max_after_contact, 0, 1e5);
  sp.max_time = rd.number(n, p, "max_time", sp.max_time, 0, 1e6);
  sp.far_ring = rd.number(n, p, "far_ring", sp.far_ring, 0, 1e3);
  sp.sphere_radius = rd.number(n, p, "sphere_radius", sp.sphere_radius, 0, 1e3);
  sp.repeat = rd.integer(n, p, "repeat", 0, 0, 1000000);
  sp.perturb_seed = (unsigned long)rd.integer(n, p, "perturb_seed", 1, 0, 4000000000L);
  sp.sample_every = rd.number(n, p, "sample_every", sp.sample_every, 1e-6, 1e3);
  sp.active_radius = rd.number(n, p, "active_radius", sp.active_radius, 0, 1e3);
  sp.trapped_hold = rd.number(n, p, "trapped_hold", sp.trapped_hold, 0, 1e5);
  return sp;
}

}  // namespace

LandingSpec parse_landing(const YAML::Node& n, const std::string& src) {
  // yaml-cpp's conversion errors become InputErrors naming the file (and line).
  try {
    return interpret_landing(n, src);
  } catch (const YAML::Exception& e) {
    throw InputError(src + ": " + e.what());
  }
}

Vec3 landing_gravity(const LandingSpec& sp) {
  // Upslope (positive): gravity gains a component against the motion.
  const double s = sp.slope_deg * kDeg;
  return sp.g * (-std::cos(s) * Vec3::UnitZ() - std::sin(s) * heading_dir(sp));
}

Perturbation perturbation(const LandingSpec& sp, double mean_radius) {
  Perturbation p;
  if (sp.repeat <= 0) return p;
  std::mt19937_64 rng(sp.perturb_seed * 1000003ULL + static_cast<unsigned long>(sp.repeat));
  std::uniform_real_distribution<double> u(0, 1);
  p.angle = 2 * kPi * u(rng);
  const double rad = 2 * mean_radius * std::sqrt(u(rng)), phi = 2 * kPi * u(rng);  // uniform in a disk of one diameter
  p.aim_offset = Vec3(rad * std::cos(phi), rad * std::sin(phi), 0);
  return p;
}

void place_lander(const Model& m, State& s, int b, const LandingSpec& sp) {
  const BodyModel& bm = m.bodies[b];
  const Vec3 h = heading_dir(sp);
  const Vec3 side = Vec3::UnitZ().cross(h);  // horizontal, normal to the motion
  double pitch = 0, roll = 0;
  if (sp.attitude != Attitude::Flat) {
    // Tilt about `side` so the back (BCF) or the front (FCF) goes down, then
    // about the motion so one corner of that edge is lowest.
    pitch = (sp.attitude == Attitude::BCF ? -1 : 1) * sp.pitch_deg * kDeg;
    roll = sp.roll_deg * kDeg;
  }
  const Quat heading(Eigen::AngleAxisd(sp.heading_deg * kDeg, Vec3::UnitZ()));
  // A positive rotation about `side` (= z x h) lowers the front: BCF uses a negative one.
  const Quat ref_q = Quat(Eigen::AngleAxisd(pitch, side)) * Quat(Eigen::AngleAxisd(roll, h)) * heading;
  BodyState& bs = s.bodies[b];
  bs.q = (ref_q * bm.ref_rot).normalized();
  // Lowest point of all shapes, relative to the centre of mass.
  std::vector<Vec3> pts;
  for (const Shape& sh : bm.shapes) extreme_points(bm, sh, bs.q, pts);
  Vec3 low = bs.q * pts[0];
  for (const Vec3& p : pts) {
    const Vec3 w = bs.q * p;
    if (w.z() < low.z()) low = w;
  }
  const double a = sp.angle_deg * kDeg;
  const Vec3 vdir = std::sin(a) * h - std::cos(a) * Vec3::UnitZ();
  const Vec3 contact = Vec3(sp.aim.x(), sp.aim.y(), sp.rim) - (sp.clearance / std::cos(a)) * vdir;
  bs.pos = contact - low;
  // Back off along the approach line from grains closer than the clearance.
  for (int iter = 0; iter < 200; ++iter) {
    double worst = 0, along = 1;
    for (int i = 0; i < m.n_grains; ++i) {
      const Vec3 p = bs.q.conjugate() * (s.pos[i] - bs.pos);
      for (const Shape& sh : bm.shapes) {
        const ShapeGap g = shape_gap(bm, sh, p, m.grain_radius[i], std::max(sp.clearance, 0.0));
        if (g.overlap + sp.clearance > worst) {
          worst = g.overlap + sp.clearance;
          along = std::fabs(vdir.dot(bs.q * g.n));
        }
      }
    }
    if (worst <= 0) break;
    bs.pos -= (worst / std::max(along, 0.2) + 1e-6) * vdir;
  }
  set_body_velocity(bm, bs, sp.speed * vdir, Vec3::Zero());
  bs.force.setZero();
  bs.torque.setZero();
  s.forces_valid = false;  // the body moved: forces are recomputed by the next step
}

std::vector<Vec3> lander_corners(const BodyModel& bm, const BodyState& bs) {
  std::vector<Vec3> out;
  const int k = largest_box(bm);
  if (k < 0) return out;
  const Shape& sh = bm.shapes[k];
  for (int c = 0; c < 8; ++c) {
    const Vec3 p(sh.size.x() * (c & 1 ? 1 : -1), sh.size.y() * (c & 2 ? 1 : -1), sh.size.z() * (c & 4 ? 1 : -1));
    out.push_back(bs.pos + bs.q * (sh.pos + sh.rot * p));
  }
  return out;
}

std::vector<Vec3> lander_corners(const Model& m, const State& s, int b) { return lander_corners(m.bodies[b], s.bodies[b]); }

LandingTracker::LandingTracker(const BodyModel& bm, const LandingSpec& sp, const Vec3& gravity, double t_start)
    : bm_(bm), sp_(sp), g_(gravity), t_start_(t_start) {
  if (const int k = largest_box(bm); k >= 0) {
    liftoff_com_ = std::max(0.0, bm.shapes[k].size.minCoeff() - bm.shapes[k].pos.norm());
    reach_ = bm.shapes[k].size.norm() + bm.shapes[k].pos.norm();
  }
}

double LandingTracker::expected_time_left(double t, const BodyState& bs) const {
  if (ended()) return 0;
  if (o_.lifted_off_clear) return std::max(0.0, o_.t_liftoff_clear + sp_.after_liftoff - t);
  const double low = lowest_corner(bs), vn = bs.vel.z();
  // Approach: to first contact at the present speed, then the collision as if it began now.
  const double v_ref = o_.contact ? vn_in_ : -vn;
  if (!(v_ref > 0) || reach_ <= 0) return -1;
  const double to_contact = o_.contact ? 0.0 : std::max(low, 0.0) / v_ref;
  // While the lander still sinks its centre will end lower: the worst attitude weighs more.
  const double worst = o_.contact && vn >= 0 ? kWorstShare : kWorstShareSinking;
  const double rise = (1 - worst) * std::max(-low, 0.0) + worst * std::max(sp_.rim + reach_ - bs.pos.z(), 0.0);
  const double up = std::max(o_.contact ? vn : 0.0, kReboundFraction * v_ref);
  double left = to_contact + rise / up + sp_.after_liftoff;
  if (o_.contact) left = std::min(left, o_.t_contact + sp_.max_after_contact - t);
  return std::max(left, 0.0);
}

double LandingTracker::lowest_corner(const BodyState& bs) const {
  double low = 1e300;
  for (const Vec3& c : lander_corners(bm_, bs)) low = std::min(low, c.z() - sp_.rim);
  return low;
}

const char* LandingTracker::phase() const {
  return !o_.contact ? "approach" : (!o_.lifted_off_clear ? "collision" : "flight");
}

Departure LandingTracker::depart(double t, const BodyState& bs) const {
  Departure d;
  d.t = t;
  d.v_out = bs.vel.norm();
  d.e_lin_out = body_lin_energy(bm_, bs);
  d.e_rot_out = body_rot_energy(bm_, bs);
  d.spin_out = bs.omega.norm();
  d.angle_out_deg = std::acos(std::clamp(bs.vel.z() / std::max(d.v_out, 1e-300), -1.0, 1.0)) / kDeg;
  d.h_liftoff = bs.pos.z() - sp_.rim;
  // Ballistic flight under the (possibly tilted) gravity, heights normal to the trim plane.
  const Vec3 v0 = bs.vel;
  const double gn = g_.z(), vn = v0.z();
  double ht = std::max(d.h_liftoff, sp_.sphere_radius);
  double disc = vn * vn + 2 * gn * (ht - d.h_liftoff);
  if (disc < 0) {  // apex below the sphere radius: back to the lift-off height instead
    ht = d.h_liftoff;
    disc = vn * vn;
  }
  if (gn < 0 && vn > 0) {
    const double tf = (-vn - std::sqrt(disc)) / gn;
    const Vec3 dx = v0 * tf + 0.5 * g_ * tf * tf;
    d.travel_time = tf;
    d.travel_distance = std::hypot(dx.x(), dx.y());
    const Vec3 v1 = v0 + g_ * tf;
    d.second_impact_speed = v1.norm();
    d.second_impact_angle_deg = std::acos(std::min(1.0, std::fabs(v1.z()) / v1.norm())) / kDeg;
  }
  return d;
}

bool LandingTracker::update(double t, const BodyState& bs, const BodyContacts& c) {
  if (ended()) return true;
  const bool touching = c.total > 0;
  const double low = lowest_corner(bs);
  if (!o_.contact && touching) {
    o_.contact = true;
    o_.t_contact = t;
    o_.v_in = bs.vel.norm();
    vn_in_ = std::max(0.0, -bs.vel.z());
    o_.e_lin_in = body_lin_energy(bm_, bs);
    o_.e_rot_in = body_rot_energy(bm_, bs);
  }
  // Lift-off (published): once a corner has been below the trim plane, the first moment every corner is
  // above it again (or the clear lift-off, below, if no corner ever went under: a bounce off a boulder).
  if (o_.contact && low <= 0) went_under_ = true;
  const bool clear_now = o_.contact && !o_.lifted_off_clear && low > 0 && !touching && bs.vel.z() > 0;
  if (o_.contact && !o_.lifted_off && low > 0 && (went_under_ || clear_now)) {
    o_.lifted_off = true;
    const Departure d = depart(t, bs);
    o_.t_liftoff = t;
    o_.v_out = d.v_out;
    o_.e_lin_out = d.e_lin_out;
    o_.e_rot_out = d.e_rot_out;
    o_.spin_out = d.spin_out;
    o_.angle_out_deg = d.angle_out_deg;
    o_.h_liftoff = d.h_liftoff;
    o_.travel_distance = d.travel_distance;
    o_.travel_time = d.travel_time;
    o_.second_impact_speed = d.second_impact_speed;
    o_.second_impact_angle_deg = d.second_impact_angle_deg;
  }
  if (o_.lifted_off_clear && c.bed > 0) {
    // Contact again within the after-lift-off window with the bed (a body,
    // or a grain that is not ejecta): the lander had not left; the collision
    // goes on (decision, documented in landing.hpp). Ejected grains drifting
    // with the lander do not count.
    o_.lifted_off_clear = false;
    ++o_.relandings;
  }
  if (o_.contact && !o_.lifted_off_clear) {
    o_.max_penetration = std::max(o_.max_penetration, -low);
    // Clear lift-off: every corner above the trim plane, no contact, and the
    // centre of mass moving away from the surface.
    if (clear_now) {
      o_.lifted_off_clear = true;
      o_.t_liftoff_clear = t;
      o_.clear = depart(t, bs);
    }
  }
  if (o_.lifted_off_clear && t >= o_.t_liftoff_clear + sp_.after_liftoff) {
    o_.ended_by = "after_liftoff";
  } else if (o_.contact && !o_.lifted_off_clear && sp_.trapped_hold > 0 && trapped(t, bs)) {
    o_.ended_by = "trapped";
  } else if (o_.contact && !o_.lifted_off_clear && t >= o_.t_contact + sp_.max_after_contact) {
    o_.ended_by = "max_after_contact";
  } else if (!o_.contact && t - t_start_ >= sp_.max_time) {
    o_.ended_by = "max_time";
  }
  return ended();
}

bool LandingTracker::trapped(double t, const BodyState& bs) {
  const double need = bm_.mass * std::max(0.0, -g_.z()) *  // potential energy to lift off
                      std::max(0.0, sp_.rim + liftoff_com_ - bs.pos.z());
  if (body_lin_energy(bm_, bs) + body_rot_energy(bm_, bs) < 0.5 * need) {
    if (trapped_since_ < 0) trapped_since_ = t;
  } else {
    trapped_since_ = -1;
  }
  return trapped_since_ >= 0 && t >= trapped_since_ + sp_.trapped_hold;
}

void LandingTracker::finish(double t) {
  if (!o_.lifted_off) o_.v_out = 0;
  if (!o_.lifted_off_clear) o_.clear = Departure();
  o_.t_end = t;
  if (o_.contact) {
    o_.speed_ratio = o_.v_in > 0 ? o_.v_out / o_.v_in : 0;
    o_.collision_duration = (o_.lifted_off ? o_.t_liftoff : t) - o_.t_contact;
    o_.speed_ratio_clear = o_.v_in > 0 ? o_.clear.v_out / o_.v_in : 0;
    o_.collision_duration_clear = (o_.lifted_off_clear ? o_.t_liftoff_clear : t) - o_.t_contact;
    if (o_.e_lin_in > 0) {
      o_.rot_out_over_lin_in = o_.e_rot_out / o_.e_lin_in;
      o_.energy_ratio = (o_.e_lin_out + o_.e_rot_out) / (o_.e_lin_in + o_.e_rot_in);
    }
    if (o_.e_lin_out > 0) o_.rot_out_over_lin_out = o_.e_rot_out / o_.e_lin_out;
  }
}

void landing_outcome_json(const LandingOutcome& o, JsonObject& oc) {
  oc.boolean("contact", o.contact).boolean("lifted_off", o.lifted_off).str("ended_by", o.ended_by);
  oc.num("t_contact", o.t_contact).num("t_liftoff", o.t_liftoff).num("t_end", o.t_end);
  oc.num("v_in", o.v_in).num("v_out", o.v_out).num("speed_ratio", o.speed_ratio);
  oc.num("E_lin_in", o.e_lin_in).num("E_rot_in", o.e_rot_in).num("E_lin_out", o.e_lin_out).num("E_rot_out", o.e_rot_out);
  oc.num("E_rot_out_over_E_lin_in", o.rot_out_over_lin_in).num("E_rot_out_over_E_lin_out", o.rot_out_over_lin_out);
  oc.num("energy_ratio", o.energy_ratio).num("angle_out_deg", o.angle_out_deg).num("spin_out", o.spin_out);
  oc.num("collision_duration", o.collision_duration).num("max_penetration", o.max_penetration);
  oc.num("h_liftoff", o.h_liftoff).num("travel_distance", o.travel_distance).num("travel_time", o.travel_time);
  oc.num("second_impact_speed", o.second_impact_speed).num("second_impact_angle_deg", o.second_impact_angle_deg);
  // The clear lift-off (variant; it also ends the run).
  JsonObject c;
  c.boolean("lifted_off", o.lifted_off_clear).num("cancelled_liftoffs", o.relandings);
  c.num("t_liftoff", o.t_liftoff_clear).num("v_out", o.clear.v_out).num("speed_ratio", o.speed_ratio_clear);
  c.num("collision_duration", o.collision_duration_clear).num("angle_out_deg", o.clear.angle_out_deg);
  c.num("spin_out", o.clear.spin_out).num("h_liftoff", o.clear.h_liftoff);
  c.num("travel_distance", o.clear.travel_distance).num("travel_time", o.clear.travel_time);
  oc.obj("clear_liftoff", c);
}

// --- the tracker as an observer ---------------------------------------------------

void LandingTrackerObserver::start(const Model& m, const State& s) {
  tracker_ = std::make_unique<LandingTracker>(m.bodies[b_], sp_, m.gravity, s.time);
}

bool LandingTrackerObserver::after_step(const Model& m, const State& s) {
  max_overlap_ = std::max(max_overlap_, s.stats.max_overlap_ratio);
  return tracker_->update(s.time, s.bodies[b_], body_contacts(s, b_, bed_top_));
}

void LandingTrackerObserver::columns(std::vector<std::string>& out) const {
  for (const char* c : {"x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "lowest_corner", "grain_contacts",
                        "body_contacts", "fx", "fy", "fz", "E_lin", "E_rot", "max_overlap_ratio"})
    out.push_back(c);
}

void LandingTrackerObserver::row(const Model& m, const State& s, std::vector<double>& out) const {
  const BodyModel& bm = m.bodies[b_];
  const BodyState& bs = s.bodies[b_];
  out.insert(out.end(), {bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.vel.x(), bs.vel.y(), bs.vel.z(), bs.omega.x(),
                         bs.omega.y(), bs.omega.z(), tracker_->lowest_corner(bs), double(s.stats.body_contacts),
                         double(s.stats.body_body_contacts), bs.force.x(), bs.force.y(), bs.force.z(),
                         body_lin_energy(bm, bs), body_rot_energy(bm, bs), s.stats.max_overlap_ratio});
}

void LandingTrackerObserver::finish(const Model& m, const State& s) {
  tracker_->finish(s.time);
  double sum = 0;
  long cnt = 0;
  for (int i = 0; i < m.n_grains; ++i)
    if (std::hypot(s.pos[i].x(), s.pos[i].y()) > sp_.container_radius - sp_.far_ring) {
      sum += s.vel[i].squaredNorm();
      ++cnt;
    }
  far_field_rms_ = cnt ? std::sqrt(sum / cnt) : 0;
}

std::string LandingTrackerObserver::progress(const Model& m, const State& s) const {
  const BodyState& bs = s.bodies[b_];
  char b[160];
  std::snprintf(b, sizeof b, "%s  speed %.4g m/s  lowest corner %+.4f m  %d grain contacts", tracker_->phase(),
                bs.vel.norm(), tracker_->lowest_corner(bs), int(s.stats.body_contacts));
  return b;
}

double LandingTrackerObserver::time_left(const State& s) const {
  const LandingOutcome& o = tracker_->outcome();
  if (!o.contact) return -1;
  return (!o.lifted_off_clear ? o.t_contact + sp_.max_after_contact : o.t_liftoff_clear + sp_.after_liftoff) -
         s.time;
}

double LandingTrackerObserver::expected_time_left(const State& s) const {
  return tracker_->expected_time_left(s.time, s.bodies[b_]);
}

LandingOutcome run_landing(Model& m, State& s, int b, const LandingSpec& sp, const LandingOptions& opt) {
  LandingScene scene;
  scene.sc.name = "landing";
  scene.sc.model = m;  // for the summary's run figures
  scene.lander = b;
  scene.spec = scene.run_spec = sp;
  scene.plan = RunPlan::open_ended("landing", "landing");
  scene.sample_every = sp.sample_every;
  SceneRunOptions ro;
  ro.out_dir = opt.out_dir;
  ro.progress_every = opt.progress_every;
  std::unique_ptr<SceneRun> sr;
  const RunReport rep = run_scene(scene, m, s, ro, &sr);
  return static_cast<const LandingRun&>(*sr).outcome(rep, true);
}

}  // namespace rt
