// Grains in the sampler horn (see horn_segments.hpp).
#include "regolith_twin/scenes/sampler/horn_segments.hpp"
#include "regolith_twin/core/hold.hpp"

#include <cstdio>

#include "regolith_twin/core/edit.hpp"

namespace rt {

void HornSegments::count(const Model& m, const State& s) {
  const long top_count = c_.top_count;
  const double top_mass = c_.top_mass;
  c_ = HornCount{};
  c_.top_count = top_count;
  c_.top_mass = top_mass;
  for (int i = 0; i < m.n_grains; ++i) {
    if (not_bed_(i) || held(m, i)) continue;
    const int k = g_.segment_of(s.pos[i]);
    if (k < 0) continue;
    ++c_.count[k];
    c_.mass[k] += 1 / m.grain_inv_mass[i];
  }
  if (t_met_ < 0 && c_.collected_mass() >= requirement_) t_met_ = s.time;
}

bool HornSegments::leaving(const Model& m, const State& s, std::vector<uint8_t>& drop) {
  if (!ticks_crossed(s, every_)) return false;
  bool any = false;
  const double top = g_.top(), rt = g_.top_radius();
  for (int i = 0; i < m.n_grains; ++i) {
    if (not_bed_(i) || held(m, i) || drop[i]) continue;
    if (g_.axial(s.pos[i]) <= top || g_.radial(s.pos[i]) >= rt + m.grain_radius[i]) continue;
    drop[i] = 1;
    any = true;
    const double mass = 1 / m.grain_inv_mass[i];
    exits_.push_back({s.time, mass, s.pos[i], s.vel[i]});
    ++c_.top_count;
    c_.top_mass += mass;
  }
  count(m, s);  // grains leaving now are above the top, outside every segment
  return any;
}

void HornSegments::grains_removed(const std::vector<int>& old_to_new) { not_bed_.removed(old_to_new); }

void HornSegments::columns(std::vector<std::string>& out) const {
  for (int k = 1; k <= 5; ++k) out.push_back("seg" + std::to_string(k) + "_n");
  for (int k = 1; k <= 5; ++k) out.push_back("seg" + std::to_string(k) + "_mass");
  out.push_back("collected_top_n");
  out.push_back("collected_mass");
}

void HornSegments::row(const Model& m, const State& s, std::vector<double>& out) const {
  for (int k = 0; k < 5; ++k) out.push_back(double(c_.count[k]));
  for (int k = 0; k < 5; ++k) out.push_back(c_.mass[k]);
  out.push_back(double(c_.top_count));
  out.push_back(c_.collected_mass());
}

void HornSegments::summary(JsonObject& out) const {
  JsonObject h;
  std::vector<double> n, ms;
  for (int k = 0; k < 5; ++k) {
    n.push_back(double(c_.count[k]));
    ms.push_back(c_.mass[k]);
  }
  h.nums("segment_grains", n).nums("segment_mass", ms);
  h.num("collected_top_grains", double(c_.top_count)).num("collected_top_mass", c_.top_mass);
  h.num("collected_mass", c_.collected_mass()).num("requirement", requirement_);
  h.boolean("requirement_met", c_.collected_mass() >= requirement_).num("time_met", t_met_);
  out.obj("horn", h);
}

std::string HornSegments::progress(const Model& m, const State& s) const {
  char b[96];
  std::snprintf(b, sizeof b, "horn %ld/%ld/%ld/%ld/%ld grains, collected %.3g mg", c_.count[0], c_.count[1],
                c_.count[2], c_.count[3], c_.count[4], c_.collected_mass() * 1e6);
  return b;
}

void HornSegments::write_csv(const std::string& path) const {
  std::string text = "t,mass,x,y,z,vx,vy,vz\n";  // written whole (docs/files.md, outputs)
  char line[192];
  for (const Exit& e : exits_) {
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", e.t, e.mass, e.pos.x(), e.pos.y(),
                  e.pos.z(), e.vel.x(), e.vel.y(), e.vel.z());
    text += line;
  }
  write_file(path, text);
}

}  // namespace rt
