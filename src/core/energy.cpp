// Energy bookkeeping from a state (not part of the step; called by observers).
#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/hold.hpp"

#include <cmath>
#include <vector>

#include "regolith_twin/core/body_collision.hpp"
#include "regolith_twin/core/contact_law.hpp"
#include "regolith_twin/core/mesh_contact.hpp"
#include "regolith_twin/core/walls.hpp"

namespace rt {
namespace {

// Every live grain contact with its elastic energy by spring type, in list
// order (docs/model.md §15).
template <ContactModel M, class F>
void visit_elastic(const Model& m, const State& s, F&& f) {
  const PairList& pl = s.pairs;
  for (int i = 0; i + 1 < static_cast<int>(pl.row_start.size()); ++i)
    for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k) {
      const int j = pl.partner[k];
      const double rs = m.grain_radius[i] + m.grain_radius[j];
      Vec3 d = s.pos[j] - s.pos[i];
      if (!pl.image.empty()) d += m.periodic.shift(pl.image[k]);  // the partner's nearest image
      const double x = rs - d.norm();
      if (x <= 0) continue;
      const double reff = m.grain_radius[i] * m.grain_radius[j] / rs;
      f(ElasticContact{ElasticContact::GrainGrain, i, j,
                       pair_elastic_split<M>(m.law(m.grain_material[i], m.grain_material[j]), x, reff,
                                             pl.spring_t[k], pl.spring_r[k], pl.spring_w[k])});
    }
  const WallList& wl = s.wall_pairs;
  for (int k = 0; k < wl.size(); ++k) {
    const int i = wl.grain[k];
    const Wall& w = m.walls[wl.wall[k]];
    const double x = wall_gap(w, s.pos[i], m.grain_radius[i]).overlap;
    if (x <= 0) continue;
    f(ElasticContact{ElasticContact::GrainWall, i, wl.wall[k],
                     pair_elastic_split<M>(m.law(m.grain_material[i], w.law_material), x, m.grain_radius[i],
                                           wl.spring_t[k], wl.spring_r[k], wl.spring_w[k])});
  }
  const BodyGrainList& bl = s.body_grains;
  std::vector<int> tris;
  std::vector<MeshHit> hits;
  for (int k = 0; k < bl.size(); ++k) {
    const int i = bl.grain[k];
    const BodyModel& bm = m.bodies[bl.body[k]];
    const BodyState& bs = s.bodies[bl.body[k]];
    if (bl.mesh_first[k] >= 0) {
      // Every touched feature, with the springs of the slot it holds (the
      // slot's normal is the one of the last force pass).
      const Shape& sh = bm.shapes[bl.shape[k]];
      const Vec3 pb = bs.q.conjugate() * (s.pos[i] - bs.pos);
      mesh_hits(*bm.surfaces[sh.mesh], sh.rot.conjugate() * (pb - sh.pos), m.grain_radius[i], tris, hits);
      const MeshSlot* slot = &bl.mesh_slots[bl.mesh_first[k]];
      const MeshSlot none;
      for (const MeshHit& h : hits) {
        const MeshSlot* best = &none;
        double dot = 0.9;
        for (int q = 0; q < kMeshSlots; ++q)
          if (slot[q].touching && slot[q].normal.dot(sh.rot * h.n) > dot) {
            dot = slot[q].normal.dot(sh.rot * h.n);
            best = &slot[q];
          }
        f(ElasticContact{ElasticContact::GrainBody, i, bl.body[k],
                         pair_elastic_split<M>(m.law(m.grain_material[i], bm.material), h.overlap,
                                               m.grain_radius[i], best->spring_t, best->spring_r, best->spring_w)});
      }
      continue;
    }
    const double x =
        shape_gap(bm, bm.shapes[bl.shape[k]], bs.q.conjugate() * (s.pos[i] - bs.pos), m.grain_radius[i]).overlap;
    if (x <= 0) continue;
    f(ElasticContact{ElasticContact::GrainBody, i, bl.body[k],
                     pair_elastic_split<M>(m.law(m.grain_material[i], bm.material), x, m.grain_radius[i],
                                           bl.spring_t[k], bl.spring_r[k], bl.spring_w[k])});
  }
}

template <class F>
void visit_elastic_any(const Model& m, const State& s, F&& f) {
  if (!s.lists_valid) return;
  if (m.contact_model == ContactModel::Linear)
    visit_elastic<ContactModel::Linear>(m, s, f);
  else
    visit_elastic<ContactModel::HertzMindlin>(m, s, f);
}

}  // namespace

void for_each_elastic_contact(const Model& m, const State& s, const std::function<void(const ElasticContact&)>& f) {
  visit_elastic_any(m, s, f);
}

Energy energy(const Model& m, const State& s) {
  Energy e;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    const double mass = m.grain_mass[i];
    e.translational += 0.5 * mass * s.vel[i].squaredNorm();
    e.rotational += 0.5 * (1.0 / m.grain_inv_inertia[i]) * s.omega[i].squaredNorm();
    e.potential -= mass * m.gravity.dot(s.pos[i]);
  }
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyModel& bm = m.bodies[b];
    if (bm.fixed) continue;
    e.translational += body_lin_energy(bm, s.bodies[b]);
    e.rotational += body_rot_energy(bm, s.bodies[b]);
    e.potential -= bm.mass * m.gravity.dot(s.bodies[b].pos);
  }
  visit_elastic_any(m, s, [&e](const ElasticContact& c) { e.elastic += c.energy.total(); });
  e.elastic += body_body_elastic_energy(m, s);  // body–body points of the last force pass
  return e;
}

double kinetic_energy(const Model& m, const State& s) {
  double e = 0;
  for (int i = 0; i < m.n_grains; ++i) {
    if (held(m, i)) continue;
    e += 0.5 * m.grain_mass[i] * s.vel[i].squaredNorm() + 0.5 * (1.0 / m.grain_inv_inertia[i]) * s.omega[i].squaredNorm();
  }
  for (size_t b = 0; b < m.bodies.size(); ++b)
    if (!m.bodies[b].fixed) e += body_lin_energy(m.bodies[b], s.bodies[b]) + body_rot_energy(m.bodies[b], s.bodies[b]);
  return e;
}

double coordination_number(const Model& m, const State& s) {
  long free_grains = 0;
  for (int i = 0; i < m.n_grains; ++i) free_grains += !held(m, i);
  return free_grains ? 2.0 * double(s.stats.contacts) / double(free_grains) : 0.0;
}

}  // namespace rt
