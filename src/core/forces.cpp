// Contacts and forces stage. Each fixed partition of the pair rows writes its
// own force buffer (partition 0 writes State::force directly); buffers are
// merged in partition order, then wall contacts are added grain by grain.
#include "regolith_twin/core/forces.hpp"
#include "regolith_twin/core/hold.hpp"

#include <algorithm>
#include <cmath>

#include "regolith_twin/core/body_collision.hpp"
#include "regolith_twin/core/contact_law.hpp"
#include "regolith_twin/core/mesh_contact.hpp"
#include "regolith_twin/core/walls.hpp"

namespace rt {
namespace {

// Law input of touching list entry k (grains i < j, d = x_j - x_i, dist2 = |d|^2).
inline PairInput pair_input(const State& s, int k, int i, int j, const Vec3& d, double dist2, double ri, double rj) {
  const double rs = ri + rj;
  const double inv_dist = 1.0 / std::sqrt(dist2);
  PairInput in;
  in.n = d * inv_dist;
  in.x = rs - dist2 * inv_dist;
  in.li = ri - 0.5 * in.x;
  in.lj = rj - 0.5 * in.x;
  in.reff = ri * rj / rs;
  in.sqrt_mstar = s.pairs.sqrt_mstar[k];
  in.vrel = s.vel[j] - s.vel[i];
  in.wi = s.omega[i];
  in.wj = s.omega[j];
  in.vrel_mid = s.vel_mid[j] - s.vel_mid[i];
  in.wi_mid = s.omega_mid[i];
  in.wj_mid = s.omega_mid[j];
  return in;
}

// Law input of grain i against a wall at gap `gap` (the wall at rest).
inline PairInput wall_input(const Model& m, const State& s, int i, const WallGap& gap) {
  const double ri = m.grain_radius[i];
  PairInput in;
  in.n = gap.n;
  in.x = gap.overlap;
  in.li = ri - 0.5 * in.x;
  in.lj = 0;
  in.reff = ri;
  in.sqrt_mstar = std::sqrt(m.grain_mass[i]);
  in.vrel = -s.vel[i];
  in.wi = s.omega[i];
  in.wj.setZero();
  in.vrel_mid = -s.vel_mid[i];
  in.wi_mid = s.omega_mid[i];
  in.wj_mid.setZero();
  return in;
}

// Grain–grain contacts of the list segments [gb, ge) (State::seg_begin,
// seg_end) into F, T: the one-pair kernel, reference of the batched one and
// the pass that logs contacts. Each owner's force is summed locally and
// added once its entries end, as the batched kernel does.
template <ContactModel M, bool Resist>
void pair_rows(const Model& m, State& s, int gb, int ge, Vec3* __restrict F, Vec3* __restrict T,
               ThreadScratch& sc) {
  PairList& pl = s.pairs;
  const double dt = m.dt;
  const int nm = m.n_materials();
  const Vec3* __restrict pos = s.pos.data();
  const double* __restrict radius = m.grain_radius.data();
  const int* __restrict material = m.grain_material.data();
  const int* __restrict partner = pl.partner.data();
  const int* __restrict owner = pl.owner.data();
  uint8_t* __restrict touching = pl.touching.data();
  const bool periodic = m.periodic.any();
  long contacts = 0;
  double max_ratio = sc.max_overlap_ratio;
  int max_grain = sc.max_overlap_grain;
  int i = -1;
  Vec3 fi = Vec3::Zero(), ti = Vec3::Zero();
  for (int seg = gb; seg < ge; ++seg)
    for (int k = s.seg_begin[seg]; k < s.seg_end[seg]; ++k) {
      if (owner[k] != i) {
        if (i >= 0) {
          F[i] += fi;
          T[i] += ti;
        }
        i = owner[k];
        fi.setZero();
        ti.setZero();
      }
      const int j = partner[k];
      Vec3 d = pos[j] - pos[i];
      if (periodic) d += m.periodic.shift(pl.image[k]);  // the partner's nearest image
      const double ri = radius[i], rj = radius[j];
      const double rs = ri + rj;
      const double dist2 = d.squaredNorm();
      if (dist2 >= rs * rs) {
        if (touching[k]) {  // contact ended: its history goes
          touching[k] = 0;
          pl.spring_t[k].setZero();
          pl.spring_r[k].setZero();
          pl.spring_w[k] = 0;
        }
        continue;
      }
      touching[k] = 1;
      const PairInput in = pair_input(s, k, i, j, d, dist2, ri, rj);
      const PairLaw& law = m.pair_law[material[i] * nm + material[j]];
      const PairOutput out =
          pair_contact<M, Resist>(law, in, PairSprings{pl.spring_t[k], pl.spring_r[k], pl.spring_w[k]}, dt);
      fi += out.force_i;
      ti += out.torque_i;
      F[j] -= out.force_i;
      T[j] += out.torque_j;
      ++contacts;
      if (s.log_contacts)
        sc.log.push_back({i, j, in.x, out.fn, out.ft.norm(), out.mr.norm(), std::fabs(out.mt), law.mu_s, law.mu_r,
                          law.mu_t, law.beta, in.reff});
      const double rmin = std::min(ri, rj);
      if (in.x > max_ratio * rmin) {
        max_ratio = in.x / rmin;
        max_grain = i;
      }
    }
  if (i >= 0) {
    F[i] += fi;
    T[i] += ti;
  }
  sc.contacts += contacts;
  sc.max_overlap_ratio = max_ratio;
  sc.max_overlap_grain = max_grain;
}

// ---------------------------------------------------------------------------
// Batched grain–grain kernel (any law, with or without rolling and twisting
// resistance; not when a contact log is kept).
//
// The list entries of a partition are walked in order, and each touching
// pair only goes into a block as its entry k and grains i, j; a full block
// is evaluated by one branch-free loop over its records that reads the grain
// and list arrays by index (the compiler vectorises it, with hardware
// gathers where the CPU has them: 4 pairs per instruction with AVX2 under
// -march=native, 2 with SSE2 in a portable build; plain C++, no
// intrinsics), and the results are then added to the force arrays in list
// order. Every record goes through the same IEEE operations in the same
// order as pair_contact (the branches of the spring rotation and of the
// Coulomb caps become selects), and the sums are formed in the same order as
// in pair_rows, so both kernels give bit-identical results
// (test/core/batched_kernel_test.cpp).

constexpr int kBlock = 64;  // records per block

struct alignas(64) ContactBlock {
  alignas(64) double c0[kBlock], c1[kBlock], c2[kBlock], c3[kBlock], mu[kBlock];  // law constants (not Uniform)
  alignas(64) double beta[kBlock], mu_r[kBlock], mu_t[kBlock];  // resistance constants (not Uniform)
  alignas(64) double rolling[kBlock], twisting[kBlock];   // 1 where the pair type has that resistance (not Uniform)
  // results
  alignas(64) double sx[kBlock], sy[kBlock], sz[kBlock];   // tangential spring after the step
  alignas(64) double rx[kBlock], ry[kBlock], rz[kBlock], tw[kBlock];  // rolling and twisting springs (Resist)
  alignas(64) double fx[kBlock], fy[kBlock], fz[kBlock];   // force on i
  alignas(64) double tix[kBlock], tiy[kBlock], tiz[kBlock];
  alignas(64) double tjx[kBlock], tjy[kBlock], tjz[kBlock];
  alignas(64) double x[kBlock];                            // overlap
  alignas(64) double rmin[kBlock];                         // smaller radius
  alignas(64) double ox[kBlock], oy[kBlock];               // periodic boxes: shift of j's image, m
  int k[kBlock], i[kBlock], j[kBlock];                     // list entry and its grains
};

// Grain and list arrays the block evaluation reads by index (flat doubles:
// component d of grain i is at 3 i + d).
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a Vec3 array is read as 3 doubles a grain");
inline const double* flat(const std::vector<Vec3>& v) { return reinterpret_cast<const double*>(v.data()); }
struct GatherSource {
  const double* __restrict pos;
  const double* __restrict radius;      // grain i's radius at i
  const double* __restrict vel;
  const double* __restrict omega;
  const double* __restrict vel_mid;
  const double* __restrict omega_mid;
  const double* __restrict spring;      // list entry k's tangential spring at 3 k
  const double* __restrict spring_r;    // list entry k's rolling spring at 3 k
  const double* __restrict spring_w;    // list entry k's twisting spring at k
  const double* __restrict sqrt_mstar;  // list entry k's sqrt(m*)
};

// detail::rotate_into_plane on one record's spring, with selects for its
// branches (same operations, same order).
__attribute__((always_inline)) inline void rotate_into_plane(double& sx, double& sy, double& sz, double nx, double ny,
                                                             double nz) {
  const double s2 = sx * sx + sy * sy + sz * sz;
  const double sn = sx * nx + sy * ny + sz * nz;
  const double px = sx - sn * nx, py = sy - sn * ny, pz = sz - sn * nz;
  const double p2 = s2 - sn * sn;
  const double g = std::sqrt(s2 / p2);
  const double qx = px * g, qy = py * g, qz = pz * g;
  const bool keep = s2 == 0.0, scale = p2 > 0.0;
  sx = keep ? sx : scale ? qx : px;
  sy = keep ? sy : scale ? qy : py;
  sz = keep ? sz : scale ? qz : pz;
}

// Scales (x, y, z) by cap / sqrt(m2) where m2, the squared magnitude being
// capped, exceeds cap2 = cap^2.
__attribute__((always_inline)) inline void scale_to_cap(double& x, double& y, double& z, double m2, double cap,
                                                        double cap2) {
  const double g = cap / std::sqrt(m2);
  const double cx = x * g, cy = y * g, cz = z * g;
  const bool over = m2 > cap2;
  x = over ? cx : x;
  y = over ? cy : y;
  z = over ? cz : z;
}

// A resisting moment m on i (and -m on j) where the pair type has it.
__attribute__((always_inline)) inline void add_moment(bool on, double mx, double my, double mz, double& tix,
                                                      double& tiy, double& tiz, double& tjx, double& tjy,
                                                      double& tjz) {
  tix = on ? tix + mx : tix;
  tiy = on ? tiy + my : tiy;
  tiz = on ? tiz + mz : tiz;
  tjx = on ? tjx - mx : tjx;
  tjy = on ? tjy - my : tjy;
  tjz = on ? tjz - mz : tjz;
}

// detail::slider on one record, with selects for its branches: advances the
// spring s by the mid-step rate, caps it, and returns in t the capped
// k s + c rate.
__attribute__((always_inline)) inline void slider(double& sx, double& sy, double& sz, double mx, double my, double mz,
                                                  double ux, double uy, double uz, double k, double c, double cap,
                                                  double dt, double& tx, double& ty, double& tz) {
  const double cap2 = cap * cap;
  sx += mx * dt;
  sy += my * dt;
  sz += mz * dt;
  scale_to_cap(sx, sy, sz, k * k * (sx * sx + sy * sy + sz * sz), cap, cap2);  // the spring
  tx = k * sx + c * ux;
  ty = k * sy + c * uy;
  tz = k * sz + c * uz;
  scale_to_cap(tx, ty, tz, tx * tx + ty * ty + tz * tz, cap, cap2);  // spring and dashpot
}

// pair_contact<M, Resist> for records [0, nb) of a block. Law constants:
// linear c0..c3 = kn, kt, cn_coef, ct_coef; Hertz–Mindlin c0..c2 = E*, G*, hm_damp;
// per record, or the same for all (Uniform: every grain has one material).
// With Resist, rolling and twisting resistance as in pair_contact<M, true>.
template <ContactModel M, bool Uniform, bool Resist, bool Periodic>
void evaluate_block(ContactBlock& b, int nb, double dt, const PairLaw& uniform_law, const GatherSource& g) {
  const double u0 = M == ContactModel::Linear ? uniform_law.kn : uniform_law.e_star;
  const double u1 = M == ContactModel::Linear ? uniform_law.kt : uniform_law.g_star;
  const double u2 = M == ContactModel::Linear ? uniform_law.cn_coef : uniform_law.hm_damp;
  const double u3 = uniform_law.ct_coef, umu = uniform_law.mu_s;
  const double ubeta = uniform_law.beta, umu_r = uniform_law.mu_r, umu_t = uniform_law.mu_t;
  const bool uroll = uniform_law.rolling, utwist = uniform_law.twisting;
#pragma omp simd
  for (int c = 0; c < nb; ++c) {
    const double c0 = Uniform ? u0 : b.c0[c], c1 = Uniform ? u1 : b.c1[c], c2 = Uniform ? u2 : b.c2[c],
                 c3 = Uniform ? u3 : b.c3[c], mu = Uniform ? umu : b.mu[c];
    // Geometry (pair_rows).
    const int gi = 3 * b.i[c], gj = 3 * b.j[c], gk = 3 * b.k[c];
    double dx = g.pos[gj] - g.pos[gi], dy = g.pos[gj + 1] - g.pos[gi + 1];
    const double dz = g.pos[gj + 2] - g.pos[gi + 2];
    if constexpr (Periodic) {  // the partner's nearest image (pair_rows)
      dx += b.ox[c];
      dy += b.oy[c];
    }
    const double ri = g.radius[b.i[c]], rj = g.radius[b.j[c]];
    const double rs = ri + rj;
    const double dist2 = dx * dx + dy * dy + dz * dz;
    const double inv_dist = 1.0 / std::sqrt(dist2);
    const double nx = dx * inv_dist, ny = dy * inv_dist, nz = dz * inv_dist;
    const double x = rs - dist2 * inv_dist;
    const double li = ri - 0.5 * x, lj = rj - 0.5 * x;
    const double sm = g.sqrt_mstar[b.k[c]];
    const double vx = g.vel[gj] - g.vel[gi], vy = g.vel[gj + 1] - g.vel[gi + 1], vz = g.vel[gj + 2] - g.vel[gi + 2];
    const double wix = g.omega[gi], wiy = g.omega[gi + 1], wiz = g.omega[gi + 2];
    const double wjx = g.omega[gj], wjy = g.omega[gj + 1], wjz = g.omega[gj + 2];
    const double mvx = g.vel_mid[gj] - g.vel_mid[gi], mvy = g.vel_mid[gj + 1] - g.vel_mid[gi + 1],
                 mvz = g.vel_mid[gj + 2] - g.vel_mid[gi + 2];
    const double mwix = g.omega_mid[gi], mwiy = g.omega_mid[gi + 1], mwiz = g.omega_mid[gi + 2];
    const double mwjx = g.omega_mid[gj], mwjy = g.omega_mid[gj + 1], mwjz = g.omega_mid[gj + 2];
    // law_terms
    const double reff = ri * rj / rs;  // (Hertz–Mindlin and resistance only)
    double fn_el, kn_eff, kt, cn, ct;
    if constexpr (M == ContactModel::Linear) {
      kn_eff = c0;
      fn_el = c0 * x;
      kt = c1;
      cn = c2 * sm;
      ct = c3 * sm;
    } else {
      const double a = std::sqrt(reff * x);
      kn_eff = 2.0 * c0 * a;
      fn_el = (2.0 / 3.0) * kn_eff * x;
      kt = 8.0 * c1 * a;
      cn = c2 * std::sqrt(kn_eff) * sm;
      ct = cn;
    }
    // Contact-point velocities: u = vrel - (lj wj + li wi) x n, normal and tangential parts.
    const double ax = lj * wjx + li * wix, ay = lj * wjy + li * wiy,
                 az = lj * wjz + li * wiz;
    const double ux = vx - (ay * nz - az * ny), uy = vy - (az * nx - ax * nz),
                 uz = vz - (ax * ny - ay * nx);
    const double un = ux * nx + uy * ny + uz * nz;
    const double utx = ux - un * nx, uty = uy - un * ny, utz = uz - un * nz;
    const double bx = lj * mwjx + li * mwix, by = lj * mwjy + li * mwiy,
                 bz = lj * mwjz + li * mwiz;
    const double mx = mvx - (by * nz - bz * ny), my = mvy - (bz * nx - bx * nz),
                 mz = mvz - (bx * ny - by * nx);
    const double mn = mx * nx + my * ny + mz * nz;
    const double mtx = mx - mn * nx, mty = my - mn * ny, mtz = mz - mn * nz;
    // Normal force on i and the magnitude used for the friction limit.
    const double fnn = -fn_el + cn * un;
    double fx = fnn * nx, fy = fnn * ny, fz = fnn * nz;
    const double fn_arg = fn_el - cn * un;
    const double fn = 0.0 < fn_arg ? fn_arg : 0.0;  // std::max(0.0, fn_arg)
    // Tangential spring: detail::rotate_into_plane, then detail::slider
    // with k = kt, c = ct, cap = mu_s fn.
    double sx = g.spring[gk], sy = g.spring[gk + 1], sz = g.spring[gk + 2];
    rotate_into_plane(sx, sy, sz, nx, ny, nz);
    double tx, ty, tz;
    slider(sx, sy, sz, mtx, mty, mtz, utx, uty, utz, kt, ct, mu * fn, dt, tx, ty, tz);
    b.sx[c] = sx;
    b.sy[c] = sy;
    b.sz[c] = sz;
    fx += tx;
    fy += ty;
    fz += tz;
    // Torques: n x ft times the lever arms.
    const double qx = ny * tz - nz * ty, qy = nz * tx - nx * tz, qz = nx * ty - ny * tx;
    b.fx[c] = fx;
    b.fy[c] = fy;
    b.fz[c] = fz;
    double tix = li * qx, tiy = li * qy, tiz = li * qz;
    double tjx = lj * qx, tjy = lj * qy, tjz = lj * qz;
    if constexpr (Resist) {
      const double beta = Uniform ? ubeta : b.beta[c], mu_r = Uniform ? umu_r : b.mu_r[c],
                   mu_t = Uniform ? umu_t : b.mu_t[c];
      const bool rolling = Uniform ? uroll : b.rolling[c] != 0.0, twisting = Uniform ? utwist : b.twisting[c] != 0.0;
      const double br = beta * reff;
      const double br2 = br * br;
      // Relative spin, end of step and mid-step, and its normal (twisting) part.
      const double wx = wjx - wix, wy = wjy - wiy, wz = wjz - wiz;
      const double mwx = mwjx - mwix, mwy = mwjy - mwiy, mwz = mwjz - mwiz;
      const double wn = wx * nx + wy * ny + wz * nz, wn_mid = mwx * nx + mwy * ny + mwz * nz;
      // Rolling: detail::rotate_into_plane, then detail::slider with
      // k = kn_eff br^2, c = cn br^2, cap = mu_r br fn.
      {
        const double wrx = wx - wn * nx, wry = wy - wn * ny, wrz = wz - wn * nz;
        const double mrx = mwx - wn_mid * nx, mry = mwy - wn_mid * ny, mrz = mwz - wn_mid * nz;
        const double r0x = g.spring_r[gk], r0y = g.spring_r[gk + 1], r0z = g.spring_r[gk + 2];
        double rx = r0x, ry = r0y, rz = r0z;
        rotate_into_plane(rx, ry, rz, nx, ny, nz);
        double mx, my, mz;
        slider(rx, ry, rz, mrx, mry, mrz, wrx, wry, wrz, kn_eff * br2, cn * br2, mu_r * br * fn, dt, mx, my, mz);
        b.rx[c] = rolling ? rx : r0x;
        b.ry[c] = rolling ? ry : r0y;
        b.rz[c] = rolling ? rz : r0z;
        add_moment(rolling, mx, my, mz, tix, tiy, tiz, tjx, tjy, tjz);
      }
      // Twisting: detail::slider1 with k = 2 kt br^2, c = 2 ct br^2,
      // cap = mu_t br mu_s fn.
      {
        const double t0 = g.spring_w[b.k[c]];
        double ts = t0;
        const double k_t = 2.0 * kt * br2, c_t = 2.0 * ct * br2, cap_t = mu_t * br * mu * fn;
        ts += wn_mid * dt;
        const double ks = k_t * std::fabs(ts);
        const double gt = cap_t / ks;
        ts = ks > cap_t ? ts * gt : ts;
        double mt = k_t * ts + c_t * wn;
        mt = std::fabs(mt) > cap_t ? std::copysign(cap_t, mt) : mt;
        b.tw[c] = twisting ? ts : t0;
        add_moment(twisting, mt * nx, mt * ny, mt * nz, tix, tiy, tiz, tjx, tjy, tjz);
      }
    }
    b.tix[c] = tix;
    b.tiy[c] = tiy;
    b.tiz[c] = tiz;
    b.tjx[c] = tjx;
    b.tjy[c] = tjy;
    b.tjz[c] = tjz;
    b.x[c] = x;
    b.rmin[c] = rj < ri ? rj : ri;  // std::min(ri, rj)
  }
}

// Running sums of one partition: the open row's force and torque, the
// overlap statistics.
struct RowSums {
  int i = -1;
  Vec3 fi = Vec3::Zero(), ti = Vec3::Zero();
  double max_ratio;
  int max_grain;
};

// Evaluate a block and add its results in list order, as pair_rows does.
template <ContactModel M, bool Uniform, bool Resist, bool Periodic>
void flush_block(ContactBlock& b, int nb, double dt, const PairLaw& uniform_law, const GatherSource& g, PairList& pl,
                 Vec3* __restrict F, Vec3* __restrict T, RowSums& r) {
  evaluate_block<M, Uniform, Resist, Periodic>(b, nb, dt, uniform_law, g);
  Vec3* __restrict spring = pl.spring_t.data();
  for (int c = 0; c < nb; ++c) {
    spring[b.k[c]] = Vec3(b.sx[c], b.sy[c], b.sz[c]);
    if constexpr (Resist) {
      pl.spring_r[b.k[c]] = Vec3(b.rx[c], b.ry[c], b.rz[c]);
      pl.spring_w[b.k[c]] = b.tw[c];
    }
    const int i = b.i[c], j = b.j[c];
    if (i != r.i) {
      if (r.i >= 0) {
        F[r.i] += r.fi;
        T[r.i] += r.ti;
      }
      r.i = i;
      r.fi.setZero();
      r.ti.setZero();
    }
    const Vec3 f(b.fx[c], b.fy[c], b.fz[c]);
    r.fi += f;
    r.ti += Vec3(b.tix[c], b.tiy[c], b.tiz[c]);
    F[j] -= f;
    T[j] += Vec3(b.tjx[c], b.tjy[c], b.tjz[c]);
    const double rmin = b.rmin[c];
    if (b.x[c] > r.max_ratio * rmin) {
      r.max_ratio = b.x[c] / rmin;
      r.max_grain = i;
    }
  }
}

template <ContactModel M, bool Uniform, bool Resist, bool Periodic>
void pair_rows_batched(const Model& m, State& s, int gb, int ge, Vec3* __restrict F, Vec3* __restrict T,
                       ThreadScratch& sc) {
  PairList& pl = s.pairs;
  const PairLaw& uniform_law = m.pair_law[Uniform ? m.single_grain_material * (m.n_materials() + 1) : 0];
  const double dt = m.dt;
  const int nm = m.n_materials();
  const Vec3* __restrict pos = s.pos.data();
  const double* __restrict radius = m.grain_radius.data();
  const int* __restrict material = m.grain_material.data();
  const int* __restrict partner = pl.partner.data();
  const int* __restrict owner = pl.owner.data();
  const double* __restrict sqrt_mstar = pl.sqrt_mstar.data();
  uint8_t* __restrict touching = pl.touching.data();
  Vec3* __restrict spring_t = pl.spring_t.data();
  Vec3 image_shift[9];  // periodic boxes: shift of each image code + 4
  if constexpr (Periodic)
    for (int c = 0; c < 9; ++c) image_shift[c] = m.periodic.shift(c - 4);
  const GatherSource g{flat(s.pos),     radius,           flat(s.vel), flat(s.omega),
                       flat(s.vel_mid), flat(s.omega_mid), flat(pl.spring_t), flat(pl.spring_r),
                       pl.spring_w.data(),  sqrt_mstar};
  ContactBlock b;
  int nb = 0;
  long contacts = 0;
  RowSums r;
  r.max_ratio = sc.max_overlap_ratio;
  r.max_grain = sc.max_overlap_grain;
  // The entries of rows [rb, re) go in chunks that fit the block. The first
  // loop tests the distance of every entry and appends each touching one
  // without a branch (the record is written at nb either way, nb advances
  // only when touching), so the entries that do not touch (1 in 4 in a
  // settled bed) cost no mispredicted jump, nor do the ends of rows.
  for (int seg = gb; seg < ge; ++seg)
  for (int k0 = s.seg_begin[seg], kend_rows = s.seg_end[seg]; k0 < kend_rows;) {
    if (nb == kBlock) {
      flush_block<M, Uniform, Resist, Periodic>(b, nb, dt, uniform_law, g, pl, F, T, r);
      nb = 0;
    }
    const int kend = std::min(kend_rows, k0 + (kBlock - nb));
    const int nb0 = nb;
    for (int k = k0; k < kend; ++k) {
      const int i = owner[k], j = partner[k];
      Vec3 d = pos[j] - pos[i];
      if constexpr (Periodic) {
        const Vec3 o = image_shift[pl.image[k] + 4];
        d.x() += o.x();
        d.y() += o.y();
        b.ox[nb] = o.x();
        b.oy[nb] = o.y();
      }
      const double rs = radius[i] + radius[j];
      const double dist2 = d.squaredNorm();
      const bool touch = dist2 < rs * rs;
      if (touching[k] && !touch) {  // contact ended: its history goes (rare)
        spring_t[k].setZero();
        pl.spring_r[k].setZero();
        pl.spring_w[k] = 0;
      }
      touching[k] = touch;
      b.k[nb] = k;
      b.i[nb] = i;
      b.j[nb] = j;
      nb += touch;
    }
    if constexpr (!Uniform) {
      for (int c = nb0; c < nb; ++c) {
        const PairLaw& law = m.pair_law[material[b.i[c]] * nm + material[b.j[c]]];
        if constexpr (M == ContactModel::Linear) {
          b.c0[c] = law.kn;
          b.c1[c] = law.kt;
          b.c2[c] = law.cn_coef;
          b.c3[c] = law.ct_coef;
        } else {
          b.c0[c] = law.e_star;
          b.c1[c] = law.g_star;
          b.c2[c] = law.hm_damp;
          b.c3[c] = 0;
        }
        b.mu[c] = law.mu_s;
        if constexpr (Resist) {
          b.beta[c] = law.beta;
          b.mu_r[c] = law.mu_r;
          b.mu_t[c] = law.mu_t;
          b.rolling[c] = law.rolling;
          b.twisting[c] = law.twisting;
        }
      }
    }
    contacts += nb - nb0;
    k0 = kend;
  }
  if (nb) flush_block<M, Uniform, Resist, Periodic>(b, nb, dt, uniform_law, g, pl, F, T, r);
  if (r.i >= 0) {
    F[r.i] += r.fi;
    T[r.i] += r.ti;
  }
  sc.contacts += contacts;
  sc.max_overlap_ratio = r.max_ratio;
  sc.max_overlap_grain = r.max_grain;
}

// A list entry whose contact ended loses its spring history.
template <class List>
inline void end_contact(List& l, int k) {
  if (!l.touching[k]) return;
  l.touching[k] = 0;
  l.spring_t[k].setZero();
  l.spring_r[k].setZero();
  l.spring_w[k] = 0;
}

// Grain–wall contacts of wall-list entries [kb, ke) into State::force.
template <ContactModel M, bool Resist>
void wall_entries(const Model& m, State& s, int kb, int ke, ThreadScratch& sc) {
  WallList& wl = s.wall_pairs;
  const double dt = m.dt;
  const uint8_t* asleep = sleep_active(m, s) ? s.sleep.asleep.data() : nullptr;
  for (int k = kb; k < ke; ++k) {
    const int i = wl.grain[k];
    if (asleep && asleep[i]) continue;  // a sleeping grain's wall contacts do not change (model.md §16)
    const Wall& w = m.walls[wl.wall[k]];
    const double ri = m.grain_radius[i];
    const WallGap gap = wall_gap(w, s.pos[i], ri);
    if (gap.overlap <= 0) {
      end_contact(wl, k);
      continue;
    }
    wl.touching[k] = 1;
    const PairInput in = wall_input(m, s, i, gap);
    const PairLaw& law = m.law(m.grain_material[i], w.law_material);
    const PairOutput out =
        pair_contact<M, Resist>(law, in, PairSprings{wl.spring_t[k], wl.spring_r[k], wl.spring_w[k]}, dt);
    s.force[i] += out.force_i;
    s.torque[i] += out.torque_i;
    sc.wall_force += out.force_i;
    ++sc.contacts;
    if (s.log_contacts)
      sc.log.push_back({i, -1 - wl.wall[k], in.x, out.fn, out.ft.norm(), out.mr.norm(), std::fabs(out.mt), law.mu_s,
                        law.mu_r, law.mu_t, law.beta, in.reff});
    const double ratio = in.x / ri;
    if (ratio > sc.max_overlap_ratio) {
      sc.max_overlap_ratio = ratio;
      sc.max_overlap_grain = i;
    }
  }
}

// One touching contact of grain i with body b: the law with the body side
// moving with the body's velocity at the contact point (body_entries).
template <ContactModel M, bool Resist>
inline void grain_body_contact(const Model& m, State& s, int i, int b, double sqrt_mstar, const Vec3& n, double x,
                               PairSprings springs, ThreadScratch& sc) {
  const BodyModel& bm = m.bodies[b];
  const BodyState& bs = s.bodies[b];
  const double ri = m.grain_radius[i];
  PairInput in;
  in.n = n;
  in.x = x;
  in.li = ri - 0.5 * in.x;
  in.lj = 0;
  in.reff = ri;
  in.sqrt_mstar = sqrt_mstar;
  const Vec3 arm = s.pos[i] + in.li * in.n - bs.pos;  // contact point from the body's centre of mass
  in.vrel = bs.vel + bs.omega.cross(arm) - s.vel[i];
  in.wi = s.omega[i];
  in.wj = bs.omega;
  in.vrel_mid = bs.vel_mid + bs.omega_mid.cross(arm) - s.vel_mid[i];
  in.wi_mid = s.omega_mid[i];
  in.wj_mid = bs.omega_mid;
  const PairLaw& law = m.law(m.grain_material[i], bm.material);
  const PairOutput out = pair_contact<M, Resist>(law, in, springs, m.dt);
  s.force[i] += out.force_i;
  s.torque[i] += out.torque_i;
  sc.body_force[b] -= out.force_i;
  sc.body_torque[b] += out.torque_j - arm.cross(out.force_i);
  ++sc.contacts;
  if (s.log_contacts)
    sc.log.push_back({i, -1000000 - b, in.x, out.fn, out.ft.norm(), out.mr.norm(), std::fabs(out.mt), law.mu_s,
                      law.mu_r, law.mu_t, law.beta, in.reff});
  const double ratio = in.x / ri;
  if (ratio > sc.max_overlap_ratio) {
    sc.max_overlap_ratio = ratio;
    sc.max_overlap_grain = i;
  }
}

// A contact keeps the slot whose normal (body frame) is within this cosine
// of its own, best matches first: about 26 degrees, far more than a normal
// turns in one step while a grain rolls over an edge, far less than the
// angle between two faces it touches at once in a corner.
constexpr double kSlotMatch = 0.9;

// Grain–mesh entry k: every touched feature (mesh_hits) is one contact;
// each takes the history slot whose normal matches its own (docs/model.md
// §6.3), new contacts take a free slot, slots left unmatched end. A contact
// beyond kMeshSlots (not met in practice) is evaluated without history.
template <ContactModel M, bool Resist>
void mesh_entry(const Model& m, State& s, int k, ThreadScratch& sc) {
  BodyGrainList& bl = s.body_grains;
  const int i = bl.grain[k], b = bl.body[k];
  const BodyModel& bm = m.bodies[b];
  const BodyState& bs = s.bodies[b];
  const Shape& sh = bm.shapes[bl.shape[k]];
  const Vec3 pb = bs.q.conjugate() * (s.pos[i] - bs.pos);  // body frame
  const int nh = mesh_hits(*bm.surfaces[sh.mesh], sh.rot.conjugate() * (pb - sh.pos), m.grain_radius[i], sc.mesh_tris,
                           sc.mesh_hits);
  MeshSlot* slot = &bl.mesh_slots[bl.mesh_first[k]];
  if (nh == 0) {
    if (bl.touching[k]) {
      bl.touching[k] = 0;
      for (int q = 0; q < kMeshSlots; ++q) slot[q] = MeshSlot{};
    }
    return;
  }
  bl.touching[k] = 1;
  MeshHit* hits = sc.mesh_hits.data();
  for (int h = 0; h < nh; ++h) {
    hits[h].n = sh.rot * hits[h].n;  // body frame from here on
    hits[h].slot = -1;
  }
  // Match contacts to live slots, best pair first.
  bool taken[kMeshSlots] = {};
  for (;;) {
    double best = kSlotMatch;
    int bh = -1, bq = -1;
    for (int h = 0; h < nh; ++h) {
      if (hits[h].slot >= 0) continue;
      for (int q = 0; q < kMeshSlots; ++q) {
        if (taken[q] || !slot[q].touching) continue;
        const double d = slot[q].normal.dot(hits[h].n);
        if (d > best) {
          best = d;
          bh = h;
          bq = q;
        }
      }
    }
    if (bh < 0) break;
    hits[bh].slot = bq;
    taken[bq] = true;
  }
  for (int q = 0; q < kMeshSlots; ++q)
    if (!taken[q] && slot[q].touching) slot[q] = MeshSlot{};  // the contact ended
  for (int h = 0, q = 0; h < nh; ++h) {
    if (hits[h].slot >= 0) continue;
    while (q < kMeshSlots && taken[q]) ++q;
    if (q == kMeshSlots) break;
    hits[h].slot = q;
    taken[q] = true;
  }
  for (int h = 0; h < nh; ++h) {
    const MeshHit& hit = hits[h];
    Vec3 st = Vec3::Zero(), sr = Vec3::Zero();
    double sw = 0;
    MeshSlot* sl = hit.slot >= 0 ? &slot[hit.slot] : nullptr;
    PairSprings springs = sl ? PairSprings{sl->spring_t, sl->spring_r, sl->spring_w} : PairSprings{st, sr, sw};
    grain_body_contact<M, Resist>(m, s, i, b, bl.sqrt_mstar[k], bs.q * hit.n, hit.overlap, springs, sc);
    if (sl) {
      sl->normal = hit.n;
      sl->touching = 1;
    }
  }
}

// Grain–body contacts of list entries [kb, ke): the grain's force goes to
// State::force, the reaction to this partition's body accumulators. The body
// side of the contact moves with the body's velocity at the contact point;
// lever arm l_j = 0 and R = r_i, as for a wall (docs/model.md §5).
template <ContactModel M, bool Resist>
void body_entries(const Model& m, State& s, int kb, int ke, ThreadScratch& sc) {
  BodyGrainList& bl = s.body_grains;
  for (int k = kb; k < ke; ++k) {
    if (bl.mesh_first[k] >= 0) {
      mesh_entry<M, Resist>(m, s, k, sc);
      continue;
    }
    const int i = bl.grain[k], b = bl.body[k];
    const BodyModel& bm = m.bodies[b];
    const BodyState& bs = s.bodies[b];
    const double ri = m.grain_radius[i];
    const ShapeGap gap = shape_gap(bm, bm.shapes[bl.shape[k]], bs.q.conjugate() * (s.pos[i] - bs.pos), ri);
    if (gap.overlap <= 0) {
      end_contact(bl, k);
      continue;
    }
    bl.touching[k] = 1;
    grain_body_contact<M, Resist>(m, s, i, b, bl.sqrt_mstar[k], bs.q * gap.n, gap.overlap,
                                  PairSprings{bl.spring_t[k], bl.spring_r[k], bl.spring_w[k]}, sc);
  }
}

template <ContactModel M, bool Resist>
void force_pass(const Model& m, State& s) {
  const int P = m.partitions;
  const int n = m.n_grains;
  for (auto& sc : s.scratch) {
    if (s.log_contacts) sc.log.clear();
    sc.contacts = 0;
    sc.max_overlap_ratio = 0;
    sc.max_overlap_grain = -1;
    sc.wall_force.setZero();
    std::fill(sc.body_force.begin(), sc.body_force.end(), Vec3::Zero());
    std::fill(sc.body_torque.begin(), sc.body_torque.end(), Vec3::Zero());
  }
  const bool bodies = !m.bodies.empty();
  const bool batched = !s.log_contacts && !s.scalar_kernel;
  const bool periodic = m.periodic.any();
  const bool sleeping = sleep_active(m, s);
  long wall_contacts = 0, body_contacts = 0;
#pragma omp parallel if (n >= m.parallel_min_grains)
  {
    // Grain–grain contacts, one partition at a time. The schedule is static:
    // a thread takes the same partitions and merge blocks every step, and
    // the integrator's static halves nearly coincide with them, so a
    // thread's grains' data stay in its own core's cache (why it matters:
    // docs/bench/b1_throughput.md). No schedule changes any result.
#pragma omp for schedule(static)
    for (int p = 0; p < P; ++p) {
      ThreadScratch& sc = s.scratch[p];
      Vec3* F = p == 0 ? s.force.data() : sc.force.data();
      Vec3* T = p == 0 ? s.torque.data() : sc.torque.data();
      // Partition 0 writes State::force, cleared here over its own range
      // (the rest by the merge below); the other partitions' buffers are
      // all zero already, as the merge clears what it has read.
      if (p == 0) {
        std::fill(F + sc.touched_lo, F + sc.touched_hi, Vec3::Zero());
        std::fill(T + sc.touched_lo, T + sc.touched_hi, Vec3::Zero());
      }
      const int gb = s.thread_seg_begin[p], ge = s.thread_seg_begin[p + 1];
      if (batched && periodic && m.single_grain_material >= 0)
        pair_rows_batched<M, true, Resist, true>(m, s, gb, ge, F, T, sc);
      else if (batched && periodic)
        pair_rows_batched<M, false, Resist, true>(m, s, gb, ge, F, T, sc);
      else if (batched && m.single_grain_material >= 0)
        pair_rows_batched<M, true, Resist, false>(m, s, gb, ge, F, T, sc);
      else if (batched)
        pair_rows_batched<M, false, Resist, false>(m, s, gb, ge, F, T, sc);
      else
        pair_rows<M, Resist>(m, s, gb, ge, F, T, sc);
    }  // (implied barrier)
    // Merge and walls, one block of grains at a time per thread (block q is
    // grains [n q/P, n (q+1)/P) and the wall entries of those grains): every
    // grain sums the partition buffers in partition order, then its wall
    // contacts in list order, whatever the thread count, and no two threads
    // write one grain.
    const int hi0 = s.scratch[0].touched_hi;
    Vec3* __restrict force = s.force.data();
    Vec3* __restrict torque = s.torque.data();
#pragma omp for schedule(static)
    for (int q = 0; q < P; ++q) {
      const int gb = int(long(n) * q / P), ge = int(long(n) * (q + 1) / P);
      if (ge > hi0) {
        std::fill(force + std::max(gb, hi0), force + ge, Vec3::Zero());
        std::fill(torque + std::max(gb, hi0), torque + ge, Vec3::Zero());
      }
      for (int p = 1; p < P; ++p) {
        ThreadScratch& sc = s.scratch[p];
        Vec3* __restrict pf = sc.force.data();
        Vec3* __restrict pt = sc.torque.data();
        if (sleeping) {  // the grains it wrote, from its list (the same sums, in the same order)
          const auto b = std::lower_bound(sc.touched.begin(), sc.touched.end(), gb);
          const auto e = std::lower_bound(b, sc.touched.end(), ge);
          for (auto it = b; it != e; ++it) {
            const int i = *it;
            force[i] += pf[i];
            torque[i] += pt[i];
            pf[i].setZero();
            pt[i].setZero();
          }
          continue;
        }
        const int lo = std::max(gb, sc.touched_lo), hi = std::min(ge, sc.touched_hi);
        for (int i = lo; i < hi; ++i) {
          force[i] += pf[i];
          torque[i] += pt[i];
          pf[i].setZero();  // ready for the next pass (its writes lie in its touched range)
          pt[i].setZero();
        }
      }
      // Contact counts of walls go to a separate total.
      ThreadScratch& sc = s.scratch[q];
      const long before = sc.contacts;
      wall_entries<M, Resist>(m, s, s.thread_wall_begin[q], s.thread_wall_begin[q + 1], sc);
#pragma omp atomic
      wall_contacts += sc.contacts - before;
    }
    // (implied barrier)
    if (bodies) {
      // Grain–body contacts, after every wall contact has been added.
#pragma omp for schedule(static)
      for (int p = 0; p < P; ++p) {
        ThreadScratch& sc = s.scratch[p];
        const long before = sc.contacts;
        body_entries<M, Resist>(m, s, s.thread_body_begin[p], s.thread_body_begin[p + 1], sc);
#pragma omp atomic
        body_contacts += sc.contacts - before;
      }
    }
  }
  // Body wrenches: grain reactions merged in partition order, then body–body contacts.
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    BodyState& bs = s.bodies[b];
    bs.force.setZero();
    bs.torque.setZero();
    for (const auto& sc : s.scratch) {
      bs.force += sc.body_force[b];
      bs.torque += sc.body_torque[b];
    }
  }
  if (m.bodies.size() > 1) body_body_forces(m, s);
  StepStats& st = s.stats;
  st.contacts = 0;
  st.max_overlap_ratio = 0;
  st.max_overlap_grain = -1;
  s.wall_force.setZero();
  for (const auto& sc : s.scratch) {
    st.contacts += sc.contacts;
    s.wall_force += sc.wall_force;
    if (sc.max_overlap_ratio > st.max_overlap_ratio) {
      st.max_overlap_ratio = sc.max_overlap_ratio;
      st.max_overlap_grain = sc.max_overlap_grain;
    }
  }
  st.wall_contacts = wall_contacts;
  st.body_contacts = body_contacts;
  st.contacts -= wall_contacts + body_contacts;
}

// Contacts of woken grains that the last pass did not evaluate (both grains
// at rest: springs held, as copies), added to the woken grains' forces.
template <ContactModel M, bool Resist>
void woken_contacts(const Model& m, State& s, const std::vector<uint8_t>& woken) {
  const PairList& pl = s.pairs;
  const double dt = m.dt;
  const int nm = m.n_materials();
  // Idle before the wake: asleep then (still asleep, or woken now) or glued.
  const auto idle_before = [&](int i) { return s.sleep.asleep[i] || woken[i] || held(m, i); };
  for (int k = 0; k < pl.size(); ++k) {
    const int i = pl.owner[k], j = pl.partner[k];
    if (!(woken[i] || woken[j]) || !idle_before(i) || !idle_before(j)) continue;
    const Vec3 d = s.pos[j] - s.pos[i];
    const double ri = m.grain_radius[i], rj = m.grain_radius[j], rs = ri + rj;
    const double dist2 = d.squaredNorm();
    if (dist2 >= rs * rs) continue;
    const PairInput in = pair_input(s, k, i, j, d, dist2, ri, rj);
    Vec3 st = pl.spring_t[k], sr = pl.spring_r[k];
    double sw = pl.spring_w[k];
    const PairLaw& law = m.pair_law[m.grain_material[i] * nm + m.grain_material[j]];
    const PairOutput out = pair_contact<M, Resist>(law, in, PairSprings{st, sr, sw}, dt);
    if (woken[i]) {
      s.force[i] += out.force_i;
      s.torque[i] += out.torque_i;
    }
    if (woken[j]) {
      s.force[j] -= out.force_i;
      s.torque[j] += out.torque_j;
    }
  }
  const WallList& wl = s.wall_pairs;
  for (int k = 0; k < wl.size(); ++k) {
    const int i = wl.grain[k];
    if (!woken[i]) continue;
    const Wall& w = m.walls[wl.wall[k]];
    const double ri = m.grain_radius[i];
    const WallGap gap = wall_gap(w, s.pos[i], ri);
    if (gap.overlap <= 0) continue;
    const PairInput in = wall_input(m, s, i, gap);
    Vec3 st = wl.spring_t[k], sr = wl.spring_r[k];
    double sw = wl.spring_w[k];
    const PairLaw& law = m.law(m.grain_material[i], w.law_material);
    const PairOutput out = pair_contact<M, Resist>(law, in, PairSprings{st, sr, sw}, dt);
    s.force[i] += out.force_i;
    s.torque[i] += out.torque_i;
  }
}

}  // namespace

void add_woken_contacts(const Model& m, State& s, const std::vector<uint8_t>& woken) {
  const bool resist = m.any_resistance;
  if (m.contact_model == ContactModel::Linear) {
    resist ? woken_contacts<ContactModel::Linear, true>(m, s, woken)
           : woken_contacts<ContactModel::Linear, false>(m, s, woken);
  } else {
    resist ? woken_contacts<ContactModel::HertzMindlin, true>(m, s, woken)
           : woken_contacts<ContactModel::HertzMindlin, false>(m, s, woken);
  }
}

void compute_forces(const Model& m, State& s) {
  const bool resist = m.any_resistance;
  if (m.contact_model == ContactModel::Linear) {
    resist ? force_pass<ContactModel::Linear, true>(m, s) : force_pass<ContactModel::Linear, false>(m, s);
  } else {
    resist ? force_pass<ContactModel::HertzMindlin, true>(m, s)
           : force_pass<ContactModel::HertzMindlin, false>(m, s);
  }
  s.forces_valid = true;
}

}  // namespace rt
