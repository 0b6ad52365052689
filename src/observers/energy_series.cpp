// Energy series of a plain scenario (see energy_series.hpp).
#include "regolith_twin/observers/energy_series.hpp"

#include <limits>

namespace rt {

Vec3 EnergySeries::group_mean(const std::vector<Vec3>& a, const GrainGroup& g) {
  if (g.count == 0) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  // every grain left
  Vec3 c = Vec3::Zero();
  for (int i = g.first; i < g.first + g.count; ++i) c += a[i];
  return c / g.count;
}

std::vector<const GrainGroup*> EnergySeries::tracked() const {
  std::vector<const GrainGroup*> out;
  for (const std::string& n : tracked_names_)
    for (const GrainGroup& g : run_.groups())
      if (g.name == n) out.push_back(&g);
  return out;
}

void EnergySeries::start(const Model& m, const State& s) {
  initial_ = energy(m, s);
  tracked_names_.clear();
  for (const GrainGroup& g : run_.groups())
    if (g.count <= kTrackedGroupMax) tracked_names_.push_back(g.name);
}

void EnergySeries::columns(std::vector<std::string>& cols) const {
  for (const char* c : {"step", "E_trans", "E_rot", "E_pot", "E_elastic", "E_total", "contacts", "wall_contacts",
                        "coordination", "max_overlap_ratio", "rms_speed", "max_speed"})
    cols.push_back(c);
  for (const std::string& n : tracked_names_)
    for (const char* c : {"_x", "_y", "_z", "_vx", "_vy", "_vz"}) cols.push_back(n + c);
}

void EnergySeries::row(const Model& m, const State& s, std::vector<double>& row) const {
  const Energy e = energy(m, s);
  const std::vector<uint8_t>& held = run_.held();
  const GrainSpeeds sp = grain_speeds(m, s, int(held.size()) == m.n_grains ? held : std::vector<uint8_t>(m.n_grains, 0));
  row.insert(row.end(), {double(s.step), e.translational, e.rotational, e.potential, e.elastic, e.total(),
                         double(s.stats.contacts), double(s.stats.wall_contacts), coordination_number(m, s),
                         s.stats.max_overlap_ratio, sp.rms, sp.max});
  for (const GrainGroup* g : tracked()) {
    const Vec3 p = group_mean(s.pos, *g), v = group_mean(s.vel, *g);
    row.insert(row.end(), {p.x(), p.y(), p.z(), v.x(), v.y(), v.z()});
  }
}

void EnergySeries::finish(const Model& m, const State& s) { final_ = energy(m, s); }

}  // namespace rt
