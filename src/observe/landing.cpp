// Lander scenes: placement, perturbed beds and the landing outcome
// (SCENARIOS.md A). See landing.hpp.
#include "regolith_twin/observe/landing.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/observe/series.hpp"

namespace rt {
namespace {

constexpr double kDeg = M_PI / 180.0;

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
        const double a = 2 * M_PI * k / 72;
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

// Helpers for the landing block: numbers with ranges, errors naming file and key.
struct BlockReader {
  const YAML::Node& n;
  const std::string& src;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(src + ": key 'landing." + key + "': " + what);
  }
  double num(const std::string& key, double dflt, double lo, double hi) const {
    if (!n[key]) return dflt;
    double v = 0;
    try {
      v = n[key].as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    if (!std::isfinite(v) || v < lo || v > hi)
      fail(key, "value " + n[key].Scalar() + " out of range (allowed [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "])");
    return v;
  }
};

}  // namespace

LandingSpec parse_landing(const YAML::Node& n, const std::string& src) {
  LandingSpec sp;
  if (!n || !n.IsMap()) throw InputError(src + ": key 'landing': missing or not a mapping");
  const std::vector<std::string> keys = {"lander", "rim", "container_radius", "attitude", "pitch_deg", "roll_deg",
                                         "angle_deg", "heading_deg", "speed", "clearance", "aim", "slope_deg", "g",
                                         "after_liftoff", "max_after_contact", "max_time", "far_ring",
                                         "sphere_radius", "repeat", "perturb_seed", "sample_every",
                                         "active_radius", "trapped_hold"};
  BlockReader rd{n, src};
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) {
      std::string list;
      for (const auto& a : keys) list += (list.empty() ? "" : ", ") + a;
      rd.fail(k, "unknown key (allowed here: " + list + ")");
    }
  }
  if (!n["lander"]) rd.fail("lander", "missing (name of the lander body under 'bodies')");
  sp.lander = n["lander"].as<std::string>();
  sp.rim = rd.num("rim", sp.rim, -1e3, 1e3);
  sp.container_radius = rd.num("container_radius", sp.container_radius, 0.01, 1e3);
  if (n["attitude"]) {
    const std::string a = n["attitude"].as<std::string>();
    if (a == "Flat" || a == "flat") sp.attitude = Attitude::Flat;
    else if (a == "BCF" || a == "bcf") sp.attitude = Attitude::BCF;
    else if (a == "FCF" || a == "fcf") sp.attitude = Attitude::FCF;
    else rd.fail("attitude", "'" + a + "' is not one of: Flat, BCF, FCF");
  }
  sp.pitch_deg = rd.num("pitch_deg", sp.pitch_deg, 0, 80);
  sp.roll_deg = rd.num("roll_deg", sp.roll_deg, 0, 80);
  sp.angle_deg = rd.num("angle_deg", sp.angle_deg, 0, 85);
  sp.heading_deg = rd.num("heading_deg", sp.heading_deg, -360, 360);
  sp.speed = rd.num("speed", sp.speed, 1e-6, 1e4);
  sp.clearance = rd.num("clearance", sp.clearance, 0, 10);
  if (n["aim"]) {
    if (!n["aim"].IsSequence() || n["aim"].size() != 2) rd.fail("aim", "expected [x, y] on the trim plane, m");
    sp.aim = Vec3(n["aim"][0].as<double>(), n["aim"][1].as<double>(), 0);
  }
  sp.slope_deg = rd.num("slope_deg", sp.slope_deg, -60, 60);
  sp.g = rd.num("g", sp.g, 0, 100);
  sp.after_liftoff = rd.num("after_liftoff", sp.after_liftoff, 0, 1e4);
  sp.max_after_contact = rd.num("max_after_contact", sp.max_after_contact, 0, 1e5);
  sp.max_time = rd.num("max_time", sp.max_time, 0, 1e6);
  sp.far_ring = rd.num("far_ring", sp.far_ring, 0, 1e3);
  sp.sphere_radius = rd.num("sphere_radius", sp.sphere_radius, 0, 1e3);
  sp.repeat = long(rd.num("repeat", 0, 0, 1e6));
  sp.perturb_seed = (unsigned long)rd.num("perturb_seed", 1, 0, 4e9);
  sp.sample_every = rd.num("sample_every", sp.sample_every, 1e-6, 1e3);
  sp.active_radius = rd.num("active_radius", sp.active_radius, 0, 1e3);
  sp.trapped_hold = rd.num("trapped_hold", sp.trapped_hold, 0, 1e5);
  return sp;
}

Vec3 landing_gravity(const LandingSpec& sp) {
  // Upslope (positive): gravity gains a component against the motion.
  const double s = sp.slope_deg * kDeg;
  return sp.g * (-std::cos(s) * Vec3::UnitZ() - std::sin(s) * heading_dir(sp));
}

void rotate_bed(const Model& m, State& s, double angle) {
  const Quat r(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
  const Mat3 R = r.toRotationMatrix();
  for (int i = 0; i < m.n_grains; ++i) {
    s.pos[i] = R * s.pos[i];
    s.vel[i] = R * s.vel[i];
    s.omega[i] = R * s.omega[i];
    s.vel_mid[i] = R * s.vel_mid[i];
    s.omega_mid[i] = R * s.omega_mid[i];
    s.force[i] = R * s.force[i];
    s.torque[i] = R * s.torque[i];
    s.pos_at_build[i] = R * s.pos_at_build[i];
  }
  for (auto* l : {&s.pairs.spring_t, &s.pairs.spring_r, &s.wall_pairs.spring_t, &s.wall_pairs.spring_r})
    for (Vec3& v : *l) v = R * v;
}

Perturbation perturbation(const LandingSpec& sp, double mean_radius) {
  Perturbation p;
  if (sp.repeat <= 0) return p;
  std::mt19937_64 rng(sp.perturb_seed * 1000003ULL + static_cast<unsigned long>(sp.repeat));
  std::uniform_real_distribution<double> u(0, 1);
  p.angle = 2 * M_PI * u(rng);
  const double rad = 2 * mean_radius * std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);  // uniform in a disk of one diameter
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
        const ShapeGap g = shape_gap(bm, sh, p, m.grain_radius[i]);
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

std::vector<Vec3> lander_corners(const Model& m, const State& s, int b) {
  const BodyModel& bm = m.bodies[b];
  const BodyState& bs = s.bodies[b];
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

void write_surface(const std::string& path, const Model& m, const State& s, const LandingSpec& sp, double cell) {
  const int n = int(std::ceil(2 * sp.container_radius / cell));
  std::vector<double> top(size_t(n) * n, -1e300);
  for (int i = 0; i < m.n_grains; ++i) {
    const int ix = int((s.pos[i].x() + sp.container_radius) / cell), iy = int((s.pos[i].y() + sp.container_radius) / cell);
    if (ix < 0 || iy < 0 || ix >= n || iy >= n) continue;
    double& t = top[size_t(iy) * n + ix];
    t = std::max(t, s.pos[i].z() + m.grain_radius[i] - sp.rim);
  }
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write the surface height map");
  out << "x,y,height\n";
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const double t = top[size_t(iy) * n + ix];
      if (t < -1e299) continue;
      out << (ix + 0.5) * cell - sp.container_radius << ',' << (iy + 0.5) * cell - sp.container_radius << ',' << t
          << '\n';
    }
}

namespace {

// Active zone: freeze grains (infinite mass, at rest) beyond the radius from
// the lander's vertical axis, wake those it reaches; woken grains stay free.
class ActiveZone {
 public:
  ActiveZone(Model& m, double radius) : m_(m), radius_(radius) {
    inv_mass_ = m.grain_inv_mass;
    inv_inertia_ = m.grain_inv_inertia;
    fixed0_ = m.grain_fixed;
    woken_.assign(m.n_grains, 0);
  }
  // Update around horizontal position c; returns true when grains changed state.
  bool update(State& s, const Vec3& c, bool first) {
    if (radius_ <= 0) return false;
    if (!first && std::hypot(c.x() - last_.x(), c.y() - last_.y()) < 0.02) return false;
    last_ = c;
    bool changed = false;
    for (int i = 0; i < m_.n_grains; ++i) {
      if (fixed0_[i] || woken_[i]) continue;
      const bool inside = std::hypot(s.pos[i].x() - c.x(), s.pos[i].y() - c.y()) < radius_;
      if (inside) {
        woken_[i] = 1;
        m_.grain_fixed[i] = 0;
        m_.grain_inv_mass[i] = inv_mass_[i];
        m_.grain_inv_inertia[i] = inv_inertia_[i];
        changed = changed || !first;
      } else if (first) {
        m_.grain_fixed[i] = 1;
        m_.grain_inv_mass[i] = 0;
        m_.grain_inv_inertia[i] = 0;
        s.vel[i].setZero();
        s.omega[i].setZero();
        changed = true;
      }
    }
    if (changed) s.rebuild_requested = true;  // pair constants (m*) and partitions follow
    return changed;
  }
  double radius() const { return radius_; }
  const Vec3& centre() const { return last_; }

 private:
  Model& m_;
  double radius_;
  std::vector<double> inv_mass_, inv_inertia_;
  std::vector<uint8_t> fixed0_, woken_;
  Vec3 last_ = Vec3::Zero();
};

}  // namespace

LandingOutcome run_landing(Model& m, State& s, int b, const LandingSpec& sp, const LandingOptions& opt) {
  using Clock = std::chrono::steady_clock;
  LandingOutcome o;
  const BodyModel& bm = m.bodies[b];
  const auto t0 = Clock::now();
  auto last_progress = t0;
  const double t_start = s.time;
  const long step0 = s.step;
  CsvSeries series;
  const bool write = !opt.out_dir.empty();
  if (write)
    series.open(opt.out_dir + "/series.csv",
                {"t", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "lowest_corner", "grain_contacts",
                 "body_contacts", "fx", "fy", "fz", "E_lin", "E_rot", "max_overlap_ratio", "ejected_grains"});
  double mean_r = 0;
  for (int i = 0; i < m.n_grains; ++i) mean_r += m.grain_radius[i];
  mean_r = m.n_grains ? mean_r / m.n_grains : 0;
  std::vector<uint8_t> ejected(m.n_grains, 0), above0(m.n_grains, 0);
  for (int i = 0; i < m.n_grains; ++i) above0[i] = s.pos[i].z() > sp.rim + mean_r;  // not counted
  ActiveZone zone(m, sp.active_radius);
  zone.update(s, s.bodies[b].pos, true);
  if (!s.forces_valid || s.rebuild_requested) prime(m, s);
  const int check_every = std::max(1, int(std::lround(1e-3 / m.dt)));  // ejecta sampled each millisecond
  double next_sample = s.time;
  const BodyState& bs = s.bodies[b];
  // Lowest height of the centre of mass above the trim plane at which every
  // corner can be above it, and the time since the lander became trapped.
  double liftoff_com = 0;
  if (const int k = largest_box(bm); k >= 0)
    liftoff_com = std::max(0.0, bm.shapes[k].size.minCoeff() - bm.shapes[k].pos.norm());
  double trapped_since = -1;
  auto lowest_corner = [&] {
    double low = 1e300;
    for (const Vec3& c : lander_corners(m, s, b)) low = std::min(low, c.z() - sp.rim);
    return low;
  };
  try {
    for (;;) {
      if (write && s.time >= next_sample - 0.5 * m.dt) {
        next_sample += sp.sample_every;
        series.row({s.time, bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.vel.x(), bs.vel.y(), bs.vel.z(), bs.omega.x(),
                    bs.omega.y(), bs.omega.z(), lowest_corner(), double(s.stats.body_contacts),
                    double(s.stats.body_body_contacts), bs.force.x(), bs.force.y(), bs.force.z(),
                    body_lin_energy(bm, bs), body_rot_energy(bm, bs), s.stats.max_overlap_ratio,
                    double(o.ejected_grains)});
      }
      step(m, s);
      o.max_overlap_ratio = std::max(o.max_overlap_ratio, s.stats.max_overlap_ratio);
      const bool touching = s.stats.body_contacts > 0 || s.stats.body_body_contacts > 0;
      const double low = lowest_corner();
      if (!o.contact && touching) {
        o.contact = true;
        o.t_contact = s.time;
        o.v_in = bs.vel.norm();
        o.e_lin_in = body_lin_energy(bm, bs);
        o.e_rot_in = body_rot_energy(bm, bs);
      }
      if (o.lifted_off && touching) {
        // Contact again within the after-lift-off window with the bed (a body,
        // or a grain that is not ejecta): the lander had not left; the
        // collision goes on (decision, documented in landing.hpp). Ejected
        // grains drifting with the lander do not count.
        bool bed_contact = s.stats.body_body_contacts > 0;
        const BodyGrainList& bl = s.body_grains;
        for (int k = 0; k < bl.size() && !bed_contact; ++k)
          bed_contact = bl.touching[k] && bl.body[k] == b && s.pos[bl.grain[k]].z() <= sp.rim + mean_r;
        if (bed_contact) {
          o.lifted_off = false;
          ++o.relandings;
        }
      }
      if (o.contact && !o.lifted_off) {
        o.max_penetration = std::max(o.max_penetration, -low);
        // Lift-off: every corner above the trim plane, no contact, and the
        // centre of mass moving away from the surface.
        const bool up = low > 0 && !touching && bs.vel.z() > 0;
        if (up) {
          o.lifted_off = true;
          o.t_liftoff = s.time;
          o.v_out = bs.vel.norm();
          o.e_lin_out = body_lin_energy(bm, bs);
          o.e_rot_out = body_rot_energy(bm, bs);
          o.spin_out = bs.omega.norm();
          o.angle_out_deg = std::acos(std::clamp(bs.vel.z() / std::max(o.v_out, 1e-300), -1.0, 1.0)) / kDeg;
          o.h_liftoff = bs.pos.z() - sp.rim;
          // Ballistic flight under the (possibly tilted) gravity, heights normal to the trim plane.
          const Vec3 g = m.gravity, v0 = bs.vel;
          const double gn = g.z(), vn = v0.z();
          double ht = std::max(o.h_liftoff, sp.sphere_radius);
          double disc = vn * vn + 2 * gn * (ht - o.h_liftoff);
          if (disc < 0) {  // apex below the sphere radius: back to the lift-off height instead
            ht = o.h_liftoff;
            disc = vn * vn;
          }
          if (gn < 0) {
            const double t = (-vn - std::sqrt(disc)) / gn;
            const Vec3 d = v0 * t + 0.5 * g * t * t;
            o.travel_time = t;
            o.travel_distance = std::hypot(d.x(), d.y());
            const Vec3 v1 = v0 + g * t;
            o.second_impact_speed = v1.norm();
            o.second_impact_angle_deg = std::acos(std::min(1.0, std::fabs(v1.z()) / v1.norm())) / kDeg;
          }
        }
      }
      if (s.step % check_every == 0) zone.update(s, bs.pos, false);
      if (s.step % check_every == 0)
        for (int i = 0; i < m.n_grains; ++i)
          if (!ejected[i] && !above0[i] && s.pos[i].z() > sp.rim + mean_r) {
            ejected[i] = 1;
            ++o.ejected_grains;
            o.ejected_volume += 4.0 / 3.0 * M_PI * std::pow(m.grain_radius[i], 3);
          }
      if (o.lifted_off && s.time >= o.t_liftoff + sp.after_liftoff) {
        o.ended_by = "after_liftoff";
        break;
      }
      if (o.contact && !o.lifted_off && sp.trapped_hold > 0) {
        const double need = bm.mass * std::max(0.0, -m.gravity.z()) *  // potential energy to lift off
                            std::max(0.0, sp.rim + liftoff_com - bs.pos.z());
        if (body_lin_energy(bm, bs) + body_rot_energy(bm, bs) < 0.5 * need) {
          if (trapped_since < 0) trapped_since = s.time;
        } else {
          trapped_since = -1;
        }
        if (trapped_since >= 0 && s.time >= trapped_since + sp.trapped_hold) {
          o.ended_by = "trapped";
          break;
        }
      }
      if (o.contact && !o.lifted_off && s.time >= o.t_contact + sp.max_after_contact) {
        o.ended_by = "max_after_contact";
        break;
      }
      if (!o.contact && s.time - t_start >= sp.max_time) {
        o.ended_by = "max_time";
        break;
      }
      if (opt.progress_every > 0) {
        const auto now = Clock::now();
        if (std::chrono::duration<double>(now - last_progress).count() >= opt.progress_every) {
          last_progress = now;
          const double wall = std::chrono::duration<double>(now - t0).count();
          const char* phase = !o.contact ? "approach" : (!o.lifted_off ? "collision" : "after lift-off");
          double left = !o.contact ? 0 : (!o.lifted_off ? o.t_contact + sp.max_after_contact : o.t_liftoff + sp.after_liftoff) - s.time;
          const double rate = (s.time - t_start) / std::max(wall, 1e-9);
          std::fprintf(stderr,
                       "[landing] %s  t = %.4g s  speed %.4g m/s  lowest corner %+.4f m  %d grain contacts  %.3g steps/s  "
                       "%s%.0f s\n",
                       phase, s.time, bs.vel.norm(), low, int(s.stats.body_contacts),
                       double(s.step - step0) / std::max(wall, 1e-9), !o.contact ? "" : "at most ",
                       left / std::max(rate, 1e-300));
        }
      }
    }
  } catch (const BlowUpError& e) {
    o.status = "blow_up";
    o.message = e.what();
  }
  if (!o.lifted_off) o.v_out = 0;
  o.t_end = s.time;
  if (o.contact) {
    o.speed_ratio = o.v_in > 0 ? o.v_out / o.v_in : 0;
    o.collision_duration = (o.lifted_off ? o.t_liftoff : s.time) - o.t_contact;
    if (o.e_lin_in > 0) {
      o.rot_out_over_lin_in = o.e_rot_out / o.e_lin_in;
      o.energy_ratio = (o.e_lin_out + o.e_rot_out) / (o.e_lin_in + o.e_rot_in);
    }
    if (o.e_lin_out > 0) o.rot_out_over_lin_out = o.e_rot_out / o.e_lin_out;
  }
  // Far-field quiet check: RMS grain speed in the outermost ring.
  double sum = 0;
  long cnt = 0;
  for (int i = 0; i < m.n_grains; ++i)
    if (std::hypot(s.pos[i].x(), s.pos[i].y()) > sp.container_radius - sp.far_ring) {
      sum += s.vel[i].squaredNorm();
      ++cnt;
    }
  o.far_field_rms = cnt ? std::sqrt(sum / cnt) : 0;
  sum = 0;
  cnt = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    o.active_grains += m.grain_inv_mass[i] != 0;
    const double d = std::hypot(s.pos[i].x() - zone.centre().x(), s.pos[i].y() - zone.centre().y());
    if (zone.radius() > 0 && m.grain_inv_mass[i] != 0 && !ejected[i] && d > zone.radius() - sp.far_ring) {
      sum += s.vel[i].squaredNorm();
      ++cnt;
    }
  }
  o.active_edge_rms = cnt ? std::sqrt(sum / cnt) : 0;
  o.steps = s.step - step0;
  o.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (write && o.status == "ok")
    series.row({s.time, bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.vel.x(), bs.vel.y(), bs.vel.z(), bs.omega.x(),
                bs.omega.y(), bs.omega.z(), lowest_corner(), double(s.stats.body_contacts),
                double(s.stats.body_body_contacts), bs.force.x(), bs.force.y(), bs.force.z(),
                body_lin_energy(bm, bs), body_rot_energy(bm, bs), s.stats.max_overlap_ratio,
                double(o.ejected_grains)});
  return o;
}

}  // namespace rt
