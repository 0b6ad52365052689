// Editing the grains of a scene between steps (see edit.hpp): per-grain
// arrays compacted or extended, contact lists renumbered with their springs.
#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/types.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "regolith_twin/core/history.hpp"
#include "regolith_twin/core/neighbours.hpp"

namespace rt {
namespace {


// v[map[i]] = v[i] for every kept i (map[i] <= i, so in place), then shrink.
template <class T>
void compact(std::vector<T>& v, const std::vector<int>& map, int kept) {
  const size_t n = map.size();
  if (v.size() != n) throw std::logic_error("remove_grains: a per-grain array does not match the grain count");
  for (size_t i = 0; i < n; ++i)
    if (map[i] >= 0) v[map[i]] = v[i];
  v.resize(kept);
}

// Pair list (CSR, rows sorted by partner): rows and partners renumbered,
// entries with a removed grain dropped. Renumbering keeps the order, so every
// row stays sorted.
void compact_pairs(PairList& pl, const std::vector<int>& map, int kept) {
  const int n = static_cast<int>(map.size());
  int out = 0, begin = pl.row_start[0];
  for (int i = 0; i < n; ++i) {
    const int end = pl.row_start[i + 1];  // read before row map[i] + 1 <= i + 1 is written
    if (map[i] >= 0) {
      for (int k = begin; k < end; ++k) {
        const int j = map[pl.partner[k]];
        if (j < 0) continue;
        pl.partner[out] = j;
        if (!pl.image.empty()) pl.image[out] = pl.image[k];
        copy_history(pl, k, pl, out);
        ++out;
      }
      pl.row_start[map[i] + 1] = out;
    }
    begin = end;
  }
  pl.row_start[0] = 0;
  pl.row_start.resize(kept + 1);
  pl.partner.resize(out);
  if (!pl.image.empty()) pl.image.resize(out);
  size_history(pl, out);
  // owner and sqrt_mstar follow in partition_work.
}

void clear_pairs(PairList& pl) {
  pl.row_start.clear();
  pl.partner.clear();
  pl.image.clear();
  pl.owner.clear();
  pl.sqrt_mstar.clear();
  size_history(pl, 0);
}

// Grain–wall list sorted by (grain, wall): the order survives renumbering.
void compact_walls(WallList& wl, const std::vector<int>& map) {
  const int n = static_cast<int>(map.size());
  int out = 0;
  for (int k = 0; k < wl.size(); ++k) {
    const int g = wl.grain[k];
    if (g < 0 || g >= n || map[g] < 0) continue;
    wl.grain[out] = map[g];
    wl.wall[out] = wl.wall[k];
    copy_history(wl, k, wl, out);
    ++out;
  }
  wl.grain.resize(out);
  wl.wall.resize(out);
  size_history(wl, out);
}

// Grain–body list sorted by (grain, body, shape): likewise.
void compact_body_grains(BodyGrainList& bl, const std::vector<int>& map) {
  // Mesh entries keep their slots, moved down to the new numbering (slot
  // blocks stay in entry order, so each moves to a lower or equal index).
  const int n = static_cast<int>(map.size());
  int out = 0, slots = 0;
  for (int k = 0; k < bl.size(); ++k) {
    const int g = bl.grain[k];
    if (g < 0 || g >= n || map[g] < 0) continue;
    bl.grain[out] = map[g];
    bl.body[out] = bl.body[k];
    bl.shape[out] = bl.shape[k];
    bl.sqrt_mstar[out] = bl.sqrt_mstar[k];
    const int first = bl.mesh_first[k];
    bl.mesh_first[out] = first >= 0 ? slots : -1;
    slots += first >= 0 ? kMeshSlots : 0;
    // copy_history reads the old block at `first` and writes the new one.
    copy_history<BodyGrainList>(bl, k, bl, out);
    if (first >= 0)
      for (int q = 0; q < kMeshSlots; ++q) bl.mesh_slots[bl.mesh_first[out] + q] = bl.mesh_slots[first + q];
    ++out;
  }
  bl.grain.resize(out);
  bl.body.resize(out);
  bl.shape.resize(out);
  bl.sqrt_mstar.resize(out);
  bl.mesh_first.resize(out);
  bl.mesh_slots.resize(slots);
  size_history(bl, out);
}

void check_sizes(const Model& m, const State& s, const char* what) {
  const size_t n = size_t(m.n_grains);
  for (const std::vector<Vec3>* v : {&s.pos, &s.vel, &s.omega, &s.vel_mid, &s.omega_mid, &s.force, &s.torque, &s.pos_at_build})
    if (v->size() != n) throw std::logic_error(std::string(what) + ": the state does not match the model's grain count");
  for (const std::vector<double>* v : {&m.grain_radius, &m.grain_mass, &m.grain_inv_mass, &m.grain_inv_inertia})
    if (v->size() != n) throw std::logic_error(std::string(what) + ": the model's grain arrays are not finalized");
  if (m.grain_material.size() != n || m.grain_hold.size() != n)
    throw std::logic_error(std::string(what) + ": the model's grain arrays are not finalized");
}

// The partitions' force buffers (partitions 1..P-1) hold zeros between passes.
void size_scratch(State& s, int n) {
  for (size_t p = 1; p < s.scratch.size(); ++p) {
    s.scratch[p].force.assign(n, Vec3::Zero());
    s.scratch[p].torque.assign(n, Vec3::Zero());
  }
}

// Lists, partitions and pair constants are rebuilt, and forces recomputed,
// before the next step moves anything (prime, which keeps the springs).
void request_rebuild(State& s) {
  s.rebuild_requested = true;
  s.forces_valid = false;
}

// Free flight (model.md §18): reaches no longer hold once grains are added,
// removed or moved by hand; the grains that had one count with the others
// until the next build computes them again.
void drop_reach(State& s) {
  s.reach.clear();
  s.free_grains = 0;
  s.stats.max_disp2 = std::max(s.stats.max_disp2, s.stats.max_free_disp2);
  s.stats.max_free_disp2 = 0;
  s.stats.free_margin = 1e300;
}

}  // namespace

int remove_grains(Model& m, State& s, const std::vector<uint8_t>& drop, std::vector<int>* old_to_new) {
  const int n = m.n_grains;
  if (int(drop.size()) != n)
    throw std::invalid_argument("remove_grains: " + std::to_string(drop.size()) + " flags for " + std::to_string(n) +
                                " grains");
  check_sizes(m, s, "remove_grains");
  std::vector<int> map(n, -1);
  int kept = 0;
  for (int i = 0; i < n; ++i)
    if (!drop[i]) map[i] = kept++;
  if (old_to_new) *old_to_new = map;
  if (kept == n) return 0;

  // Model: every per-grain array, then the extremes finalize_model derives.
  compact(m.grain_radius, map, kept);
  compact(m.grain_mass, map, kept);
  compact(m.grain_material, map, kept);
  compact(m.grain_hold, map, kept);
  compact(m.grain_inv_mass, map, kept);
  compact(m.grain_inv_inertia, map, kept);
  m.n_grains = kept;
  m.max_radius = 0;
  m.min_radius = kept ? 1e300 : 0;
  for (int i = 0; i < kept; ++i) {
    m.max_radius = std::max(m.max_radius, m.grain_radius[i]);
    m.min_radius = std::min(m.min_radius, m.grain_radius[i]);
  }
  m.single_grain_material = kept ? m.grain_material[0] : -1;
  for (int i = 1; i < kept; ++i)
    if (m.grain_material[i] != m.single_grain_material) m.single_grain_material = -1;

  // State: kinematics, the last forces, the positions of the last list build
  // (so displacements since then still count towards the next rebuild).
  for (std::vector<Vec3>* v : {&s.pos, &s.vel, &s.omega, &s.vel_mid, &s.omega_mid, &s.force, &s.torque, &s.pos_at_build})
    compact(*v, map, kept);
  size_scratch(s, kept);
  if (s.sleep.initialized) {  // sleep flags and force references follow their grains (model.md §16)
    compact(s.sleep.asleep, map, kept);
    compact(s.sleep.f_ref, map, kept);
    compact(s.sleep.f_last, map, kept);
    s.sleep.cell_scratch.assign(kept, -1);
  }
  if (s.stats.max_overlap_grain >= 0 && s.stats.max_overlap_grain < n)
    s.stats.max_overlap_grain = map[s.stats.max_overlap_grain];

  // Lists with their springs. The pair and wall lists are read by the next
  // build only while lists_valid; the grain–body list always.
  if (s.lists_valid && int(s.pairs.row_start.size()) == n + 1) {
    compact_pairs(s.pairs, map, kept);
    compact_walls(s.wall_pairs, map);
  } else {
    s.lists_valid = false;
    clear_pairs(s.pairs);
    compact_walls(s.wall_pairs, map);
  }
  compact_body_grains(s.body_grains, map);
  if (s.lists_valid) partition_work(m, s);
  partition_body_list(m, s);
  drop_reach(s);
  request_rebuild(s);
  return n - kept;
}

int add_grain(Model& m, State& s, double radius, int material, const Vec3& pos, const Vec3& vel, const Vec3& omega) {
  if (!(radius > 0)) throw InputError("add_grain: radius must be > 0 m");
  if (material < 0 || material >= m.n_materials()) throw InputError("add_grain: unknown material index");
  check_sizes(m, s, "add_grain");
  const int n = m.n_grains;
  const int i = add_grain(m, radius, material, false);
  // Mass and inertia as finalize_model derives them.
  const double mass = 4.0 / 3.0 * kPi * radius * radius * radius * m.materials[material].density;
  m.grain_mass.push_back(mass);
  const InverseMass im = grain_inverse_mass(m, i);
  m.grain_inv_mass.push_back(im.mass);
  m.grain_inv_inertia.push_back(im.inertia);
  m.max_radius = std::max(m.max_radius, radius);
  m.min_radius = n ? std::min(m.min_radius, radius) : radius;
  m.single_grain_material = n == 0 || m.single_grain_material == material ? material : -1;

  s.pos.push_back(pos);
  s.vel.push_back(vel);
  s.omega.push_back(omega);
  s.vel_mid.push_back(vel);
  s.omega_mid.push_back(omega);
  s.force.push_back(Vec3::Zero());
  s.torque.push_back(Vec3::Zero());
  s.pos_at_build.push_back(pos);  // not yet in any list: counts as moved by nothing
  size_scratch(s, n + 1);
  if (s.sleep.initialized) {  // a new grain is awake
    s.sleep.asleep.push_back(0);
    s.sleep.f_ref.push_back(Vec3::Zero());
    s.sleep.f_last.push_back(Vec3::Zero());
    s.sleep.cell_scratch.push_back(-1);
  }
  // An empty row for the new grain keeps the pair list valid.
  if (s.lists_valid && int(s.pairs.row_start.size()) == n + 1) {
    s.pairs.row_start.push_back(s.pairs.row_start.back());
    partition_work(m, s);
  } else {
    s.lists_valid = false;
  }
  drop_reach(s);
  request_rebuild(s);
  return i;
}

void rotate_grains_about_z(const Model& m, State& s, double angle) {
  if (m.periodic.any()) throw InputError("rotating the grains: not in a periodic box (the box would not turn)");
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
  drop_reach(s);
  for (auto* l : {&s.pairs.spring_t, &s.pairs.spring_r, &s.wall_pairs.spring_t, &s.wall_pairs.spring_r})
    for (Vec3& v : *l) v = R * v;
  // The sleep cells do not turn with the bed: sleeping starts again, every grain awake.
  if (s.sleep.initialized) {
    s.sleep = SleepState{};
    s.forces_valid = false;
  }
}

}  // namespace rt
