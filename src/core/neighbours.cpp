// Neighbours stage: counting-sort cell lists, half pair list, wall list,
// history carry-over and the fixed work partition.
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/core/neighbours.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "regolith_twin/core/history.hpp"
#include "regolith_twin/core/sleep.hpp"
#include "regolith_twin/core/walls.hpp"

namespace rt {
namespace {

// Copy the springs of the entries present in both sorted ranges, old
// [os, oe) and new [ns, ne); zero the rest. cmp(o, k) orders old entry o
// against new entry k by the list's key (< 0, 0, > 0). Every list (pair rows,
// grain–wall, grain–body) carries its history through this one walk.
template <class List, class Cmp>
void carry_history(const List& old_list, int os, int oe, List& nl, int ns, int ne, Cmp cmp) {
  int o = os;
  for (int k = ns; k < ne; ++k) {
    while (o < oe && cmp(o, k) < 0) ++o;
    if (o < oe && cmp(o, k) == 0)
      copy_history(old_list, o, nl, k);
    else
      clear_history(nl, k);
  }
}

inline int order(long a, long b) { return a < b ? -1 : (a > b ? 1 : 0); }

// Sort grains into cells of side 2 r_max + skin. Dense: the cells tile the
// grains' bounding box. When that box would need more than max(4 n, 64)
// cells (a few grains far from the bed: ejecta), the cells are hashed into a
// table of at least 2 n buckets instead, so far grains do not coarsen the
// cells of the bed; a bucket may then hold grains of several cells, which
// the distance tests sort out. Either way a row finds every partner within
// the cut-off and is sorted, so the lists are the same.
struct Grid {
  Vec3 lo;
  Vec3 inv_cell;      // 1 / cell side per axis (a periodic axis: its length over a whole number of cells)
  int nx, ny, nz;     // cells per axis (dense grids; periodic axes of any grid)
  bool hashed;
  uint32_t mask;      // buckets - 1 (hashed grids; a power of two minus one)
  bool px, py;        // periodic along x, y: cell coordinates wrap modulo nx, ny
};

// Integer cell coordinate of x along one axis (hashed grids; far grains clamped, still correct).
inline long cell_coord(double x) { return long(std::clamp(std::floor(x), -1e9, 1e9)); }

inline uint32_t bucket_of(const Grid& g, long x, long y, long z) {
  const uint64_t h = uint64_t(x) * 0x9E3779B185EBCA87ULL ^ uint64_t(y) * 0xC2B2AE3D27D4EB4FULL ^
                     uint64_t(z) * 0x165667B19E3779F9ULL;
  return uint32_t((h ^ (h >> 29)) & g.mask);
}

// Cell coordinate along a periodic axis of n cells (the grain is wrapped;
// rounding may put it on the far edge).
inline long periodic_coord(double c, int n) { return std::clamp(long(std::floor(c)), 0L, long(n - 1)); }

// Periodic boxes: every grain moved into [lo, lo + length) along the
// periodic axes (its position at the last build with it, so displacements
// since the build stay continuous). Done at each list build.
void wrap_grains(const Model& m, State& s) {
  const Periodic& p = m.periodic;
  for (int a = 0; a < 2; ++a) {
    if (!(a == 0 ? p.x : p.y)) continue;
    const double lo = p.lo[a], L = p.length[a];
    for (int i = 0; i < m.n_grains; ++i) {
      const double k = std::floor((s.pos[i][a] - lo) / L);
      if (k != 0) s.pos[i][a] -= k * L;
    }
  }
}

}  // namespace

void grain_bounds(const Model& m, const State& s, Vec3& lo, Vec3& hi) {
  lo = Vec3::Constant(1e300);
  hi = Vec3::Constant(-1e300);
  for (int i = 0; i < m.n_grains; ++i) {
    lo = lo.cwiseMin(s.pos[i]);
    hi = hi.cwiseMax(s.pos[i]);
  }
  if (m.n_grains == 0) lo = hi = Vec3::Zero();
}

namespace {

Grid bin_grains(const Model& m, State& s) {
  const int n = m.n_grains;
  Vec3 lo, hi;
  grain_bounds(m, s, lo, hi);
  double cell = 2 * m.max_radius + m.skin;
  if (!(cell > 0)) cell = 1.0;  // no grains: any cell size
  const long max_cells = std::max<long>(4L * n, 64);
  Grid g{lo, Vec3::Constant(1.0 / cell), 0, 0, 0, false, 0, m.periodic.x, m.periodic.y};
  Vec3 ext = (hi - lo) / cell;
  // A periodic axis: a whole number of cells of at least the cut-off tile the box.
  int per[2] = {0, 0};
  for (int a = 0; a < 2; ++a) {
    if (!(a == 0 ? g.px : g.py)) continue;
    per[a] = std::max(1, int(std::floor(m.periodic.length[a] / cell)));
    g.lo[a] = m.periodic.lo[a];
    g.inv_cell[a] = per[a] / m.periodic.length[a];
    ext[a] = per[a] - 1;
  }
  const double cells = (std::floor(ext.x()) + 1) * (std::floor(ext.y()) + 1) * (std::floor(ext.z()) + 1);
  int ncell = 0;
  if (cells <= max_cells) {
    g.nx = int(ext.x()) + 1;
    g.ny = int(ext.y()) + 1;
    g.nz = int(ext.z()) + 1;
    ncell = g.nx * g.ny * g.nz;
  } else {
    g.hashed = true;
    g.nx = per[0];
    g.ny = per[1];
    uint32_t buckets = 64;
    while (buckets < 2u * uint32_t(n)) buckets *= 2;
    g.mask = buckets - 1;
    ncell = int(buckets);
  }
  s.cell_start.assign(ncell + 1, 0);
  s.cell_of.resize(n);
  s.cell_items.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 c = (s.pos[i] - g.lo).cwiseProduct(g.inv_cell);
    int id;
    if (g.hashed) {
      id = int(bucket_of(g, g.px ? periodic_coord(c.x(), g.nx) : cell_coord(c.x()),
                         g.py ? periodic_coord(c.y(), g.ny) : cell_coord(c.y()), cell_coord(c.z())));
    } else {
      const int cx = g.px ? int(periodic_coord(c.x(), g.nx)) : std::min(int(c.x()), g.nx - 1),
                cy = g.py ? int(periodic_coord(c.y(), g.ny)) : std::min(int(c.y()), g.ny - 1),
                cz = std::min(int(c.z()), g.nz - 1);
      id = (cz * g.ny + cy) * g.nx + cx;
    }
    s.cell_of[i] = id;
    ++s.cell_start[id + 1];
  }
  for (int c = 0; c < ncell; ++c) s.cell_start[c + 1] += s.cell_start[c];
  // Fill in ascending grain order, using cell_start as a moving cursor, then
  // shift it back so cell_start[c] is again the first slot of cell c.
  for (int i = 0; i < n; ++i) s.cell_items[s.cell_start[s.cell_of[i]]++] = i;
  for (int c = ncell; c > 0; --c) s.cell_start[c] = s.cell_start[c - 1];
  s.cell_start[0] = 0;
  return g;
}

// The distinct buckets of the cells [x0, x1] x [y0, y1] x [z0, z1] of a
// hashed grid, sorted, into out (at most 27 for a grain's neighbourhood).
template <class Out>
int buckets_of_box(const Grid& g, long x0, long x1, long y0, long y1, long z0, long z1, Out& out) {
  int k = 0;
  for (long z = z0; z <= z1; ++z)
    for (long y = y0; y <= y1; ++y)
      for (long x = x0; x <= x1; ++x) out[k++] = bucket_of(g, x, y, z);
  std::sort(out.begin(), out.begin() + k);
  return int(std::unique(out.begin(), out.begin() + k) - out.begin());
}

// Partners of row i (j > i within the cut-off, ascending) appended to out.
void row_partners(const Model& m, const State& s, const Grid& g, int i, std::vector<int>& out) {
  const size_t first = out.size();
  const Vec3 xi = s.pos[i];
  const double ri = m.grain_radius[i];
  const double skin = m.skin;
  auto scan = [&](int cc) {
    for (int q = s.cell_start[cc]; q < s.cell_start[cc + 1]; ++q) {
      const int j = s.cell_items[q];
      if (j <= i) continue;
      if (held(m, i) && held(m, j)) continue;  // pairs of held grains never interact
      if (!m.mobile_contacts && !held(m, i) && !held(m, j)) continue;  // collisionless
      const double cut = ri + m.grain_radius[j] + skin;
      if ((s.pos[j] - xi).squaredNorm() < cut * cut) out.push_back(j);
    }
  };
  if (g.hashed) {
    const Vec3 c = (xi - g.lo).cwiseProduct(g.inv_cell);
    const long cx = cell_coord(c.x()), cy = cell_coord(c.y()), cz = cell_coord(c.z());
    std::array<uint32_t, 27> b;
    const int nb = buckets_of_box(g, cx - 1, cx + 1, cy - 1, cy + 1, cz - 1, cz + 1, b);
    for (int k = 0; k < nb; ++k) scan(int(b[k]));
  } else {
    const int c = s.cell_of[i];
    const int cx = c % g.nx, cy = (c / g.nx) % g.ny, cz = c / (g.nx * g.ny);
    for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, g.nz - 1); ++z)
      for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, g.ny - 1); ++y)
        for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, g.nx - 1); ++x) scan((z * g.ny + y) * g.nx + x);
  }
  std::sort(out.begin() + first, out.end());
}

// The same in a periodic box: the cells around i wrap along the periodic
// axes, each partner's nearest image is taken (unique: the box is at least
// twice the cut-off), and the entry is packed as 16 j + (image code + 4).
void row_partners_periodic(const Model& m, const State& s, const Grid& g, int i, std::vector<int>& out) {
  const size_t first = out.size();
  const Vec3 xi = s.pos[i];
  const double ri = m.grain_radius[i];
  const double skin = m.skin;
  const Periodic& p = m.periodic;
  const double lx = p.length.x(), ly = p.length.y();
  const Vec3 c = (xi - g.lo).cwiseProduct(g.inv_cell);
  long ax[3], ay[3];
  int nxs = 0, nys = 0;
  const auto around = [](long c0, bool periodic, int n, long* out3) {
    int k = 0;
    for (long d = -1; d <= 1; ++d) {
      long v = c0 + d;
      if (periodic) v = ((v % n) + n) % n;
      if (std::find(out3, out3 + k, v) == out3 + k) out3[k++] = v;
    }
    return k;
  };
  const long cx = g.px ? periodic_coord(c.x(), g.nx) : (g.hashed ? cell_coord(c.x()) : long(s.cell_of[i] % g.nx));
  const long cy = g.py ? periodic_coord(c.y(), g.ny)
                       : (g.hashed ? cell_coord(c.y()) : long((s.cell_of[i] / g.nx) % g.ny));
  const long cz = g.hashed ? cell_coord(c.z()) : long(s.cell_of[i] / (g.nx * g.ny));
  nxs = around(cx, g.px, g.nx, ax);
  nys = around(cy, g.py, g.ny, ay);
  std::array<uint32_t, 27> cells;
  int nc = 0;
  for (long z = cz - 1; z <= cz + 1; ++z)
    for (int b = 0; b < nys; ++b)
      for (int a = 0; a < nxs; ++a) {
        if (g.hashed) {
          cells[nc++] = bucket_of(g, ax[a], ay[b], z);
        } else {
          if (z < 0 || z >= g.nz || ax[a] < 0 || ax[a] >= g.nx || ay[b] < 0 || ay[b] >= g.ny) continue;
          cells[nc++] = uint32_t((z * g.ny + ay[b]) * g.nx + ax[a]);
        }
      }
  std::sort(cells.begin(), cells.begin() + nc);
  nc = int(std::unique(cells.begin(), cells.begin() + nc) - cells.begin());
  for (int k = 0; k < nc; ++k) {
    const int cc = int(cells[k]);
    for (int q = s.cell_start[cc]; q < s.cell_start[cc + 1]; ++q) {
      const int j = s.cell_items[q];
      if (j <= i) continue;
      if (held(m, i) && held(m, j)) continue;  // pairs of held grains never interact
      if (!m.mobile_contacts && !held(m, i) && !held(m, j)) continue;  // collisionless
      Vec3 d = s.pos[j] - xi;
      int sx = 0, sy = 0;
      if (p.x) {
        sx = -int(std::lround(d.x() / lx));
        d.x() += sx * lx;
      }
      if (p.y) {
        sy = -int(std::lround(d.y() / ly));
        d.y() += sy * ly;
      }
      const double cut = ri + m.grain_radius[j] + skin;
      if (d.squaredNorm() < cut * cut) out.push_back(16 * j + (sx + 3 * sy + 4));
    }
  }
  std::sort(out.begin() + first, out.end());
}

// Half pair list. Each block of rows [n b/P, n (b+1)/P) is searched into its
// own buffer (statically, like the force pass), then the blocks are copied
// into place after a prefix sum of the row lengths; every row is built and
// sorted on its own, so the list is the same for any thread count.
void build_pairs(const Model& m, State& s, const Grid& g) {
  const int n = m.n_grains;
  const int P = m.partitions;
  PairList& nl = s.pairs_next;
  nl.row_start.resize(n + 1);
  const PairList& ol = s.pairs;
  const bool have_old = s.lists_valid && static_cast<int>(ol.row_start.size()) == n + 1;
  const bool periodic = m.periodic.any();
#pragma omp parallel if (n >= m.parallel_min_grains)
  {
#pragma omp for schedule(static)
    for (int b = 0; b < P; ++b) {
      std::vector<int>& out = s.scratch[b].list_partners;
      out.clear();
      const int ib = int(long(n) * b / P), ie = int(long(n) * (b + 1) / P);
      for (int i = ib; i < ie; ++i) {
        const size_t before = out.size();
        if (periodic)
          row_partners_periodic(m, s, g, i, out);
        else
          row_partners(m, s, g, i, out);
        nl.row_start[i + 1] = static_cast<int>(out.size() - before);  // row length for now
      }
    }
#pragma omp single
    {
      nl.row_start[0] = 0;
      for (int i = 0; i < n; ++i) nl.row_start[i + 1] += nl.row_start[i];
      nl.partner.resize(nl.row_start[n]);
      nl.image.resize(periodic ? nl.row_start[n] : 0);
      size_history(nl, nl.size());
    }  // (implied barrier)
#pragma omp for schedule(static)
    for (int b = 0; b < P; ++b) {
      const std::vector<int>& in = s.scratch[b].list_partners;
      const int ib = int(long(n) * b / P), ie = int(long(n) * (b + 1) / P);
      if (periodic) {
        for (size_t q = 0; q < in.size(); ++q) {  // unpack 16 j + (image + 4)
          nl.partner[nl.row_start[ib] + q] = in[q] >> 4;
          nl.image[nl.row_start[ib] + q] = int8_t((in[q] & 15) - 4);
        }
      } else {
        std::copy(in.begin(), in.end(), nl.partner.begin() + nl.row_start[ib]);
      }
      const auto by_partner = [&ol, &nl](int o, int k) { return order(ol.partner[o], nl.partner[k]); };
      for (int i = ib; i < ie; ++i) {
        if (have_old)
          carry_history(ol, ol.row_start[i], ol.row_start[i + 1], nl, nl.row_start[i], nl.row_start[i + 1],
                        by_partner);
        else
          carry_history(ol, 0, 0, nl, nl.row_start[i], nl.row_start[i + 1], by_partner);
      }
    }
  }
  std::swap(s.pairs, s.pairs_next);
}

void build_walls(const Model& m, State& s) {
  WallList& nl = s.wall_pairs_next;
  nl.grain.clear();
  nl.wall.clear();
  const int nw = static_cast<int>(m.walls.size());
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    for (int w = 0; w < nw; ++w) {
      if (!s.wall_on[w]) continue;
      if (wall_gap(m.walls[w], s.pos[i], m.grain_radius[i]).overlap > -m.skin) {
        nl.grain.push_back(i);
        nl.wall.push_back(w);
      }
    }
  }
  size_history(nl, nl.size());
  // Entries are sorted by (grain, wall): history carried by that key.
  const WallList& ol = s.wall_pairs;
  carry_history(ol, 0, s.lists_valid ? ol.size() : 0, nl, 0, nl.size(), [&ol, &nl](int o, int k) {
    const int c = order(ol.grain[o], nl.grain[k]);
    return c != 0 ? c : order(ol.wall[o], nl.wall[k]);
  });
  std::swap(s.wall_pairs, s.wall_pairs_next);
}

// Range of grid cells along one axis that holds every grain whose binned
// coordinate lies in [a, b] (cell units from the grid's low corner). Grains
// sit in cells floor(c) clamped to the last cell, with c >= 0. False when no
// cell can hold one.
bool cell_range(double a, double b, int cells, int& first, int& last) {
  if (!(b >= 0)) return false;
  a = std::max(a, 0.0);
  const double top = cells - 1;
  first = a >= top ? cells - 1 : int(a);
  last = b >= top ? cells - 1 : int(b);
  return true;
}

// Grain–body candidates: every grain whose gap to a body shape is below the
// skin, sorted by (grain, body, shape); history carried by that key. g must
// bin the current positions (bin_grains). For each body, only the grains of
// the cells overlapping its bounding sphere grown by r_max + skin are tested;
// the grains near one of its shapes are sorted, and the bodies' grains merged
// in grain order, so the list is the one a test of every grain against every
// body gives (same entries, order and values).
void build_body_grains(const Model& m, State& s, const Grid& g) {
  BodyGrainList& nl = s.body_grains_next;
  nl.grain.clear();
  nl.body.clear();
  nl.shape.clear();
  nl.sqrt_mstar.clear();
  nl.mesh_first.clear();
  int mesh_slots = 0;
  const int nb = static_cast<int>(m.bodies.size());
  // Scratch (the pair build is done with it): [segment end of each body,
  // cursor of each body, the sorted candidate grains of each body, a heap of
  // bodies ordered by the grain at their cursor].
  std::vector<int>& buf = s.scratch[0].list_partners;
  buf.assign(2 * size_t(nb), 0);
  for (int b = 0; b < nb; ++b) {
    const BodyModel& bm = m.bodies[b];
    const BodyState& bs = s.bodies[b];
    const double inv_body = bm.inv_mass();
    const Quat to_body = bs.q.conjugate();
    const int n_shapes = static_cast<int>(bm.shapes.size());
    buf[nb + b] = static_cast<int>(buf.size());
    // Every grain within reach of the body's centre, with a margin far above
    // the rounding of the coordinates.
    const double reach_max = bm.bound_radius + m.max_radius + m.skin;
    const double h = reach_max + 1e-9 * (reach_max + bs.pos.cwiseAbs().maxCoeff() + g.lo.cwiseAbs().maxCoeff());
    // (bodies are not allowed in periodic boxes: the cells are cubes here)
    const Vec3 a = (bs.pos - Vec3::Constant(h) - g.lo) * g.inv_cell.x(),
               c = (bs.pos + Vec3::Constant(h) - g.lo) * g.inv_cell.x();
    auto test = [&](int i) {
      if (m.grain_inv_mass[i] + inv_body == 0) return;  // glued grain against an immovable body
      const double ri = m.grain_radius[i];
      const Vec3 d = s.pos[i] - bs.pos;
      const double reach = bm.bound_radius + ri + m.skin;
      if (d.squaredNorm() > reach * reach) return;
      const Vec3 p = to_body * d;
      for (int k = 0; k < n_shapes; ++k)
        if (shape_gap(bm, bm.shapes[k], p, ri, m.skin).overlap > -m.skin) {
          buf.push_back(i);  // a candidate: its shapes are listed in the merge below
          return;
        }
    };
    auto scan = [&](int cc) {
      for (int q = s.cell_start[cc]; q < s.cell_start[cc + 1]; ++q) test(s.cell_items[q]);
    };
    if (g.hashed) {
      // The buckets of the cells in the box, each once; every grain when the
      // box has more cells than the table has buckets.
      const long x0 = cell_coord(a.x()), x1 = cell_coord(c.x()), y0 = cell_coord(a.y()), y1 = cell_coord(c.y()),
                 z0 = cell_coord(a.z()), z1 = cell_coord(c.z());
      const double box_cells = double(x1 - x0 + 1) * double(y1 - y0 + 1) * double(z1 - z0 + 1);
      if (box_cells > double(g.mask) + 1) {
        for (int i = 0; i < m.n_grains; ++i) test(i);
      } else {
        static thread_local std::vector<uint32_t> buckets;  // capacity kept between builds
        buckets.resize(size_t(box_cells));
        const int nbk = buckets_of_box(g, x0, x1, y0, y1, z0, z1, buckets);
        for (int k = 0; k < nbk; ++k) scan(int(buckets[k]));
      }
    } else {
      int x0, x1, y0, y1, z0, z1;
      if (cell_range(a.x(), c.x(), g.nx, x0, x1) && cell_range(a.y(), c.y(), g.ny, y0, y1) &&
          cell_range(a.z(), c.z(), g.nz, z0, z1))
        for (int z = z0; z <= z1; ++z)
          for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) scan((z * g.ny + y) * g.nx + x);
    }
    std::sort(buf.begin() + buf[nb + b], buf.end());
    buf[b] = static_cast<int>(buf.size());
  }
  // Merge: take the (grain, body) candidates in grain order, bodies in order
  // within a grain, and list the body's shapes within reach in order.
  const int heap0 = static_cast<int>(buf.size());
  for (int b = 0; b < nb; ++b)
    if (buf[nb + b] < buf[b]) buf.push_back(b);
  const auto later = [&buf, nb](int p, int q) {
    const int gp = buf[buf[nb + p]], gq = buf[buf[nb + q]];
    return gp != gq ? gp > gq : p > q;
  };
  auto heap_end = buf.end();
  std::make_heap(buf.begin() + heap0, heap_end, later);
  while (heap_end != buf.begin() + heap0) {
    std::pop_heap(buf.begin() + heap0, heap_end, later);
    const int b = *(heap_end - 1);
    const int i = buf[buf[nb + b]];
    const BodyModel& bm = m.bodies[b];
    const BodyState& bs = s.bodies[b];
    const double ri = m.grain_radius[i];
    const double inv = m.grain_inv_mass[i] + bm.inv_mass();
    const Vec3 p = bs.q.conjugate() * (s.pos[i] - bs.pos);
    for (int k = 0; k < static_cast<int>(bm.shapes.size()); ++k) {
      if (shape_gap(bm, bm.shapes[k], p, ri, m.skin).overlap > -m.skin) {
        nl.grain.push_back(i);
        nl.body.push_back(b);
        nl.shape.push_back(k);
        nl.sqrt_mstar.push_back(std::sqrt(1.0 / inv));
        const bool mesh = bm.shapes[k].type == ShapeType::Mesh;
        nl.mesh_first.push_back(mesh ? mesh_slots : -1);
        mesh_slots += mesh ? kMeshSlots : 0;
      }
    }
    if (++buf[nb + b] < buf[b])
      std::push_heap(buf.begin() + heap0, heap_end, later);
    else
      --heap_end;
  }
  size_history(nl, nl.size());
  nl.mesh_slots.resize(mesh_slots);
  const BodyGrainList& ol = s.body_grains;
  carry_history(ol, 0, ol.size(), nl, 0, nl.size(), [&ol, &nl](int o, int k) {
    int c = order(ol.grain[o], nl.grain[k]);
    if (c == 0) c = order(ol.body[o], nl.body[k]);
    return c != 0 ? c : order(ol.shape[o], nl.shape[k]);
  });
  std::swap(s.body_grains, s.body_grains_next);
  for (int b = 0; b < nb; ++b) {
    s.bodies[b].pos_at_build = s.bodies[b].pos;
    s.bodies[b].q_at_build = s.bodies[b].q;
  }
  s.body_list_grain_disp = std::sqrt(s.stats.max_disp2);
  partition_body_list(m, s);
  ++s.body_rebuilds;
}

// Bound on the displacement of any point of body b since it was at (pos0, q0).
double body_point_shift(const Model& m, const State& s, size_t b, const Vec3& pos0, const Quat& q0) {
  const BodyState& bs = s.bodies[b];
  return (bs.pos - pos0).norm() + q0.angularDistance(bs.q) * m.bodies[b].bound_radius;
}

// Largest displacement of any body point since the grain–body list was built.
double max_body_displacement(const Model& m, const State& s) {
  double worst = 0;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    worst = std::max(worst, body_point_shift(m, s, b, s.bodies[b].pos_at_build, s.bodies[b].q_at_build));
  return worst;
}

}  // namespace

bool body_list_needs_rebuild(const Model& m, const State& s) {
  if (m.bodies.empty()) return false;
  // A gap can close by at most the grain's plus the body's displacement since
  // the build; grains are measured from pos_at_build (triangle inequality).
  return std::sqrt(s.stats.max_disp2) + s.body_list_grain_disp + max_body_displacement(m, s) > m.skin;
}

void partition_body_list(const Model& m, State& s) {
  // Entries split at grain boundaries into the fixed partitions.
  const int P = m.partitions;
  s.thread_body_begin.resize(P + 1);
  const BodyGrainList& bl = s.body_grains;
  for (int p = 0; p <= P; ++p) {
    int k = int(long(bl.size()) * p / P);
    while (k > 0 && k < bl.size() && bl.grain[k] == bl.grain[k - 1]) ++k;
    s.thread_body_begin[p] = k;
  }
  for (int p = 1; p <= P; ++p) s.thread_body_begin[p] = std::max(s.thread_body_begin[p], s.thread_body_begin[p - 1]);
}

void build_body_list(const Model& m, State& s) {
  // The cells of the last full build are not kept (they may also predate a
  // checkpoint restore or a moved bed): bin the current positions again.
  const Grid g = bin_grains(m, s);
  build_body_grains(m, s, g);
  if (sleep_active(m, s)) {
    sleep_segments(m, s);  // the watch list follows the grain–body entries
    s.sleep.ref_pending = true;
  }
}

// Split rows into partitions of about equal entry counts; record the grain
// range each partition writes so merging touches only that range.
void partition_work(const Model& m, State& s) {
  // Per-entry row owner and constant of the pair law.
  PairList& pairs = s.pairs;
  pairs.owner.resize(pairs.size());
  pairs.sqrt_mstar.resize(pairs.size());
#pragma omp parallel for schedule(static) if (m.n_grains >= m.parallel_min_grains)
  for (int i = 0; i < m.n_grains; ++i)
    for (int k = pairs.row_start[i]; k < pairs.row_start[i + 1]; ++k) {
      pairs.owner[k] = i;
      pairs.sqrt_mstar[k] = std::sqrt(1.0 / (m.grain_inv_mass[i] + m.grain_inv_mass[pairs.partner[k]]));
    }
  const int P = m.partitions;
  const int n = m.n_grains;
  const PairList& pl = s.pairs;
  const long total = pl.size();
  s.thread_row_begin.resize(P + 1);
  for (int p = 0; p <= P; ++p) {
    const long target = total * p / P;
    s.thread_row_begin[p] =
        p == P ? n : int(std::lower_bound(pl.row_start.begin(), pl.row_start.end() - 1, target) - pl.row_start.begin());
  }
  for (int p = 0; p < P; ++p) {
    ThreadScratch& sc = s.scratch[p];
    const int rb = s.thread_row_begin[p], re = s.thread_row_begin[p + 1];
    int hi = re;
    for (int i = rb; i < re; ++i)
      if (pl.row_start[i + 1] > pl.row_start[i]) hi = std::max(hi, pl.partner[pl.row_start[i + 1] - 1] + 1);
    sc.touched_lo = rb;
    sc.touched_hi = std::min(hi, n);
  }
  // Wall entries: those of grains [n q/P, n (q+1)/P) form partition q (the
  // force pass merges that block of grains and adds its wall contacts in one go).
  const WallList& wl = s.wall_pairs;
  if (sleep_active(m, s)) {
    sleep_segments(m, s);  // the entries with an awake grain, split by count (model.md §16)
  } else {
    s.seg_begin.resize(P);
    s.seg_end.resize(P);
    s.thread_seg_begin.resize(P + 1);
    for (int p = 0; p < P; ++p) {
      s.seg_begin[p] = pl.row_start[s.thread_row_begin[p]];
      s.seg_end[p] = pl.row_start[s.thread_row_begin[p + 1]];
      s.thread_seg_begin[p] = p;
    }
    s.thread_seg_begin[P] = P;
  }
  s.thread_wall_begin.resize(P + 1);
  for (int q = 0; q <= P; ++q)
    s.thread_wall_begin[q] =
        int(std::lower_bound(wl.grain.begin(), wl.grain.end(), int(long(n) * q / P)) - wl.grain.begin());
}

namespace {

// Free flight (docs/model.md §18). The reach of grain i: the smallest gap to
// any other grain within reach_cells cells (grains beyond them are at least
// reach_cells cells away, so their gap is at least that minus both radii),
// to every wall that is on and to every body shape (a shape farther than the
// body's bounding sphere allows is not evaluated).
double grain_reach(const Model& m, const State& s, const Grid& g, int i) {
  const int K = m.free_flight.reach_cells;
  const Vec3 xi = s.pos[i];
  const double ri = m.grain_radius[i];
  double c = K / g.inv_cell.x() - ri - m.max_radius;  // cubic cells (no free flight in periodic boxes)
  auto scan = [&](int cc) {
    for (int q = s.cell_start[cc]; q < s.cell_start[cc + 1]; ++q) {
      const int j = s.cell_items[q];
      if (j != i) c = std::min(c, (s.pos[j] - xi).norm() - ri - m.grain_radius[j]);
    }
  };
  if (g.hashed) {
    const Vec3 cc = (xi - g.lo) * g.inv_cell.x();
    const long cx = cell_coord(cc.x()), cy = cell_coord(cc.y()), cz = cell_coord(cc.z());
    static thread_local std::vector<uint32_t> buckets;  // capacity kept between builds
    buckets.resize(size_t(2 * K + 1) * (2 * K + 1) * (2 * K + 1));
    const int nb = buckets_of_box(g, cx - K, cx + K, cy - K, cy + K, cz - K, cz + K, buckets);
    for (int k = 0; k < nb; ++k) scan(int(buckets[k]));
  } else {
    const int cell = s.cell_of[i];
    const int cx = cell % g.nx, cy = (cell / g.nx) % g.ny, cz = cell / (g.nx * g.ny);
    for (int z = std::max(cz - K, 0); z <= std::min(cz + K, g.nz - 1); ++z)
      for (int y = std::max(cy - K, 0); y <= std::min(cy + K, g.ny - 1); ++y)
        for (int x = std::max(cx - K, 0); x <= std::min(cx + K, g.nx - 1); ++x) scan((z * g.ny + y) * g.nx + x);
  }
  for (size_t w = 0; w < m.walls.size(); ++w)
    if (s.wall_on[w]) c = std::min(c, -wall_gap(m.walls[w], xi, ri).overlap);
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyModel& bm = m.bodies[b];
    const BodyState& bs = s.bodies[b];
    const Vec3 d = xi - bs.pos;
    if (d.norm() - bm.bound_radius - ri >= c) continue;
    const Vec3 p = bs.q.conjugate() * d;
    for (const Shape& sh : bm.shapes) {
      const ShapeGap sg = shape_gap(bm, sh, p, ri, std::max(c, 0.0));
      if (sg.overlap != -1e300) c = std::min(c, -sg.overlap);  // -1e300: nothing within c (meshes)
    }
  }
  return c;
}

// Reach of every grain without a list entry (0 for the others); the body
// poses of this build. Off: no reach, and every grain follows the skin test.
void build_reach(const Model& m, State& s, const Grid& g) {
  s.free_grains = 0;
  if (!m.free_flight.enabled) {
    s.reach.clear();
    return;
  }
  const int n = m.n_grains;
  std::vector<uint8_t>& listed = s.reach_listed;  // scratch, capacity kept
  listed.assign(n, 0);
  const PairList& pl = s.pairs;
  for (int i = 0; i < n; ++i)
    for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k) listed[i] = listed[pl.partner[k]] = 1;
  for (int i : s.wall_pairs.grain) listed[i] = 1;
  for (int i : s.body_grains.grain) listed[i] = 1;
  s.reach.assign(n, 0.0);
  long count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (n >= m.parallel_min_grains)
  for (int i = 0; i < n; ++i) {
    if (listed[i] || held(m, i)) continue;
    s.reach[i] = grain_reach(m, s, g, i);
    ++count;
  }
  s.free_grains = count;
  s.free_grains_max = std::max(s.free_grains_max, count);
  s.body_pos_at_full.resize(m.bodies.size());
  s.body_q_at_full.resize(m.bodies.size());
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    s.body_pos_at_full[b] = s.bodies[b].pos;
    s.body_q_at_full[b] = s.bodies[b].q;
  }
}

// Largest displacement of any body point since the last full build.
double body_displacement_since_full(const Model& m, const State& s) {
  double worst = 0;
  for (size_t b = 0; b < m.bodies.size() && b < s.body_pos_at_full.size(); ++b)
    worst = std::max(worst, body_point_shift(m, s, b, s.body_pos_at_full[b], s.body_q_at_full[b]));
  return worst;
}

}  // namespace

bool lists_need_rebuild(const Model& m, const State& s) {
  if (!s.lists_valid || s.rebuild_requested) return true;
  const double half = 0.5 * m.skin;
  if (s.stats.max_disp2 > half * half) return true;  // two grains without a reach: their skin
  if (s.reach.empty() || s.free_grains == 0) return false;
  // A grain with a reach against anything else: its own displacement plus the
  // largest of any other grain or body point must stay below its reach.
  const double others = std::max(std::sqrt(std::max(s.stats.max_disp2, s.stats.max_free_disp2)),
                                 body_displacement_since_full(m, s));
  return others >= s.stats.free_margin;
}

void build_neighbour_lists(const Model& m, State& s) {
  if (m.periodic.any()) wrap_grains(m, s);
  const Grid g = bin_grains(m, s);
  build_pairs(m, s, g);
  build_walls(m, s);
  partition_work(m, s);
  s.pos_at_build = s.pos;
  s.stats.max_disp2 = 0;
  s.stats.max_free_disp2 = 0;
  s.stats.free_margin = 1e300;
  build_body_grains(m, s, g);
  build_reach(m, s, g);
  if (sleep_active(m, s)) {
    sleep_segments(m, s);  // again: the watch list includes the new grain–body entries
    s.sleep.ref_pending = true;  // the evaluated contacts of sleeping grains changed
  }
  s.lists_valid = true;
  s.rebuild_requested = false;
  ++s.rebuilds;
}

}  // namespace rt
