// Contacts and forces stage. Each fixed partition of the pair rows writes its
// own force buffer (partition 0 writes State::force directly); buffers are
// merged in partition order, then wall contacts are added grain by grain.
#include "regolith_twin/core/forces.hpp"

#include <algorithm>
#include <cmath>

#include "regolith_twin/core/body_collision.hpp"
#include "regolith_twin/core/contact_law.hpp"
#include "regolith_twin/core/walls.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace rt {
namespace {

int thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}
int thread_count() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

// Grain–grain contacts of rows [rb, re) into F, T. Arrays are taken as
// restrict pointers and row i's force is summed locally, so the compiler
// keeps grain i in registers while it walks the row.
template <ContactModel M, bool Resist>
void pair_rows(const Model& m, State& s, int rb, int re, Vec3* __restrict F, Vec3* __restrict T,
               ThreadScratch& sc) {
  PairList& pl = s.pairs;
  const double dt = m.dt;
  const int nm = m.n_materials();
  const Vec3* __restrict pos = s.pos.data();
  const Vec3* __restrict vel = s.vel.data();
  const Vec3* __restrict omega = s.omega.data();
  const Vec3* __restrict vel_mid = s.vel_mid.data();
  const Vec3* __restrict omega_mid = s.omega_mid.data();
  const double* __restrict radius = m.grain_radius.data();
  const int* __restrict material = m.grain_material.data();
  const int* __restrict partner = pl.partner.data();
  const int* __restrict row = pl.row_start.data();
  uint8_t* __restrict touching = pl.touching.data();
  long contacts = 0;
  double max_ratio = sc.max_overlap_ratio;
  int max_grain = sc.max_overlap_grain;
  for (int i = rb; i < re; ++i) {
    const Vec3 xi = pos[i], vi = vel[i], wi = omega[i], vi_mid = vel_mid[i], wi_mid = omega_mid[i];
    const double ri = radius[i];
    const PairLaw* laws = &m.pair_law[material[i] * nm];
    Vec3 fi = Vec3::Zero(), ti = Vec3::Zero();
    for (int k = row[i]; k < row[i + 1]; ++k) {
      const int j = partner[k];
      const Vec3 d = pos[j] - xi;
      const double rj = radius[j];
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
      const double inv_dist = 1.0 / std::sqrt(dist2);
      PairInput in;
      in.n = d * inv_dist;
      in.x = rs - dist2 * inv_dist;
      in.li = ri - 0.5 * in.x;
      in.lj = rj - 0.5 * in.x;
      in.reff = ri * rj / rs;
      in.sqrt_mstar = pl.sqrt_mstar[k];
      in.vrel = vel[j] - vi;
      in.wi = wi;
      in.wj = omega[j];
      in.vrel_mid = vel_mid[j] - vi_mid;
      in.wi_mid = wi_mid;
      in.wj_mid = omega_mid[j];
      const PairLaw& law = laws[material[j]];
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
    F[i] += fi;
    T[i] += ti;
  }
  sc.contacts += contacts;
  sc.max_overlap_ratio = max_ratio;
  sc.max_overlap_grain = max_grain;
}

// Grain–wall contacts of wall-list entries [kb, ke) into State::force.
template <ContactModel M, bool Resist>
void wall_entries(const Model& m, State& s, int kb, int ke, ThreadScratch& sc) {
  WallList& wl = s.wall_pairs;
  const double dt = m.dt;
  for (int k = kb; k < ke; ++k) {
    const int i = wl.grain[k];
    const Wall& w = m.walls[wl.wall[k]];
    const double ri = m.grain_radius[i];
    const WallGap gap = wall_gap(w, s.pos[i], ri);
    if (gap.overlap <= 0) {
      if (wl.touching[k]) {
        wl.touching[k] = 0;
        wl.spring_t[k].setZero();
        wl.spring_r[k].setZero();
        wl.spring_w[k] = 0;
      }
      continue;
    }
    wl.touching[k] = 1;
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
    const PairLaw& law = m.law(m.grain_material[i], w.law_material);
    const PairOutput out =
        pair_contact<M, Resist>(law, in, PairSprings{wl.spring_t[k], wl.spring_r[k], wl.spring_w[k]}, dt);
    s.force[i] += out.force_i;
    s.torque[i] += out.torque_i;
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

// Grain–body contacts of list entries [kb, ke): the grain's force goes to
// State::force, the reaction to this partition's body accumulators. The body
// side of the contact moves with the body's velocity at the contact point;
// lever arm l_j = 0 and R = r_i, as for a wall (MODEL.md §5).
template <ContactModel M, bool Resist>
void body_entries(const Model& m, State& s, int kb, int ke, ThreadScratch& sc) {
  BodyGrainList& bl = s.body_grains;
  const double dt = m.dt;
  for (int k = kb; k < ke; ++k) {
    const int i = bl.grain[k], b = bl.body[k];
    const BodyModel& bm = m.bodies[b];
    const BodyState& bs = s.bodies[b];
    const double ri = m.grain_radius[i];
    const ShapeGap gap = shape_gap(bm, bm.shapes[bl.shape[k]], bs.q.conjugate() * (s.pos[i] - bs.pos), ri);
    if (gap.overlap <= 0) {
      if (bl.touching[k]) {
        bl.touching[k] = 0;
        bl.spring_t[k].setZero();
        bl.spring_r[k].setZero();
        bl.spring_w[k] = 0;
      }
      continue;
    }
    bl.touching[k] = 1;
    PairInput in;
    in.n = bs.q * gap.n;
    in.x = gap.overlap;
    in.li = ri - 0.5 * in.x;
    in.lj = 0;
    in.reff = ri;
    in.sqrt_mstar = bl.sqrt_mstar[k];
    const Vec3 arm = s.pos[i] + in.li * in.n - bs.pos;  // contact point from the body's centre of mass
    in.vrel = bs.vel + bs.omega.cross(arm) - s.vel[i];
    in.wi = s.omega[i];
    in.wj = bs.omega;
    in.vrel_mid = bs.vel_mid + bs.omega_mid.cross(arm) - s.vel_mid[i];
    in.wi_mid = s.omega_mid[i];
    in.wj_mid = bs.omega_mid;
    const PairLaw& law = m.law(m.grain_material[i], bm.material);
    const PairOutput out =
        pair_contact<M, Resist>(law, in, PairSprings{bl.spring_t[k], bl.spring_r[k], bl.spring_w[k]}, dt);
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
    std::fill(sc.body_force.begin(), sc.body_force.end(), Vec3::Zero());
    std::fill(sc.body_torque.begin(), sc.body_torque.end(), Vec3::Zero());
  }
  const bool bodies = !m.bodies.empty();
  long wall_contacts = 0, body_contacts = 0;
#pragma omp parallel if (n >= m.parallel_min_grains)
  {
    const int tid = thread_id(), nt = thread_count();
    // Grain–grain contacts, one partition at a time per thread.
    for (int p = tid; p < P; p += nt) {
      ThreadScratch& sc = s.scratch[p];
      Vec3* F = p == 0 ? s.force.data() : sc.force.data();
      Vec3* T = p == 0 ? s.torque.data() : sc.torque.data();
      const int lo = p == 0 ? 0 : sc.touched_lo, hi = p == 0 ? n : sc.touched_hi;
      std::fill(F + lo, F + hi, Vec3::Zero());
      std::fill(T + lo, T + hi, Vec3::Zero());
      pair_rows<M, Resist>(m, s, s.thread_row_begin[p], s.thread_row_begin[p + 1], F, T, sc);
    }
#pragma omp barrier
    // Merge partition buffers in partition order.
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      for (int p = 1; p < P; ++p) {
        const ThreadScratch& sc = s.scratch[p];
        if (i >= sc.touched_lo && i < sc.touched_hi) {
          s.force[i] += sc.force[i];
          s.torque[i] += sc.torque[i];
        }
      }
    }
    // Wall contacts: partitions split at grain boundaries, so no two write one grain.
    // Contact counts of walls go to a separate total.
    for (int p = tid; p < P; p += nt) {
      ThreadScratch& sc = s.scratch[p];
      const long before = sc.contacts;
      wall_entries<M, Resist>(m, s, s.thread_wall_begin[p], s.thread_wall_begin[p + 1], sc);
#pragma omp atomic
      wall_contacts += sc.contacts - before;
    }
    if (bodies) {
      // Grain–body contacts, after every wall contact has been added.
#pragma omp barrier
      for (int p = tid; p < P; p += nt) {
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
  for (const auto& sc : s.scratch) {
    st.contacts += sc.contacts;
    if (sc.max_overlap_ratio > st.max_overlap_ratio) {
      st.max_overlap_ratio = sc.max_overlap_ratio;
      st.max_overlap_grain = sc.max_overlap_grain;
    }
  }
  st.wall_contacts = wall_contacts;
  st.body_contacts = body_contacts;
  st.contacts -= wall_contacts + body_contacts;
}

}  // namespace

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
