// Reusable observers: body contacts, ejecta, active zone, surface height map,
// region count (see their headers in observers/).
#include <cmath>
#include <sstream>

#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/types.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/observers/active_zone.hpp"
#include "regolith_twin/observers/body_contacts.hpp"
#include "regolith_twin/observers/ejecta.hpp"
#include "regolith_twin/observers/escape.hpp"
#include "regolith_twin/observers/region_count.hpp"
#include "regolith_twin/observers/surface_map.hpp"

namespace rt {

BodyContacts body_contacts(const State& s, int b, double bed_top) {
  BodyContacts c;
  const BodyGrainList& bl = s.body_grains;
  for (int k = 0; k < bl.size(); ++k)
    if (bl.touching[k] && bl.body[k] == b) {
      ++c.total;
      c.bed += s.pos[bl.grain[k]].z() <= bed_top;
    }
  for (const BodyPointContact& p : s.body_points)
    if (p.a == b || p.b == b) {
      ++c.total;
      ++c.bed;
    }
  return c;
}

// --- ejecta ---------------------------------------------------------------------

void Ejecta::start(const Model& m, const State& s) {
  flag_.assign(m.n_grains, 0);
  above0_.assign(m.n_grains, 0);
  for (int i = 0; i < m.n_grains; ++i) above0_[i] = s.pos[i].z() > height_;  // not counted
  count_ = 0;
  volume_ = 0;
}

bool Ejecta::after_step(const Model& m, const State& s) {
  if (!ticks_crossed(s, every_)) return false;
  for (int i = 0; i < m.n_grains; ++i)
    if (!flag_[i] && !above0_[i] && s.pos[i].z() > height_) {
      flag_[i] = 1;
      ++count_;
      volume_ += 4.0 / 3.0 * kPi * std::pow(m.grain_radius[i], 3);
    }
  return false;
}

// --- active zone ----------------------------------------------------------------

void ActiveZone::prepare(Model& m, State& s) {
  // Grains another policy holds at the start (glued by the scene) are left alone.
  fixed0_.assign(m.n_grains, 0);
  for (int i = 0; i < m.n_grains; ++i) fixed0_[i] = held(m, i);
  woken_.assign(m.n_grains, 0);
  update(m, s, s.bodies[body_].pos, true);
  // Lists and forces for the frozen model (and any rebuild already pending).
  if (s.rebuild_requested) s.forces_valid = false;
}

void ActiveZone::after_measures(Model& m, State& s) {
  if (ticks_crossed(s, every_)) update(m, s, s.bodies[body_].pos, false);
}

// Update around horizontal position c; returns true when grains changed state.
bool ActiveZone::update(Model& m, State& s, const Vec3& c, bool first) {
  if (radius_ <= 0) return false;
  if (!first && std::hypot(c.x() - last_.x(), c.y() - last_.y()) < 0.02) return false;
  last_ = c;
  bool changed = false;
  for (int i = 0; i < m.n_grains; ++i) {
    if (fixed0_[i] || woken_[i]) continue;
    const bool inside = std::hypot(s.pos[i].x() - c.x(), s.pos[i].y() - c.y()) < radius_;
    if (inside) {
      woken_[i] = 1;
      release_grain(m, i, kHoldOutsideZone);
      changed = changed || !first;
    } else if (first) {
      hold_grain(m, s, i, kHoldOutsideZone);
      changed = true;
    }
  }
  if (changed) s.rebuild_requested = true;  // pair constants (m*) and partitions follow
  return changed;
}

void ActiveZone::finish(Model& m, State& s) {
  double sum = 0;
  long cnt = 0;
  active_ = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    active_ += !held(m, i);
    const double d = std::hypot(s.pos[i].x() - last_.x(), s.pos[i].y() - last_.y());
    const bool ejected = ejecta_ && ejecta_->ejected(i);
    if (radius_ > 0 && !held(m, i) && !ejected && d > radius_ - ring_) {
      sum += s.vel[i].squaredNorm();
      ++cnt;
    }
  }
  edge_rms_ = cnt ? std::sqrt(sum / cnt) : 0;
}

// --- surface height map ---------------------------------------------------------

void write_surface(const std::string& path, const Model& m, const State& s, double half, double reference,
                   double cell) {
  const int n = int(std::ceil(2 * half / cell));
  std::vector<double> top(size_t(n) * n, -1e300);
  for (int i = 0; i < m.n_grains; ++i) {
    const int ix = int((s.pos[i].x() + half) / cell), iy = int((s.pos[i].y() + half) / cell);
    if (ix < 0 || iy < 0 || ix >= n || iy >= n) continue;
    double& t = top[size_t(iy) * n + ix];
    t = std::max(t, s.pos[i].z() + m.grain_radius[i] - reference);
  }
  std::ostringstream out;  // written whole at the end (docs/files.md, outputs)
  out << "x,y,height\n";
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const double t = top[size_t(iy) * n + ix];
      if (t < -1e299) continue;
      out << (ix + 0.5) * cell - half << ',' << (iy + 0.5) * cell - half << ',' << t << '\n';
    }
  write_file(path, out.str());
}

// --- region count ---------------------------------------------------------------

void RegionCount::count(const Model& m, const State& s) {
  n_ = 0;
  mass_ = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    const Vec3& p = s.pos[i];
    if ((p.array() >= lo_.array()).all() && (p.array() <= hi_.array()).all()) {
      ++n_;
      mass_ += m.grain_mass[i];
    }
  }
}

void RegionCount::columns(std::vector<std::string>& out) const {
  out.push_back(name_ + "_count");
  out.push_back(name_ + "_mass");
}

void RegionCount::row(const Model& m, const State& s, std::vector<double>& out) const {
  out.push_back(double(n_));
  out.push_back(mass_);
}

}  // namespace rt

// --- grains leaving the scene ---------------------------------------------------

namespace rt {

bool Escape::leaving(const Model& m, const State& s, std::vector<uint8_t>& drop) {
  if (!ticks_crossed(s, every_)) return false;
  bool any = false;
  for (int i = 0; i < m.n_grains; ++i) {
    const Vec3& p = s.pos[i];
    if ((p.array() >= lo_.array()).all() && (p.array() <= hi_.array()).all()) continue;
    // The face crossed farthest, relative to the box size.
    const Vec3 size = (hi_ - lo_).cwiseMax(Vec3::Constant(1e-300));
    int face = 0;
    double worst = -1;
    for (int d = 0; d < 3; ++d) {
      const double below = (lo_[d] - p[d]) / size[d], above = (p[d] - hi_[d]) / size[d];
      if (below > worst) worst = below, face = 2 * d;
      if (above > worst) worst = above, face = 2 * d + 1;
    }
    exits_.push_back({s.time, face, m.grain_mass[i], p, s.vel[i]});
    mass_ += m.grain_mass[i];
    face_mass_[face] += m.grain_mass[i];
    drop[i] = 1;
    any = true;
  }
  return any;
}

void Escape::columns(std::vector<std::string>& out) const {
  out.push_back("escaped_grains");
  out.push_back("escaped_mass");
}

void Escape::row(const Model& m, const State& s, std::vector<double>& out) const {
  out.push_back(double(exits_.size()));
  out.push_back(mass_);
}

void Escape::finish(const Model& m, const State& s) {
  if (log_.empty()) return;
  std::ostringstream f;  // written whole at the end (docs/files.md, outputs)
  static const char* names[] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  f << "t,face,mass,x,y,z,vx,vy,vz\n";
  f.precision(10);
  for (const Exit& e : exits_)
    f << e.t << ',' << names[e.face] << ',' << e.mass << ',' << e.pos.x() << ',' << e.pos.y() << ',' << e.pos.z()
      << ',' << e.vel.x() << ',' << e.vel.y() << ',' << e.vel.z() << '\n';
  write_file(log_, f.str());
}

void Escape::summary(JsonObject& out) const {
  out.num("escaped_grains", double(exits_.size())).num("escaped_mass", mass_);
  out.num("escaped_mass_top", face_mass_[ZMax]);
}

// --- renumbering after removals -------------------------------------------------

void Ejecta::grains_removed(const std::vector<int>& old_to_new) {
  renumber_grains(flag_, old_to_new);
  renumber_grains(above0_, old_to_new);
}

void ActiveZone::grains_removed(const std::vector<int>& old_to_new) {
  renumber_grains(fixed0_, old_to_new);
  renumber_grains(woken_, old_to_new);
}

}  // namespace rt
