// Body–body contacts through Bullet's narrow phase (see body_collision.hpp).
#include "regolith_twin/core/body_collision.hpp"
#include "regolith_twin/core/hash.hpp"

#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "regolith_twin/core/contact_law.hpp"

namespace rt {

namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 to_eigen(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

btTransform to_bt(const Mat3& r, const Vec3& p) {
  return btTransform(btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                     to_bt(p));
}

// A solid ellipsoid with semi-axes a (shape frame), exact for GJK–EPA: the
// support point in direction d is A^2 d / |A d| with A = diag(a).
class EllipsoidShape : public btConvexInternalShape {
 public:
  explicit EllipsoidShape(const Vec3& semi) : semi_(to_bt(semi)) {
    m_shapeType = CUSTOM_CONVEX_SHAPE_TYPE;
    m_implicitShapeDimensions = semi_;
    btConvexInternalShape::setMargin(0);
  }

  btVector3 localGetSupportingVertexWithoutMargin(const btVector3& d) const override {
    const btVector3 ad = semi_ * d;
    const btScalar len = ad.length();
    if (!(len > 0)) return btVector3(semi_.x(), 0, 0);
    return semi_ * ad / len;
  }

  void batchedUnitVectorGetSupportingVertexWithoutMargin(const btVector3* dirs, btVector3* out, int n) const override {
    for (int i = 0; i < n; ++i) out[i] = localGetSupportingVertexWithoutMargin(dirs[i]);
  }

  // Exact bounds: half extent along world axis i is |A R^T e_i|.
  void getAabb(const btTransform& t, btVector3& lo, btVector3& hi) const override {
    const btMatrix3x3& r = t.getBasis();
    btVector3 h;
    for (int i = 0; i < 3; ++i) {
      const btVector3 row = r.getRow(i) * semi_;
      h[i] = row.length() + getMargin();
    }
    lo = t.getOrigin() - h;
    hi = t.getOrigin() + h;
  }

  void calculateLocalInertia(btScalar mass, btVector3& inertia) const override {
    const btScalar a2 = semi_.x() * semi_.x(), b2 = semi_.y() * semi_.y(), c2 = semi_.z() * semi_.z();
    inertia.setValue(mass / 5 * (b2 + c2), mass / 5 * (a2 + c2), mass / 5 * (a2 + b2));
  }

  const char* getName() const override { return "Ellipsoid"; }

 private:
  btVector3 semi_;
};

// One body shape as a Bullet collision object. Members are destroyed in
// reverse order: the object, then the shape, then the mesh data it points to.
struct ShapeEntry {
  std::vector<btScalar> vertices;                    // triangle mesh data (fixed mesh)
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> mesh;
  std::unique_ptr<btCollisionShape> shape;
  std::unique_ptr<btCollisionObject> object;
  double breaking = 0;                                // Bullet's contact-breaking threshold of the shape, m
  double reach = 0;                                   // bounding radius about the body's centre of mass, m
  bool smooth = false;                                // strictly convex (sphere, ellipsoid): one contact point
  double half_thickness = 0;  // depth scale of the body–body overlap guard, m (a fixed mesh, a surface: infinite)
};

// A point reported by Bullet, converted to the conventions of the law.
struct RawPoint {
  Vec3 on_a, on_b;   // points on a's and b's surfaces (world), m
  Vec3 n;            // unit normal from a to b
  double depth;      // > 0, m
  Vec3 local_a, local_b;  // on_a and on_b in the body frames, m
};

struct Candidate {
  double d;
  int i, j;  // new point, old point
};

// Fingerprint of everything the geometry is built from (mesh contents by size only).
uint64_t geometry_key(const Model& m) {
  uint64_t h = kFnvOffset;
  for (const BodyModel& b : m.bodies) {
    const int fixed = b.fixed ? 1 : 0;
    h = fnv1a(&fixed, sizeof fixed, h);
    const size_t ns = b.shapes.size();
    h = fnv1a(&ns, sizeof ns, h);
    for (const Shape& sh : b.shapes) {
      const double v[11] = {sh.pos.x(), sh.pos.y(), sh.pos.z(), sh.rot.w(), sh.rot.x(), sh.rot.y(),
                            sh.rot.z(), sh.size.x(), sh.size.y(), sh.size.z(), static_cast<double>(sh.type)};
      h = fnv1a(v, sizeof v, h);
      if (sh.type == ShapeType::Mesh && sh.mesh >= 0 && sh.mesh < static_cast<int>(b.meshes.size())) {
        const size_t nv = b.meshes[sh.mesh].vertices.size(), nt = b.meshes[sh.mesh].triangles.size();
        h = fnv1a(&nv, sizeof nv, h);
        h = fnv1a(&nt, sizeof nt, h);
      }
    }
  }
  return h;
}

}  // namespace

// Bullet objects of every body shape, plus the dispatcher and scratch of a query.
struct BodyGeometry {
  uint64_t key = 0;
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::vector<std::vector<ShapeEntry>> shapes;  // [body][shape]
  std::vector<double> body_reach;               // bounding radius of each body, m
  // Scratch of one call (reused; never part of the result).
  std::vector<RawPoint> raw, raw_tmp;
  std::vector<int> order, hull;
  std::vector<Candidate> cand;
  std::vector<int> match_new, match_old;
  std::vector<uint8_t> taken;
  std::atomic<bool> busy{false};
};

namespace {

ShapeEntry make_entry(const BodyModel& b, const Shape& sh) {
  ShapeEntry e;
  switch (sh.type) {
    case ShapeType::Box: {
      auto box = std::make_unique<btBoxShape>(to_bt(sh.size));
      box->setMargin(0);  // keeps the half extents: the box stays exact
      box->initializePolyhedralFeatures();
      e.shape = std::move(box);
      break;
    }
    case ShapeType::Sphere:
      e.shape = std::make_unique<btSphereShape>(sh.size.x());  // the margin is the radius: exact
      break;
    case ShapeType::Cylinder: {
      auto cyl = std::make_unique<btCylinderShapeZ>(btVector3(sh.size.x(), sh.size.x(), sh.size.z()));
      cyl->setMargin(0);  // keeps radius and half length: sharp rims
      e.shape = std::move(cyl);
      break;
    }
    case ShapeType::Ellipsoid:
      if (sh.size.x() == sh.size.y() && sh.size.y() == sh.size.z())
        e.shape = std::make_unique<btSphereShape>(sh.size.x());
      else
        e.shape = std::make_unique<EllipsoidShape>(sh.size);
      break;
    case ShapeType::Mesh: {
      if (sh.mesh < 0 || sh.mesh >= static_cast<int>(b.meshes.size()))
        throw InputError("body '" + b.name + "': mesh shape without a mesh");
      const TriangleMesh& tm = b.meshes[sh.mesh];
      if (tm.vertices.empty() || tm.triangles.empty())
        throw InputError("body '" + b.name + "': empty collision mesh (link '" + sh.link + "')");
      if (b.fixed) {
        for (const Vec3& v : tm.vertices) {
          e.vertices.push_back(v.x());
          e.vertices.push_back(v.y());
          e.vertices.push_back(v.z());
        }
        for (const auto& t : tm.triangles)
          for (int k = 0; k < 3; ++k) {
            if (t[k] < 0 || t[k] >= static_cast<int>(tm.vertices.size()))
              throw InputError("body '" + b.name + "': mesh triangle index out of range (link '" + sh.link + "')");
            e.indices.push_back(t[k]);
          }
        e.mesh = std::make_unique<btTriangleIndexVertexArray>(
            static_cast<int>(tm.triangles.size()), e.indices.data(), 3 * static_cast<int>(sizeof(int)),
            static_cast<int>(tm.vertices.size()), e.vertices.data(), 3 * static_cast<int>(sizeof(btScalar)));
        auto bvh = std::make_unique<btBvhTriangleMeshShape>(e.mesh.get(), true);
        bvh->setMargin(0);  // triangles take the concave shape's margin: keep them flat
        e.shape = std::move(bvh);
      } else {
        // A moving mesh collides as the convex hull of its vertices.
        auto hull = std::make_unique<btConvexHullShape>();
        for (const Vec3& v : tm.vertices) hull->addPoint(to_bt(v), false);
        hull->recalcLocalAabb();
        hull->setMargin(0);
        hull->initializePolyhedralFeatures();
        e.shape = std::move(hull);
      }
      break;
    }
  }
  e.smooth = sh.type == ShapeType::Sphere || sh.type == ShapeType::Ellipsoid;
  // Half thickness (docs/model.md §13): the smallest half extent of the
  // shape; a moving mesh, of its hull's box; a fixed mesh is a surface.
  if (sh.type != ShapeType::Mesh) {
    e.half_thickness = sh.type == ShapeType::Cylinder ? std::min(sh.size.x(), sh.size.z()) : sh.size.minCoeff();
  } else if (b.fixed) {
    e.half_thickness = std::numeric_limits<double>::infinity();
  } else {
    Vec3 lo = b.meshes[sh.mesh].vertices[0], hi = lo;
    for (const Vec3& v : b.meshes[sh.mesh].vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    e.half_thickness = 0.5 * (hi - lo).minCoeff();
  }
  e.object = std::make_unique<btCollisionObject>();
  e.object->setCollisionShape(e.shape.get());
  e.breaking = e.shape->getContactBreakingThreshold(gContactBreakingThreshold);
  btVector3 c;
  btScalar r;
  e.shape->getBoundingSphere(c, r);
  e.reach = sh.pos.norm() + (sh.rot * to_eigen(c)).norm() + r;
  return e;
}

BodyGeometry& geometry(const Model& m) {
  if (!m.body_geometry || m.body_geometry->key != geometry_key(m)) build_body_geometry(m);
  return *m.body_geometry;
}

// Releases the single-user flag of the geometry.
struct BusyGuard {
  explicit BusyGuard(BodyGeometry& g) : g_(g) {
    if (g_.busy.exchange(true))
      throw std::logic_error("body_body_forces: the same Model's body geometry is in use on another thread");
  }
  ~BusyGuard() { g_.busy.store(false); }
  BodyGeometry& g_;
};

// Records every penetrating point an algorithm reports, before any manifold
// reduction (the manifold would keep 4 points chosen by insertion order).
class Collector : public btManifoldResult {
 public:
  Collector(const btCollisionObjectWrapper* wa, const btCollisionObjectWrapper* wb, const btCollisionObject* obj_a,
            std::vector<RawPoint>& out)
      : btManifoldResult(wa, wb), obj_a_(obj_a), out_(out) {}

  // Bullet's convention: the point is on the algorithm's body 1, the normal
  // points from body 1 to body 0, body 0's point = point + normal * depth
  // (depth < 0 when penetrating). Body 0 is the manifold's first object.
  void addContactPoint(const btVector3& normal_on_1, const btVector3& point_on_1, btScalar depth) override {
    if (!(depth < 0)) return;
    RawPoint p;
    const Vec3 n10 = to_eigen(normal_on_1).normalized();
    const Vec3 p1 = to_eigen(point_on_1), p0 = to_eigen(point_on_1 + normal_on_1 * depth);
    if (m_manifoldPtr->getBody0() == obj_a_) {
      p.on_a = p0;
      p.on_b = p1;
      p.n = -n10;
    } else {
      p.on_a = p1;
      p.on_b = p0;
      p.n = n10;
    }
    p.depth = -depth;
    out_.push_back(p);
  }

 private:
  const btCollisionObject* obj_a_;
  std::vector<RawPoint>& out_;
};

// Penetrating points of shape ea (body a) against shape eb (body b),
// appended to g.raw with body-frame positions. Returns the pair's
// contact-breaking threshold (Bullet's: 2 % of the smaller shape's size).
double narrow_phase(BodyGeometry& g, const btTransform& ta, const btTransform& tb, ShapeEntry& ea, ShapeEntry& eb,
                    const BodyState& ba, const BodyState& bb) {
  ea.object->setWorldTransform(ta);
  eb.object->setWorldTransform(tb);
  const btCollisionObjectWrapper wa(nullptr, ea.shape.get(), ea.object.get(), ta, -1, -1);
  const btCollisionObjectWrapper wb(nullptr, eb.shape.get(), eb.object.get(), tb, -1, -1);
  btPersistentManifold* manifold = g.dispatcher->getNewManifold(ea.object.get(), eb.object.get());
  const double breaking = manifold->getContactBreakingThreshold();
  btCollisionAlgorithm* algo = g.dispatcher->findAlgorithm(&wa, &wb, manifold, BT_CONTACT_POINT_ALGORITHMS);
  const size_t first = g.raw.size();
  if (algo) {
    btDispatcherInfo info;
    info.m_enableSatConvex = true;  // SAT + face clipping for polyhedra with features
    Collector result(&wa, &wb, ea.object.get(), g.raw);
    result.setPersistentManifold(manifold);
    algo->processCollision(&wa, &wb, info, &result);
    algo->~btCollisionAlgorithm();
    g.dispatcher->freeCollisionAlgorithm(algo);
  }
  g.dispatcher->releaseManifold(manifold);
  const Mat3 ra_t = ba.q.toRotationMatrix().transpose(), rb_t = bb.q.toRotationMatrix().transpose();
  for (size_t k = first; k < g.raw.size(); ++k) {
    g.raw[k].local_a = ra_t * (g.raw[k].on_a - ba.pos);
    g.raw[k].local_b = rb_t * (g.raw[k].on_b - bb.pos);
  }
  return breaking;
}

bool lex_less(const Vec3& u, const Vec3& v) {
  if (u.x() != v.x()) return u.x() < v.x();
  if (u.y() != v.y()) return u.y() < v.y();
  return u.z() < v.z();
}

// Reduce the reported points of one shape pair to the corners of its contact
// patch. 1. Points within tol of a deeper one (on body a) collapse into it:
// the perturbed queries and neighbouring mesh triangles report the same
// corner more than once. 2. Points inside the patch outline (the 2D convex
// hull of the points in the plane normal to the mean normal) that are not
// deeper than the outline are dropped: on a flat patch they only bias the
// centre of pressure (a box on two floor triangles also reports points along
// their shared edge). A curved contact keeps its deepest point.
void reduce_points(std::vector<RawPoint>& pts, double tol, int max_points, std::vector<RawPoint>& tmp,
                   std::vector<int>& idx, std::vector<int>& hull, std::vector<uint8_t>& taken) {
  std::sort(pts.begin(), pts.end(), [](const RawPoint& p, const RawPoint& q) {
    if (p.depth != q.depth) return p.depth > q.depth;
    return lex_less(p.local_a, q.local_a);
  });
  tmp.clear();
  for (const RawPoint& p : pts) {
    bool dup = false;
    for (const RawPoint& k : tmp) dup = dup || (p.local_a - k.local_a).norm() < tol;
    if (!dup) tmp.push_back(p);
  }
  pts.swap(tmp);
  if (static_cast<int>(pts.size()) > max_points && max_points == 1) pts.resize(1);  // the deepest
  const int n = static_cast<int>(pts.size());
  if (n < 3) return;
  Vec3 nm = Vec3::Zero();
  for (const RawPoint& p : pts) nm += p.n;
  nm.normalize();
  const Vec3 e1 = nm.unitOrthogonal(), e2 = nm.cross(e1);
  auto uv = [&](int i) {
    const Vec3 c = 0.5 * (pts[i].on_a + pts[i].on_b);
    return Eigen::Vector2d(c.dot(e1), c.dot(e2));
  };
  idx.resize(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](int i, int j) {
    const Eigen::Vector2d a = uv(i), b = uv(j);
    if (a.x() != b.x()) return a.x() < b.x();
    if (a.y() != b.y()) return a.y() < b.y();
    return i < j;
  });
  const double ext = (uv(idx.back()) - uv(idx.front())).norm() + tol;
  const double eps = 1e-9 * ext * ext;  // collinear within this: not a corner
  auto cross = [&](int o, int a, int b) {
    const Eigen::Vector2d oa = uv(a) - uv(o), ob = uv(b) - uv(o);
    return oa.x() * ob.y() - oa.y() * ob.x();
  };
  // Andrew's monotone chain, strict corners only.
  hull.clear();
  for (int pass = 0; pass < 2; ++pass) {
    const size_t base = hull.size();
    for (int k = 0; k < n; ++k) {
      const int i = pass == 0 ? idx[k] : idx[n - 1 - k];
      while (hull.size() >= base + 2 && cross(hull[hull.size() - 2], hull.back(), i) <= eps) hull.pop_back();
      hull.push_back(i);
    }
    hull.pop_back();  // the last point starts the other chain
  }
  double hull_depth = 0;
  for (int i : hull) hull_depth = std::max(hull_depth, pts[i].depth);
  tmp.clear();
  for (int i = 0; i < n; ++i) {
    const bool corner = std::find(hull.begin(), hull.end(), i) != hull.end();
    if (corner || pts[i].depth > hull_depth * (1 + 1e-9)) tmp.push_back(pts[i]);
  }
  pts.swap(tmp);
  // More corners than the contact may have (two polygons clipped against each
  // other): keep a spread-out set, deepest first (pts is still depth-sorted):
  // each next point is the one farthest from those already kept.
  if (static_cast<int>(pts.size()) > max_points) {
    tmp.clear();
    tmp.push_back(pts[0]);
    taken.assign(pts.size(), 0);
    taken[0] = 1;
    while (static_cast<int>(tmp.size()) < max_points) {
      int best = -1;
      double best_d = -1;
      for (size_t i = 0; i < pts.size(); ++i) {
        if (taken[i]) continue;
        double d = 1e300;
        for (const RawPoint& k : tmp) d = std::min(d, (pts[i].on_b - k.on_b).squaredNorm());
        if (d > best_d) {
          best_d = d;
          best = static_cast<int>(i);
        }
      }
      taken[best] = 1;
      tmp.push_back(pts[best]);
    }
    pts.swap(tmp);
  }
}

// Ordering key of a shape pair.
struct PairKey {
  int a, b, sa, sb;
  bool operator<(const PairKey& o) const {
    if (a != o.a) return a < o.a;
    if (b != o.b) return b < o.b;
    if (sa != o.sa) return sa < o.sa;
    return sb < o.sb;
  }
  bool operator==(const PairKey& o) const { return a == o.a && b == o.b && sa == o.sa && sb == o.sb; }
};
PairKey key_of(const BodyPointContact& c) { return {c.a, c.b, c.shape_a, c.shape_b}; }

// Largest number of points of a face contact (Bullet's manifold size).
constexpr int kFacePoints = 4;

// Points a shape pair may have: one if either shape is strictly convex.
int max_points(const Model& m, const BodyPointContact& c) {
  auto smooth = [](ShapeType t) { return t == ShapeType::Sphere || t == ShapeType::Ellipsoid; };
  const bool one = smooth(m.bodies[c.a].shapes[c.shape_a].type) || smooth(m.bodies[c.b].shapes[c.shape_b].type);
  return one ? 1 : kFacePoints;
}

}  // namespace

void build_body_geometry(const Model& m) {
  const int nb = static_cast<int>(m.bodies.size());
  int movable = 0;
  for (const BodyModel& b : m.bodies) movable += b.fixed ? 0 : 1;
  if (nb >= 2 && movable >= 1 && !(m.body_kn > 0) && !(m.kn > 0))
    throw InputError("model: body–body contacts need body_kn > 0 (or a scene k_n > 0)");
  if (nb < 2) {  // nothing can collide: no Bullet objects at all
    m.body_geometry.reset();
    return;
  }
  auto g = std::make_shared<BodyGeometry>();
  g->key = geometry_key(m);
  // Small pools: one manifold and one algorithm (plus one per mesh triangle,
  // freed at once) are live at a time.
  btDefaultCollisionConstructionInfo ci;
  ci.m_defaultMaxPersistentManifoldPoolSize = 16;
  ci.m_defaultMaxCollisionAlgorithmPoolSize = 16;
  g->config = std::make_unique<btDefaultCollisionConfiguration>(ci);
  // Perturbed GJK–EPA queries: several points for a face on a curved or
  // featureless partner in one call.
  g->config->setConvexConvexMultipointIterations(3, 3);
  g->dispatcher = std::make_unique<btCollisionDispatcher>(g->config.get());
  g->shapes.resize(nb);
  g->body_reach.assign(nb, 0.0);
  for (int i = 0; i < nb; ++i) {
    const BodyModel& b = m.bodies[i];
    g->shapes[i].reserve(b.shapes.size());
    for (const Shape& sh : b.shapes) {
      g->shapes[i].push_back(make_entry(b, sh));
      g->body_reach[i] = std::max(g->body_reach[i], g->shapes[i].back().reach);
    }
  }
  // Scratch capacity for one shape pair's reported points (a box on a few
  // mesh triangles reports a few dozen); a query with more grows it once.
  constexpr size_t kScratch = 256;
  g->raw.reserve(kScratch);
  g->raw_tmp.reserve(kScratch);
  g->order.reserve(kScratch);
  g->hull.reserve(2 * kScratch);
  g->taken.reserve(kScratch);
  g->cand.reserve(kScratch);
  g->match_new.reserve(kScratch);
  g->match_old.reserve(kScratch);
  m.body_geometry = std::move(g);
}

BodyPairLaw body_pair_law(const Model& m, int a, int b) {
  const BodyModel& A = m.bodies[a];
  const BodyModel& B = m.bodies[b];
  const PairLaw& law = m.law(A.material, B.material);
  BodyPairLaw L;
  if (A.fixed)
    L.mstar = B.mass;
  else if (B.fixed)
    L.mstar = A.mass;
  else
    L.mstar = A.mass * B.mass / (A.mass + B.mass);
  const double sm = std::sqrt(L.mstar);
  L.kn = m.body_kn > 0 ? m.body_kn : m.kn;
  if (law.kn > 0) {
    // The table's law at the scene k_n, rescaled: k_t ∝ k_n, C ∝ sqrt(k).
    const double f = L.kn / law.kn;
    L.kt = law.kt * f;
    L.cn = law.cn_coef * std::sqrt(f) * sm;
    L.ct = law.ct_coef * std::sqrt(f) * sm;
  } else {
    L.kt = 2.0 / 7.0 * L.kn;
    L.cn = linear_damping_coef(L.kn, law.eps_n) * sm;
    L.ct = linear_damping_coef(L.kt, law.eps_t) * sm;
  }
  L.mu_s = law.mu_s;
  return L;
}

void body_body_forces(const Model& m, State& s) {
  s.stats.body_body_contacts = 0;
  s.stats.max_body_overlap_ratio = 0;
  s.stats.body_overlap_a = s.stats.body_overlap_b = -1;
  const int nb = static_cast<int>(m.bodies.size());
  if (nb < 2) {
    s.body_points.clear();
    return;
  }
  BodyGeometry& g = geometry(m);
  BusyGuard guard(g);
  const std::vector<BodyPointContact>& old = s.body_points;
  std::vector<BodyPointContact>& out = s.body_points_next;
  out.clear();
  size_t cursor = 0;  // first old point whose key is not below the current pair's

  for (int a = 0; a < nb; ++a) {
    const BodyModel& A = m.bodies[a];
    for (int b = a + 1; b < nb; ++b) {
      const BodyModel& B = m.bodies[b];
      if (A.fixed && B.fixed) continue;
      BodyState& sa = s.bodies[a];
      BodyState& sb = s.bodies[b];
      if ((sb.pos - sa.pos).norm() > g.body_reach[a] + g.body_reach[b]) continue;
      const Mat3 ra = sa.q.toRotationMatrix(), rb = sb.q.toRotationMatrix();
      const BodyPairLaw law = body_pair_law(m, a, b);
      const double sm = std::sqrt(law.mstar);
      for (int ia = 0; ia < static_cast<int>(A.shapes.size()); ++ia) {
        const Shape& sha = A.shapes[ia];
        const btTransform ta = to_bt(ra * sha.rot.toRotationMatrix(), sa.pos + ra * sha.pos);
        ShapeEntry& ea = g.shapes[a][ia];
        btVector3 lo_a, hi_a;
        ea.shape->getAabb(ta, lo_a, hi_a);
        for (int ib = 0; ib < static_cast<int>(B.shapes.size()); ++ib) {
          const Shape& shb = B.shapes[ib];
          const btTransform tb = to_bt(rb * shb.rot.toRotationMatrix(), sb.pos + rb * shb.pos);
          ShapeEntry& eb = g.shapes[b][ib];
          btVector3 lo_b, hi_b;
          eb.shape->getAabb(tb, lo_b, hi_b);
          if (!TestAabbAgainstAabb2(lo_a, hi_a, lo_b, hi_b)) continue;

          g.raw.clear();
          const double tol = narrow_phase(g, ta, tb, ea, eb, sa, sb);
          if (g.raw.empty()) continue;
          const int n_max = (ea.smooth || eb.smooth) ? 1 : kFacePoints;
          reduce_points(g.raw, tol, n_max, g.raw_tmp, g.order, g.hull, g.taken);
          const int n = static_cast<int>(g.raw.size());
          // Overlap guard (docs/model.md §13): the deepest point against the thinner shape.
          const double thin = std::min(ea.half_thickness, eb.half_thickness);
          for (const RawPoint& p : g.raw)
            if (thin > 0 && p.depth / thin > s.stats.max_body_overlap_ratio) {
              s.stats.max_body_overlap_ratio = p.depth / thin;
              s.stats.body_overlap_a = a;
              s.stats.body_overlap_b = b;
            }
          // Deterministic order: by the point's position on body a.
          std::sort(g.raw.begin(), g.raw.end(),
                    [](const RawPoint& p, const RawPoint& q) { return lex_less(p.local_a, q.local_a); });

          // Previous points of this shape pair.
          const PairKey key{a, b, ia, ib};
          while (cursor < old.size() && key_of(old[cursor]) < key) ++cursor;
          size_t end = cursor;
          while (end < old.size() && key_of(old[end]) == key) ++end;
          const int n_old = static_cast<int>(end - cursor);

          // One-to-one matching, closest first: distance on whichever body the point stayed put.
          g.match_new.assign(n, -1);
          g.match_old.assign(n_old, -1);
          g.cand.clear();
          for (int i = 0; i < n; ++i)
            for (int j = 0; j < n_old; ++j) {
              const BodyPointContact& o = old[cursor + j];
              const double d = std::min((g.raw[i].local_a - o.local_a).norm(), (g.raw[i].local_b - o.local_b).norm());
              if (d < tol) g.cand.push_back({d, i, j});
            }
          std::sort(g.cand.begin(), g.cand.end(), [](const Candidate& x, const Candidate& y) {
            if (x.d != y.d) return x.d < y.d;
            if (x.i != y.i) return x.i < y.i;
            return x.j < y.j;
          });
          for (const Candidate& c : g.cand)
            if (g.match_new[c.i] < 0 && g.match_old[c.j] < 0) {
              g.match_new[c.i] = c.j;
              g.match_old[c.j] = c.i;
            }

          // The shape pair is one contact of at most n_max points. Springs:
          // every point carries a fixed share k/n_max (a face contact, n_max
          // points, has the pair's k; an edge or a corner is softer), so the
          // elastic force is the gradient of sum 1/2 (k/n_max) x_i^2 and a
          // point enters and leaves at zero depth: no energy is created when
          // points come and go. Dashpots: C/sqrt(n n_max) per point, the
          // damping of n springs of k/n_max in parallel, so every
          // configuration has the pair's restitution.
          PairLaw pl;
          pl.kn = law.kn / n_max;
          pl.kt = law.kt / n_max;
          pl.cn_coef = law.cn / (std::sqrt(static_cast<double>(n) * n_max) * sm);
          pl.ct_coef = law.ct / (std::sqrt(static_cast<double>(n) * n_max) * sm);
          pl.mu_s = law.mu_s;
          for (int i = 0; i < n; ++i) {
            const RawPoint& p = g.raw[i];
            BodyPointContact c;
            c.a = a;
            c.b = b;
            c.shape_a = ia;
            c.shape_b = ib;
            c.local_a = p.local_a;
            c.local_b = p.local_b;
            const Vec3 carried = g.match_new[i] >= 0 ? old[cursor + g.match_new[i]].spring_t : Vec3::Zero();
            c.spring_t = carried;
            c.overlap = p.depth;
            c.normal = p.n;
            c.point = 0.5 * (p.on_a + p.on_b);
            const Vec3 arm_a = c.point - sa.pos, arm_b = c.point - sb.pos;
            PairInput in;
            in.n = p.n;
            in.x = p.depth;
            in.li = in.lj = 0;  // the contact-point velocities below already hold the rotation
            in.reff = 0;
            in.sqrt_mstar = sm;
            in.vrel = (sb.vel + sb.omega.cross(arm_b)) - (sa.vel + sa.omega.cross(arm_a));
            in.vrel_mid = (sb.vel_mid + sb.omega_mid.cross(arm_b)) - (sa.vel_mid + sa.omega_mid.cross(arm_a));
            in.wi = in.wj = in.wi_mid = in.wj_mid = Vec3::Zero();
            Vec3 roll = Vec3::Zero();
            double twist = 0;
            const PairOutput f = pair_contact<ContactModel::Linear, false>(pl, in, PairSprings{c.spring_t, roll, twist}, m.dt);
            if (s.hold_body_springs) c.spring_t = carried;  // priming pass: history not advanced
            c.force_a = f.force_i;
            sa.force += f.force_i;
            sa.torque += arm_a.cross(f.force_i);
            sb.force -= f.force_i;
            sb.torque -= arm_b.cross(f.force_i);
            out.push_back(c);
          }
          s.stats.body_body_contacts += n;
          cursor = end;
        }
      }
    }
  }
  std::swap(s.body_points, s.body_points_next);
}

size_t max_body_points(const Model& m) {
  auto smooth = [](ShapeType t) { return t == ShapeType::Sphere || t == ShapeType::Ellipsoid; };
  size_t total = 0;
  const size_t nb = m.bodies.size();
  for (size_t a = 0; a < nb; ++a)
    for (size_t b = a + 1; b < nb; ++b) {
      if (m.bodies[a].fixed && m.bodies[b].fixed) continue;
      for (const Shape& sa : m.bodies[a].shapes)
        for (const Shape& sb : m.bodies[b].shapes) {
          total += (smooth(sa.type) || smooth(sb.type)) ? 1 : kFacePoints;
          if (total >= kMaxReservedBodyPoints) return kMaxReservedBodyPoints;
        }
    }
  return total;
}

double body_body_elastic_energy(const Model& m, const State& s) {
  double e = 0;
  const std::vector<BodyPointContact>& pts = s.body_points;
  for (size_t i = 0; i < pts.size();) {
    size_t j = i;
    while (j < pts.size() && key_of(pts[j]) == key_of(pts[i])) ++j;
    const double n_max = max_points(m, pts[i]);
    const BodyPairLaw law = body_pair_law(m, pts[i].a, pts[i].b);
    for (size_t k = i; k < j; ++k)
      e += 0.5 * law.kn / n_max * pts[k].overlap * pts[k].overlap +
           0.5 * law.kt / n_max * pts[k].spring_t.squaredNorm();
    i = j;
  }
  return e;
}

}  // namespace rt
