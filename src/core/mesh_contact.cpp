// Grain–triangle-mesh contacts: welded surface, adjacency, Bullet BVH and
// the feature classification of a sphere's contacts (see mesh_contact.hpp).
#include "regolith_twin/core/mesh_contact.hpp"

#include <BulletCollision/CollisionShapes/btBvhTriangleMeshShape.h>
#include <BulletCollision/CollisionShapes/btOptimizedBvh.h>
#include <BulletCollision/CollisionShapes/btTriangleIndexVertexArray.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace rt {

struct MeshSurface {
  struct EdgeRef {
    int a, b, tri;  // edge (a, b), a < b, of triangle tri
  };
  std::vector<Vec3> v;                    // welded vertices
  std::vector<std::array<int, 3>> t;      // triangles (welded indices)
  std::vector<Vec3> normal;               // unit normal of each triangle (outward for counter-clockwise winding)
  std::vector<EdgeRef> edges;             // every triangle edge, sorted by (a, b, tri)
  std::vector<int> vt_start, vt_tri;      // triangles around each vertex (CSR)
  std::vector<Vec3> vertex_pn;            // angle-weighted pseudo-normal of each vertex
  bool closed = false;                    // every edge shared by exactly two triangles
  // Bullet's BVH over the welded triangles (members destroyed in reverse order).
  std::vector<btScalar> bt_vertices;
  std::vector<int> bt_indices;
  std::unique_ptr<btTriangleIndexVertexArray> bt_mesh;
  std::unique_ptr<btBvhTriangleMeshShape> bt_shape;
  const btOptimizedBvh* bvh = nullptr;
};

namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }

// Closest point of triangle (a, b, c) to p and the region it lies in
// (Ericson, Real-Time Collision Detection, 5.1.5). local: the vertex
// (0, 1, 2) or the edge (0: ab, 1: bc, 2: ca).
struct Closest {
  Vec3 q;
  int kind;   // MeshHit::Kind
  int local;
};

Closest closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, MeshHit::Vertex, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, MeshHit::Vertex, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + (d1 / (d1 - d3)) * ab, MeshHit::Edge, 0};
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, MeshHit::Vertex, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + (d2 / (d2 - d6)) * ac, MeshHit::Edge, 2};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), MeshHit::Edge, 1};
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), MeshHit::Face, -1};
}

Closest closest_on(const MeshSurface& ms, int tri, const Vec3& p) {
  const auto& t = ms.t[tri];
  return closest_on_triangle(p, ms.v[t[0]], ms.v[t[1]], ms.v[t[2]]);
}

// Closest point of segment (a, b) to p, from the lower vertex index, so every
// triangle sharing the edge computes the same point.
Vec3 closest_on_edge(const MeshSurface& ms, int ia, int ib, const Vec3& p) {
  const Vec3& a = ms.v[ia];
  const Vec3 ab = ms.v[ib] - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return a + t * ab;
}

std::pair<std::vector<MeshSurface::EdgeRef>::const_iterator, std::vector<MeshSurface::EdgeRef>::const_iterator>
edge_range(const MeshSurface& ms, int a, int b) {
  const auto lo = std::lower_bound(ms.edges.begin(), ms.edges.end(), std::make_pair(a, b),
                                   [](const MeshSurface::EdgeRef& e, const std::pair<int, int>& k) {
                                     return e.a != k.first ? e.a < k.first : e.b < k.second;
                                   });
  auto hi = lo;
  while (hi != ms.edges.end() && hi->a == a && hi->b == b) ++hi;
  return {lo, hi};
}

// Bullet's node callback: every triangle whose bounds meet the query box.
struct CollectTriangles : btNodeOverlapCallback {
  explicit CollectTriangles(std::vector<int>& out) : out_(out) {}
  void processNode(int, int tri) override { out_.push_back(tri); }
  std::vector<int>& out_;
};

// Nearest point over the triangles reported (or all of them).
struct Nearest : btNodeOverlapCallback {
  Nearest(const MeshSurface& ms, const Vec3& p) : ms_(ms), p_(p) {}
  void processNode(int, int tri) override { consider(tri); }
  void consider(int tri) {
    const Closest c = closest_on(ms_, tri, p_);
    const double d2 = (c.q - p_).squaredNorm();
    if (d2 < best2 || (d2 == best2 && tri < best_tri)) {
      best2 = d2;
      best_tri = tri;
      best = c;
    }
  }
  const MeshSurface& ms_;
  Vec3 p_;
  double best2 = std::numeric_limits<double>::infinity();
  int best_tri = std::numeric_limits<int>::max();
  Closest best{};
};

void query(const MeshSurface& ms, btNodeOverlapCallback& cb, const Vec3& p, double h) {
  const Vec3 lo = p - Vec3::Constant(h), hi = p + Vec3::Constant(h);
  ms.bvh->reportAabbOverlappingNodex(&cb, to_bt(lo), to_bt(hi));
}

// Welds vertices closer than tol (the lowest index of a cluster is kept).
std::vector<int> weld(const std::vector<Vec3>& v, double tol, std::vector<Vec3>& out) {
  const int n = static_cast<int>(v.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&v](int i, int j) { return v[i].x() != v[j].x() ? v[i].x() < v[j].x() : i < j; });
  std::vector<int> rank(n);
  for (int k = 0; k < n; ++k) rank[order[k]] = k;
  std::vector<int> map(n, -1);
  out.clear();
  for (int i = 0; i < n; ++i) {
    if (map[i] >= 0) continue;
    const int id = static_cast<int>(out.size());
    out.push_back(v[i]);
    map[i] = id;
    for (int dir : {-1, 1})
      for (int k = rank[i] + dir; k >= 0 && k < n && std::fabs(v[order[k]].x() - v[i].x()) <= tol; k += dir) {
        const int j = order[k];
        if (map[j] < 0 && (v[j] - v[i]).norm() <= tol) map[j] = id;
      }
  }
  return map;
}

}  // namespace

std::shared_ptr<const MeshSurface> build_mesh_surface(const TriangleMesh& mesh, const std::string& what) {
  auto ms = std::make_shared<MeshSurface>();
  const int nv = static_cast<int>(mesh.vertices.size());
  if (nv == 0 || mesh.triangles.empty()) throw InputError(what + ": empty collision mesh");
  Vec3 lo = mesh.vertices[0], hi = lo;
  for (const Vec3& p : mesh.vertices) {
    if (!p.allFinite()) throw InputError(what + ": mesh vertex is not finite");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double tol = 1e-9 * (hi - lo).norm();
  const std::vector<int> map = weld(mesh.vertices, tol, ms->v);
  for (const auto& tr : mesh.triangles) {
    std::array<int, 3> w;
    for (int k = 0; k < 3; ++k) {
      if (tr[k] < 0 || tr[k] >= nv) throw InputError(what + ": mesh triangle index out of range");
      w[k] = map[tr[k]];
    }
    if (w[0] == w[1] || w[1] == w[2] || w[2] == w[0]) continue;
    const Vec3 nrm = (ms->v[w[1]] - ms->v[w[0]]).cross(ms->v[w[2]] - ms->v[w[0]]);
    const double len = nrm.norm();
    if (!(len > 0)) continue;
    ms->t.push_back(w);
    ms->normal.push_back(nrm / len);
  }
  if (ms->t.empty()) throw InputError(what + ": collision mesh has only degenerate triangles");
  const int nt = static_cast<int>(ms->t.size());
  const int nw = static_cast<int>(ms->v.size());
  // Adjacency: edges, triangles around each vertex, pseudo-normals.
  ms->edges.reserve(3 * size_t(nt));
  ms->vt_start.assign(nw + 1, 0);
  ms->vertex_pn.assign(nw, Vec3::Zero());
  for (int i = 0; i < nt; ++i) {
    const auto& w = ms->t[i];
    for (int k = 0; k < 3; ++k) {
      const int a = w[k], b = w[(k + 1) % 3];
      ms->edges.push_back({std::min(a, b), std::max(a, b), i});
      ++ms->vt_start[a + 1];
      const Vec3 e1 = ms->v[b] - ms->v[a], e2 = ms->v[w[(k + 2) % 3]] - ms->v[a];
      const double c = std::clamp(e1.dot(e2) / (e1.norm() * e2.norm()), -1.0, 1.0);
      ms->vertex_pn[a] += std::acos(c) * ms->normal[i];
    }
  }
  std::sort(ms->edges.begin(), ms->edges.end(), [](const MeshSurface::EdgeRef& x, const MeshSurface::EdgeRef& y) {
    if (x.a != y.a) return x.a < y.a;
    if (x.b != y.b) return x.b < y.b;
    return x.tri < y.tri;
  });
  ms->closed = true;
  for (size_t k = 0; k < ms->edges.size();) {
    size_t e = k;
    while (e < ms->edges.size() && ms->edges[e].a == ms->edges[k].a && ms->edges[e].b == ms->edges[k].b) ++e;
    if (e - k != 2) ms->closed = false;
    k = e;
  }
  for (int i = 0; i < nw; ++i) ms->vt_start[i + 1] += ms->vt_start[i];
  ms->vt_tri.resize(ms->vt_start[nw]);
  std::vector<int> cursor(ms->vt_start.begin(), ms->vt_start.end() - 1);
  for (int i = 0; i < nt; ++i)
    for (int k = 0; k < 3; ++k) ms->vt_tri[cursor[ms->t[i][k]]++] = i;
  // Bullet's quantized BVH (double precision build) over the welded triangles.
  ms->bt_vertices.reserve(3 * size_t(nw));
  for (const Vec3& p : ms->v) {
    ms->bt_vertices.push_back(p.x());
    ms->bt_vertices.push_back(p.y());
    ms->bt_vertices.push_back(p.z());
  }
  ms->bt_indices.reserve(3 * size_t(nt));
  for (const auto& w : ms->t) ms->bt_indices.insert(ms->bt_indices.end(), w.begin(), w.end());
  ms->bt_mesh = std::make_unique<btTriangleIndexVertexArray>(nt, ms->bt_indices.data(), 3 * int(sizeof(int)), nw,
                                                             ms->bt_vertices.data(), 3 * int(sizeof(btScalar)));
  ms->bt_shape = std::make_unique<btBvhTriangleMeshShape>(ms->bt_mesh.get(), true);
  ms->bvh = ms->bt_shape->getOptimizedBvh();
  if (!ms->bvh) throw InputError(what + ": could not build the mesh BVH");
  return ms;
}

int mesh_surface_triangles(const MeshSurface& ms) { return static_cast<int>(ms.t.size()); }
int mesh_surface_vertices(const MeshSurface& ms) { return static_cast<int>(ms.v.size()); }

int mesh_hits(const MeshSurface& ms, const Vec3& p, double r, std::vector<int>& tris, std::vector<MeshHit>& out) {
  tris.clear();
  out.clear();
  if (!(r > 0)) return 0;
  CollectTriangles cb(tris);
  query(ms, cb, p, r);
  std::sort(tris.begin(), tris.end());
  // Closest points that agree within tol are one point (rounding of the
  // coordinates is far below it; see mesh_contact.hpp).
  const double tol = 1e-9 * r + 1e-13 * p.norm();
  const double tol2 = tol * tol;
  const double r2 = r * r;
  for (const int tri : tris) {
    const Closest c = closest_on(ms, tri, p);
    if ((c.q - p).squaredNorm() >= r2) continue;
    MeshHit h;
    h.tri = tri;
    h.kind = c.kind;
    const auto& w = ms.t[tri];
    int ea = -1, eb = -1;
    if (c.kind == MeshHit::Face) {
      // Plane distance: exact for a plane along the axes, as for a plane wall.
      const Vec3& nrm = ms.normal[tri];
      const double d = nrm.dot(p - ms.v[w[0]]);
      h.point = p - d * nrm;
      h.overlap = r - std::fabs(d);
      h.n = d >= 0 ? Vec3(-nrm) : nrm;
    } else {
      if (c.kind == MeshHit::Edge) {
        ea = std::min(w[c.local], w[(c.local + 1) % 3]);
        eb = std::max(w[c.local], w[(c.local + 1) % 3]);
        h.point = closest_on_edge(ms, ea, eb, p);
      } else {
        h.point = ms.v[w[c.local]];
      }
      const Vec3 d = h.point - p;
      const double dist = d.norm();
      h.overlap = r - dist;
      h.n = dist > 0 ? Vec3(d / dist) : Vec3(-ms.normal[tri]);
    }
    if (!(h.overlap > 0)) continue;
    // The same point already listed: keep the better of the two (a face
    // before an edge before a vertex, then the deeper).
    int same = -1;
    for (int k = 0; k < static_cast<int>(out.size()); ++k)
      if ((out[k].point - h.point).squaredNorm() <= tol2) {
        same = k;
        break;
      }
    if (same >= 0) {
      const MeshHit& o = out[same];
      if (o.kind < h.kind || (o.kind == h.kind && o.overlap >= h.overlap)) continue;
    }
    // An edge or vertex point is a contact only where it is the closest
    // point of every triangle around it (a local minimum on the surface).
    if (h.kind != MeshHit::Face) {
      bool local_min = true;
      if (h.kind == MeshHit::Edge) {
        const auto range = edge_range(ms, ea, eb);
        for (auto e = range.first; e != range.second && local_min; ++e)
          local_min = (closest_on(ms, e->tri, p).q - h.point).squaredNorm() <= tol2;
      } else {
        const int vi = w[c.local];
        for (int k = ms.vt_start[vi]; k < ms.vt_start[vi + 1] && local_min; ++k)
          local_min = (closest_on(ms, ms.vt_tri[k], p).q - h.point).squaredNorm() <= tol2;
      }
      if (!local_min) continue;
    }
    if (same >= 0)
      out[same] = h;
    else
      out.push_back(h);
  }
  return static_cast<int>(out.size());
}

ShapeGap mesh_gap(const MeshSurface& ms, const Vec3& p, double r, double reach) {
  Nearest nearest(ms, p);
  if (reach >= 0 && std::isfinite(reach)) {
    query(ms, nearest, p, r + reach);
  } else {
    for (int tri = 0; tri < static_cast<int>(ms.t.size()); ++tri) nearest.consider(tri);
  }
  ShapeGap g;
  if (nearest.best_tri == std::numeric_limits<int>::max()) return g;  // nothing in reach
  double dist = std::sqrt(nearest.best2);
  if (reach >= 0 && std::isfinite(reach) && dist > r + reach) return g;
  Closest c = nearest.best;
  const int tri = nearest.best_tri;
  const auto& w = ms.t[tri];
  if (c.kind == MeshHit::Face) {  // the plane's distance and foot point, as in mesh_hits
    const double d = ms.normal[tri].dot(p - ms.v[w[0]]);
    c.q = p - d * ms.normal[tri];
    dist = std::fabs(d);
  }
  // Pseudo-normal of the nearest feature: inside or outside a closed mesh.
  Vec3 pn = ms.normal[tri];
  if (c.kind == MeshHit::Edge) {
    const auto range = edge_range(ms, std::min(w[c.local], w[(c.local + 1) % 3]), std::max(w[c.local], w[(c.local + 1) % 3]));
    pn.setZero();
    for (auto e = range.first; e != range.second; ++e) pn += ms.normal[e->tri];
  } else if (c.kind == MeshHit::Vertex) {
    pn = ms.vertex_pn[w[c.local]];
  }
  const bool inside = ms.closed && (p - c.q).dot(pn) < 0;
  g.point = c.q;
  if (inside) {
    g.overlap = r + dist;
    g.n = dist > 0 ? Vec3((p - c.q) / dist) : Vec3(ms.normal[tri]);
  } else {
    g.overlap = r - dist;
    g.n = dist > 0 ? Vec3((c.q - p) / dist) : Vec3(-ms.normal[tri]);
  }
  return g;
}

}  // namespace rt
