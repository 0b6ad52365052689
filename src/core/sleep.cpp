// Sleep stage (docs/model.md §16): cells of quiet grains leave the step.
#include "regolith_twin/core/sleep.hpp"
#include "regolith_twin/core/hold.hpp"

#include <algorithm>
#include <cmath>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/forces.hpp"
#include "regolith_twin/core/neighbours.hpp"

namespace rt {
namespace {

double mean_diameter(const Model& m) {
  if (m.n_grains == 0) return 0;
  double sum = 0;
  for (double r : m.grain_radius) sum += r;
  return 2 * sum / m.n_grains;
}

// Integer cell coordinates of a point (may lie outside the grid).
inline void coords(const SleepState& z, const Vec3& x, long& cx, long& cy, long& cz) {
  const Vec3 c = (x - z.lo) / z.cell;
  cx = long(std::floor(std::clamp(c.x(), -1e9, 1e9)));
  cy = long(std::floor(std::clamp(c.y(), -1e9, 1e9)));
  cz = long(std::floor(std::clamp(c.z(), -1e9, 1e9)));
}

inline int cell_index(const SleepState& z, long cx, long cy, long cz) {
  if (cx < 0 || cy < 0 || cz < 0 || cx >= z.nx || cy >= z.ny || cz >= z.nz) return -1;
  return int((cz * z.ny + cy) * z.nx + cx);
}

// Set `flag` on the cells of the 3x3x3 block around (cx, cy, cz) that lie in the grid.
void mark_block(SleepState& z, long cx, long cy, long cz, uint8_t flag) {
  for (long k = std::max(cz - 1, 0L); k <= std::min(cz + 1, long(z.nz) - 1); ++k)
    for (long j = std::max(cy - 1, 0L); j <= std::min(cy + 1, long(z.ny) - 1); ++j)
      for (long i = std::max(cx - 1, 0L); i <= std::min(cx + 1, long(z.nx) - 1); ++i)
        z.cell_flags[size_t((k * z.ny + j) * z.nx + i)] |= flag;
}

// Set `flag` on every cell within `reach` of centre c (cell boxes against the sphere).
void mark_sphere(SleepState& z, const Vec3& c, double reach, uint8_t flag) {
  long x0, y0, z0, x1, y1, z1;
  coords(z, c - Vec3::Constant(reach), x0, y0, z0);
  coords(z, c + Vec3::Constant(reach), x1, y1, z1);
  x0 = std::max(x0, 0L), y0 = std::max(y0, 0L), z0 = std::max(z0, 0L);
  x1 = std::min(x1, long(z.nx) - 1), y1 = std::min(y1, long(z.ny) - 1), z1 = std::min(z1, long(z.nz) - 1);
  for (long k = z0; k <= z1; ++k)
    for (long j = y0; j <= y1; ++j)
      for (long i = x0; i <= x1; ++i) {
        const Vec3 lo = z.lo + z.cell * Vec3(double(i), double(j), double(k));
        const Vec3 q = c.cwiseMax(lo).cwiseMin(lo + Vec3::Constant(z.cell));  // closest point of the cell
        if ((q - c).squaredNorm() <= reach * reach) z.cell_flags[size_t((k * z.ny + j) * z.nx + i)] |= flag;
      }
}

void init_sleep(const Model& m, State& s) {
  SleepState& z = s.sleep;
  z.d_mean = mean_diameter(m);
  const SleepThresholds th = sleep_thresholds(m, z.d_mean);
  const int n = m.n_grains;
  Vec3 lo, hi;
  grain_bounds(m, s, lo, hi);
  // One cell of margin around the grains' box (grains that settle or are
  // thrown a little beyond it still sleep); far ejecta lie outside and stay awake.
  z.cell = th.cell;
  z.lo = lo - Vec3::Constant(th.cell);
  const Vec3 ext = (hi - z.lo) / th.cell;
  z.nx = int(ext.x()) + 2;
  z.ny = int(ext.y()) + 2;
  z.nz = int(ext.z()) + 2;
  const long cells = long(z.nx) * z.ny * z.nz;
  if (cells > 64L * std::max(n, 1024))
    throw InputError("sleep: the grains' box needs " + std::to_string(cells) +
                     " sleep cells; raise sleep.cell (the grains are spread far beyond a bed)");
  z.asleep.assign(n, 0);
  z.f_ref.assign(n, Vec3::Zero());
  z.f_last = s.force;
  z.quiet.assign(size_t(cells), 0.0);
  z.cell_flags.assign(size_t(cells), 0);
  z.cell_sum.assign(size_t(cells), 0.0);
  z.cell_count.assign(size_t(cells), 0);
  z.cell_scratch.assign(n, -1);
  z.gravity = m.gravity;
  z.next_check = s.step;
  z.last_check = s.time;
  z.ref_pending = true;
  z.initialized = true;
  z.awake.clear();
  for (int i = 0; i < n; ++i) z.awake.push_back(i);
}

enum : uint8_t { kMoving = 1, kAgitated = 2, kWake = 4, kHasSleeper = 8, kBody = 16 };

}  // namespace

SleepThresholds sleep_thresholds(const Model& m) { return sleep_thresholds(m, mean_diameter(m)); }

SleepThresholds sleep_thresholds(const Model& m, double d) {
  const double g = m.gravity.norm();
  const double reach = 2 * m.max_radius + m.skin;
  SleepThresholds t{};
  t.speed = m.sleep.speed * std::sqrt(g * d);
  t.time = g > 0 ? m.sleep.time * std::sqrt(d / g) : 1e300;
  t.force_per_mass = m.sleep.force * g;
  t.cell = m.sleep.cell > 0 ? std::max(m.sleep.cell, reach) : 2 * reach;
  t.margin = t.cell - reach;
  if (!(t.margin > 0)) t.margin = 0.5 * reach;  // cell == reach: at most half a reach per check
  return t;
}

long sleeping_grains(const State& s) {
  long k = 0;
  for (uint8_t a : s.sleep.asleep) k += a;
  return k;
}

void sleep_segments(const Model& m, State& s) {
  SleepState& z = s.sleep;
  const int n = m.n_grains;
  const int P = m.partitions;
  const PairList& pl = s.pairs;
  z.awake.clear();
  for (int i = 0; i < n; ++i)
    if (!z.asleep[i]) z.awake.push_back(i);
  const int total_entries = pl.size();
  // Active entries: at least one grain awake and free (a glued grain counts as asleep).
  const double* inv_mass = m.grain_inv_mass.data();
  const auto idle = [&](int i) { return z.asleep[i] || inv_mass[i] == 0; };
  long active = 0;
  for (int k = 0; k < total_entries; ++k) active += !(idle(pl.owner[k]) && idle(pl.partner[k]));
  s.seg_begin.clear();
  s.seg_end.clear();
  s.thread_seg_begin.assign(P + 1, 0);
  long seen = 0;
  int p = 0;  // partition being filled
  long next_cut = active * 1 / P;
  int last = -2;
  for (int k = 0; k < total_entries; ++k) {
    if (idle(pl.owner[k]) && idle(pl.partner[k])) continue;
    while (p < P && seen >= next_cut) {  // partition p ends before this entry
      ++p;
      s.thread_seg_begin[p] = int(s.seg_begin.size());
      next_cut = active * (p + 1) / P;
      last = -2;
    }
    if (k == last + 1 && !s.seg_end.empty()) {
      s.seg_end.back() = k + 1;
    } else {
      s.seg_begin.push_back(k);
      s.seg_end.push_back(k + 1);
    }
    last = k;
    ++seen;
  }
  while (p < P) s.thread_seg_begin[++p] = int(s.seg_begin.size());
  // Grain range each partition writes.
  for (int q = 0; q < P; ++q) {
    ThreadScratch& sc = s.scratch[q];
    int lo = n, hi = 0;
    for (int g = s.thread_seg_begin[q]; g < s.thread_seg_begin[q + 1]; ++g)
      for (int k = s.seg_begin[g]; k < s.seg_end[g]; ++k) {
        lo = std::min(lo, pl.owner[k]);
        hi = std::max(hi, std::max(pl.partner[k], pl.owner[k]) + 1);
      }
    if (q == 0) lo = 0;  // partition 0 writes State::force from grain 0 on
    sc.touched_lo = std::min(lo, hi);
    sc.touched_hi = hi;
    // The grains it writes, for a merge that visits only them.
    sc.touched.clear();
    if (q == 0) continue;
    for (int g = s.thread_seg_begin[q]; g < s.thread_seg_begin[q + 1]; ++g)
      for (int k = s.seg_begin[g]; k < s.seg_end[g]; ++k) {
        if (sc.touched.empty() || sc.touched.back() != pl.owner[k]) sc.touched.push_back(pl.owner[k]);
        sc.touched.push_back(pl.partner[k]);
      }
    std::sort(sc.touched.begin(), sc.touched.end());
    sc.touched.erase(std::unique(sc.touched.begin(), sc.touched.end()), sc.touched.end());
  }
  // Sleeping grains whose evaluated contacts can change: a partner awake, or a body.
  std::vector<int>& mark = z.cell_scratch;
  mark.assign(n, 0);
  for (int g = 0; g < int(s.seg_begin.size()); ++g)
    for (int k = s.seg_begin[g]; k < s.seg_end[g]; ++k) {
      mark[pl.owner[k]] = 1;
      mark[pl.partner[k]] = 1;
    }
  for (int k = 0; k < s.body_grains.size(); ++k) mark[s.body_grains.grain[k]] = 1;
  z.watch.clear();
  for (int i = 0; i < n; ++i)
    if (z.asleep[i] && mark[i]) z.watch.push_back(i);
}

namespace {
// Mark the flagged grains awake and complete their forces (model.md §16).
void wake(const Model& m, State& s, std::vector<uint8_t>& woken) {
  SleepState& z = s.sleep;
  long count = 0;
  for (int i = 0; i < m.n_grains; ++i)
    if (woken[i]) {
      z.asleep[i] = 0;
      ++count;
    }
  if (count == 0) return;
  z.woke += count;
  if (s.forces_valid) add_woken_contacts(m, s, woken);
  if (s.lists_valid) sleep_segments(m, s);
  z.ref_pending = true;
}
}  // namespace

void wake_all(const Model& m, State& s) {
  SleepState& z = s.sleep;
  if (!z.initialized) return;
  z.woken.assign(m.n_grains, 0);
  for (int i = 0; i < m.n_grains; ++i) z.woken[i] = z.asleep[i];
  for (double& q : z.quiet) q = 0;
  wake(m, s, z.woken);
}

void update_sleep(const Model& m, State& s) {
  if (!m.sleep.enabled) return;
  SleepState& z = s.sleep;
  const int n = m.n_grains;
  if (!z.initialized || int(z.asleep.size()) != n) {
    init_sleep(m, s);
    s.rebuild_requested = true;  // lists and segments follow the sleep flags from the next step
  }
  const SleepThresholds th = sleep_thresholds(m, z.d_mean);
  z.awake_grain_steps += double(z.awake.size());
  bool woke_any = false, slept_any = false;
  std::fill(z.cell_flags.begin(), z.cell_flags.end(), 0);

  // A change of gravity wakes everything.
  if (m.gravity != z.gravity) {
    wake_all(m, s);
    z.gravity = m.gravity;
  }

  // Every step: the force on sleeping grains from their evaluated contacts.
  bool force_wake = false;
  if (z.ref_pending) {
    for (int i : z.watch) z.f_ref[i] = s.force[i];
    z.ref_pending = false;
  } else {
    for (int i : z.watch) {
      if (!z.asleep[i]) continue;
      const double lim = th.force_per_mass * m.grain_mass[i];
      if ((s.force[i] - z.f_ref[i]).squaredNorm() > lim * lim) {
        long cx, cy, cz;
        coords(z, s.pos[i], cx, cy, cz);
        const int c = cell_index(z, cx, cy, cz);
        if (c >= 0) z.cell_flags[c] |= kWake;
        force_wake = true;
      }
    }
  }

  const bool check = s.step >= z.next_check;
  if (!check && !force_wake) return;

  // Grains that touch something (a grain, a wall, a body): only those may
  // fall asleep; a grain touching nothing is in flight.
  std::vector<uint8_t>& touch = z.touch;
  if (check) {
    touch.assign(n, 0);
    const PairList& pl = s.pairs;
    for (int k = 0; k < pl.size(); ++k)
      if (pl.touching[k]) touch[pl.owner[k]] = touch[pl.partner[k]] = 1;
    for (int k = 0; k < s.wall_pairs.size(); ++k)
      if (s.wall_pairs.touching[k]) touch[s.wall_pairs.grain[k]] = 1;
    for (int k = 0; k < s.body_grains.size(); ++k)
      if (s.body_grains.touching[k]) touch[s.body_grains.grain[k]] = 1;
  }
  // Cell of every grain; per cell: awake grains' squared speeds, sleepers.
  std::fill(z.cell_sum.begin(), z.cell_sum.end(), 0.0);
  std::fill(z.cell_count.begin(), z.cell_count.end(), 0);
  double vmax = 0;
  const double v2_lim = th.speed * th.speed;
  for (int i = 0; i < n; ++i) {
    long cx, cy, cz;
    coords(z, s.pos[i], cx, cy, cz);
    const int c = cell_index(z, cx, cy, cz);
    z.cell_scratch[i] = c;
    if (z.asleep[i]) {
      if (c >= 0) z.cell_flags[c] |= kHasSleeper;
      continue;
    }
    if (!check || held(m, i)) continue;  // glued grains neither move nor sleep
    const double r = m.grain_radius[i];
    const double v2 = s.vel[i].squaredNorm() + s.omega[i].squaredNorm() * r * r;
    vmax = std::max(vmax, std::sqrt(v2));
    if (v2 > v2_lim) mark_block(z, cx, cy, cz, kMoving);  // moving: the neighbouring cells must be awake
    if (c < 0) continue;
    z.cell_sum[c] += v2;
    ++z.cell_count[c];
    const double lim = th.force_per_mass * m.grain_mass[i];
    if ((s.force[i] - z.f_last[i]).squaredNorm() > lim * lim) z.cell_flags[c] |= kAgitated;
    z.f_last[i] = s.force[i];
  }
  // Moving bodies keep the cells around them awake, as far as they can get before the next check.
  double body_speed = 0;
  if (check)
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      const BodyState& bs = s.bodies[b];
      const double v = bs.vel.norm() + bs.omega.norm() * m.bodies[b].bound_radius;
      if (m.bodies[b].fixed || v <= th.speed) continue;
      body_speed = std::max(body_speed, v);
      mark_sphere(z, bs.pos, m.bodies[b].bound_radius + m.max_radius + m.skin + th.margin, kBody);
    }

  // Decisions, cell by cell.
  const double elapsed = s.time - z.last_check;
  const bool first = z.checks == 0;
  for (size_t c = 0; c < z.cell_flags.size(); ++c) {
    uint8_t& f = z.cell_flags[c];
    if ((f & kHasSleeper) && (f & (kWake | kMoving | kBody))) f |= kWake;
    else f &= uint8_t(~kWake);
    if (!check) continue;
    const int cnt = z.cell_count[c];
    const bool quiet = cnt > 0 && z.cell_sum[c] < v2_lim * cnt && !(f & (kMoving | kAgitated | kBody | kWake));
    if (!quiet) {
      z.quiet[c] = 0;
      continue;
    }
    z.quiet[c] = (first && m.sleep.at_start) ? th.time : z.quiet[c] + elapsed;
  }
  // Wake the flagged cells.
  z.woken.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    const int c = z.cell_scratch[i];
    if (c >= 0 && z.asleep[i] && (z.cell_flags[c] & kWake)) {
      z.woken[i] = 1;
      woke_any = true;
    }
  }
  if (woke_any) wake(m, s, z.woken);
  // Put the quiet cells' awake grains to sleep; their kinetic energy is discarded (and logged).
  if (check) {
    for (int i = 0; i < n; ++i) {
      const int c = z.cell_scratch[i];
      // A grain touching nothing is in flight (a rattler in its cage, an ejected grain): it stays awake.
      if (c < 0 || z.asleep[i] || z.quiet[c] < th.time || held(m, i) || !touch[i]) continue;
      const double im = m.grain_inv_mass[i], ii = m.grain_inv_inertia[i];
      z.discarded_energy += 0.5 * s.vel[i].squaredNorm() / im + (ii > 0 ? 0.5 * s.omega[i].squaredNorm() / ii : 0);
      z.discarded_max_speed = std::max(z.discarded_max_speed, s.vel[i].norm());
      s.vel[i].setZero();
      s.omega[i].setZero();
      s.vel_mid[i].setZero();
      s.omega_mid[i].setZero();
      z.asleep[i] = 1;
      ++z.fell_asleep;
      slept_any = true;
    }
    // Next check: before anything moving can cross the margin around a sleeping cell.
    const double v = std::max(vmax, body_speed);
    long k = m.sleep.check_every;
    if (v > 0) k = std::min<long>(k, std::max<long>(1, long(0.5 * th.margin / (v * m.dt))));
    z.next_check = s.step + k;
    z.last_check = s.time;
    ++z.checks;
  }
  if (slept_any) {
    sleep_segments(m, s);
    z.ref_pending = true;
  }
}

}  // namespace rt
