// State construction: every buffer the step needs, sized once.
#include "regolith_twin/core/state.hpp"

#include <algorithm>

#include "regolith_twin/core/body_collision.hpp"

namespace rt {

State make_state(const Model& m) {
  const int n = m.n_grains;
  State s;
  s.pos.assign(n, Vec3::Zero());
  s.vel.assign(n, Vec3::Zero());
  s.omega.assign(n, Vec3::Zero());
  s.vel_mid.assign(n, Vec3::Zero());
  s.omega_mid.assign(n, Vec3::Zero());
  s.force.assign(n, Vec3::Zero());
  s.torque.assign(n, Vec3::Zero());
  s.pos_at_build.assign(n, Vec3::Zero());
  s.wall_on.assign(m.walls.size(), 1);
  s.bodies.resize(m.bodies.size());
  s.scratch.resize(m.partitions);
  for (auto& sc : s.scratch) {
    sc.body_force.assign(m.bodies.size(), Vec3::Zero());
    sc.body_torque.assign(m.bodies.size(), Vec3::Zero());
  }
  for (int p = 1; p < m.partitions; ++p) {
    s.scratch[p].force.assign(n, Vec3::Zero());
    s.scratch[p].torque.assign(n, Vec3::Zero());
  }
  // Reserve list storage with head room so rebuilds do not allocate.
  const size_t pair_cap = 16 * size_t(n) + 64, wall_cap = 4 * size_t(n) + 64;
  // One block of rows of the list build: its share of pair_cap.
  const size_t block_cap = pair_cap / size_t(std::max(m.partitions, 1)) + 64;
  for (auto& sc : s.scratch) sc.list_partners.reserve(block_cap);
  for (PairList* l : {&s.pairs, &s.pairs_next}) {
    l->row_start.reserve(n + 1);
    l->partner.reserve(pair_cap);
    l->owner.reserve(pair_cap);
    l->sqrt_mstar.reserve(pair_cap);
    l->spring_t.reserve(pair_cap);
    l->spring_r.reserve(pair_cap);
    l->spring_w.reserve(pair_cap);
    l->touching.reserve(pair_cap);
  }
  for (WallList* l : {&s.wall_pairs, &s.wall_pairs_next}) {
    l->grain.reserve(wall_cap);
    l->wall.reserve(wall_cap);
    l->spring_t.reserve(wall_cap);
    l->spring_r.reserve(wall_cap);
    l->spring_w.reserve(wall_cap);
    l->touching.reserve(wall_cap);
  }
  // Grain–body candidates: head room for a quarter of the grains near a body
  // shape (a body buried in the bed); a list that outgrows it reallocates at
  // that rebuild, as the grain lists do, and keeps the larger capacity.
  const size_t body_cap = m.bodies.empty() ? 0 : size_t(n) / 4 + 256;
  for (BodyGrainList* l : {&s.body_grains, &s.body_grains_next}) {
    l->grain.reserve(body_cap);
    l->body.reserve(body_cap);
    l->shape.reserve(body_cap);
    l->sqrt_mstar.reserve(body_cap);
    l->spring_t.reserve(body_cap);
    l->spring_r.reserve(body_cap);
    l->spring_w.reserve(body_cap);
    l->touching.reserve(body_cap);
    l->mesh_first.reserve(body_cap);
  }
  // Grain–mesh contacts: slots for a sixteenth of the grains near a mesh
  // shape, and per partition the scratch of one grain's query.
  bool meshes = false;
  for (const BodyModel& b : m.bodies)
    for (const Shape& sh : b.shapes) meshes = meshes || sh.type == ShapeType::Mesh;
  if (meshes && n > 0) {
    const size_t slot_cap = (size_t(n) / 16 + 64) * kMeshSlots;
    s.body_grains.mesh_slots.reserve(slot_cap);
    s.body_grains_next.mesh_slots.reserve(slot_cap);
    for (auto& sc : s.scratch) {
      sc.mesh_tris.reserve(256);
      sc.mesh_hits.reserve(64);
    }
  }
  // Body–body contact points: every point the shape pairs can have.
  const size_t point_cap = max_body_points(m);
  s.body_points.reserve(point_cap);
  s.body_points_next.reserve(point_cap);
  s.cell_start.reserve(4 * size_t(n) + 66);
  s.cell_items.reserve(n);
  s.cell_of.reserve(n);
  return s;
}

void scale_contact_springs(State& s, double f) {
  const auto scale = [f](auto& list) {
    for (Vec3& v : list.spring_t) v *= f;
    for (Vec3& v : list.spring_r) v *= f;
    for (double& v : list.spring_w) v *= f;
  };
  scale(s.pairs);
  scale(s.wall_pairs);
  scale(s.body_grains);
  for (MeshSlot& k : s.body_grains.mesh_slots) {
    k.spring_t *= f;
    k.spring_r *= f;
    k.spring_w *= f;
  }
  for (BodyPointContact& c : s.body_points) c.spring_t *= f;
}

}  // namespace rt
