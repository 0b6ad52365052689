// Rigid bodies: free rotation, energies and grain–shape gaps (see body.hpp).
#include "regolith_twin/core/body.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "regolith_twin/core/mesh_contact.hpp"

namespace rt {

void finalize_body(BodyModel& b) {
  auto fail = [&](const std::string& what) {
    throw InputError("body '" + b.name + "': " + what);
  };
  if (!b.fixed) {
    if (!(b.mass > 0) || !std::isfinite(b.mass)) fail("mass must be > 0 kg (got " + std::to_string(b.mass) + ")");
    for (int k = 0; k < 3; ++k)
      if (!(b.inertia[k] > 0) || !std::isfinite(b.inertia[k]))
        fail("principal moments of inertia must be > 0 kg m^2");
    // Triangle inequality of principal moments (a physical mass distribution).
    const Vec3& I = b.inertia;
    if (I[0] > (I[1] + I[2]) * (1 + 1e-9) || I[1] > (I[0] + I[2]) * (1 + 1e-9) || I[2] > (I[0] + I[1]) * (1 + 1e-9))
      fail("principal moments of inertia violate I_a <= I_b + I_c (not a physical body)");
  }
  if (b.shapes.empty()) fail("has no collision shape");
  b.surfaces.assign(b.meshes.size(), nullptr);
  double bound = 0;
  for (const Shape& sh : b.shapes) {
    double reach = 0;
    switch (sh.type) {
      case ShapeType::Sphere:
        if (!(sh.size.x() > 0)) fail("sphere radius must be > 0 m (link '" + sh.link + "')");
        reach = sh.size.x();
        break;
      case ShapeType::Box:
      case ShapeType::Ellipsoid:
        if (!(sh.size.minCoeff() > 0)) fail("box/ellipsoid sizes must be > 0 m (link '" + sh.link + "')");
        reach = sh.type == ShapeType::Box ? sh.size.norm() : sh.size.maxCoeff();
        break;
      case ShapeType::Cylinder:
        if (!(sh.size.x() > 0 && sh.size.z() > 0)) fail("cylinder radius and length must be > 0 m (link '" + sh.link + "')");
        reach = std::hypot(sh.size.x(), sh.size.z());
        break;
      case ShapeType::Mesh:
        if (sh.mesh < 0 || sh.mesh >= static_cast<int>(b.meshes.size())) fail("mesh shape without a mesh");
        for (const Vec3& v : b.meshes[sh.mesh].vertices) reach = std::max(reach, v.norm());
        if (!b.surfaces[sh.mesh])
          b.surfaces[sh.mesh] = build_mesh_surface(b.meshes[sh.mesh], "body '" + b.name + "' (link '" + sh.link + "')");
        break;
    }
    bound = std::max(bound, sh.pos.norm() + reach);
  }
  b.bound_radius = bound;
}

Mat3 inverse_inertia_world(const BodyModel& b, const Quat& q) {
  if (b.fixed) return Mat3::Zero();
  const Mat3 R = q.toRotationMatrix();
  return R * b.inertia.cwiseInverse().asDiagonal() * R.transpose();
}

void set_body_velocity(const BodyModel& b, BodyState& s, const Vec3& v, const Vec3& omega) {
  if (b.fixed) {
    s.vel.setZero();
    s.omega.setZero();
    s.ang_mom.setZero();
  } else {
    const Mat3 R = s.q.toRotationMatrix();
    s.vel = v;
    s.omega = omega;
    s.ang_mom = R * b.inertia.asDiagonal() * R.transpose() * omega;
  }
  s.vel_mid = s.vel;
  s.omega_mid = s.omega;
}

double body_rot_energy(const BodyModel& b, const BodyState& s) {
  if (b.fixed) return 0;
  const Vec3 l = s.q.conjugate() * s.ang_mom;  // body frame
  return 0.5 * (l.array().square() / b.inertia.array()).sum();
}

double body_lin_energy(const BodyModel& b, const BodyState& s) {
  return b.fixed ? 0.0 : 0.5 * b.mass * s.vel.squaredNorm();
}

Quat free_rotation(const Vec3& inertia, const Quat& q, const Vec3& L, double dt) {
  Quat r = q;
  Vec3 l = q.conjugate() * L;  // body-frame angular momentum
  // Flow of H_k = l_k^2 / (2 I_k): the body turns about its axis k by
  // theta = l_k h / I_k, and l (seen from the body) turns by -theta.
  auto flow = [&](int k, double h) {
    const double theta = l[k] / inertia[k] * h;
    const Quat rk(Eigen::AngleAxisd(theta, Vec3::Unit(k)));
    r = r * rk;
    l = rk.conjugate() * l;
  };
  flow(0, 0.5 * dt);
  flow(1, 0.5 * dt);
  flow(2, dt);
  flow(1, 0.5 * dt);
  flow(0, 0.5 * dt);
  r.normalize();
  return r;
}

namespace {

// Gap from the closest point q on the shape surface, for a centre outside.
ShapeGap outside(const Vec3& p, const Vec3& q, double r) {
  ShapeGap g;
  const Vec3 d = q - p;
  const double dist = d.norm();
  g.overlap = r - dist;
  g.n = d / dist;
  g.point = q;
  return g;
}

ShapeGap sphere_gap(const Vec3& p, double a, double r) {
  ShapeGap g;
  const double d = p.norm();
  g.overlap = r + a - d;
  g.n = d > 0 ? Vec3(-p / d) : Vec3(-Vec3::UnitZ());
  g.point = -a * g.n;
  return g;
}

ShapeGap box_gap(const Vec3& p, const Vec3& h, double r) {
  const Vec3 q = p.cwiseMax(-h).cwiseMin(h);
  if (q != p) return outside(p, q, r);
  // Centre inside: push out through the nearest face.
  const Vec3 depth = h - p.cwiseAbs();
  int k = 0;
  depth.minCoeff(&k);
  ShapeGap g;
  g.overlap = r + depth[k];
  const double sgn = p[k] >= 0 ? 1.0 : -1.0;
  g.n = -sgn * Vec3::Unit(k);
  g.point = p;
  g.point[k] = sgn * h[k];
  return g;
}

ShapeGap cylinder_gap(const Vec3& p, double a, double hl, double r) {
  const double rho = std::hypot(p.x(), p.y());
  const Vec3 radial = rho > 0 ? Vec3(p.x() / rho, p.y() / rho, 0) : Vec3::UnitX();
  const double z = std::clamp(p.z(), -hl, hl);
  const double rc = std::min(rho, a);
  if (rho > a || std::fabs(p.z()) > hl) return outside(p, Vec3(rc * radial.x(), rc * radial.y(), z), r);
  ShapeGap g;
  const double side = a - rho, cap = hl - std::fabs(p.z());
  if (side < cap) {
    g.overlap = r + side;
    g.n = -radial;
    g.point = Vec3(a * radial.x(), a * radial.y(), p.z());
  } else {
    const double sgn = p.z() >= 0 ? 1.0 : -1.0;
    g.overlap = r + cap;
    g.n = Vec3(0, 0, -sgn);
    g.point = Vec3(p.x(), p.y(), sgn * hl);
  }
  return g;
}

// Closest point of an ellipsoid with semi-axes e to an outside point p:
// x_k = p_k e_k^2 / (t + e_k^2) with F(t) = sum (e_k p_k / (t + e_k^2))^2 = 1.
// F is convex and decreasing for t >= 0, so Newton from t = 0 rises
// monotonically to the root.
ShapeGap ellipsoid_gap(const Vec3& p, const Vec3& e, double r) {
  const Vec3 e2 = e.cwiseProduct(e);
  const double level = (p.cwiseQuotient(e)).squaredNorm();
  if (level > 1) {
    double t = 0;
    for (int it = 0; it < 100; ++it) {
      double F = -1, dF = 0;
      for (int k = 0; k < 3; ++k) {
        const double a = e[k] * p[k] / (t + e2[k]);
        F += a * a;
        dF -= 2 * a * a / (t + e2[k]);
      }
      const double step = -F / dF;
      t += step;
      if (std::fabs(step) <= 1e-15 * (t + e2.maxCoeff())) break;
    }
    Vec3 q;
    for (int k = 0; k < 3; ++k) q[k] = p[k] * e2[k] / (t + e2[k]);
    return outside(p, q, r);
  }
  // Centre inside (already a deep overlap): radial projection to the surface.
  ShapeGap g;
  const double s = level > 0 ? 1.0 / std::sqrt(level) : 1.0;
  const Vec3 q = level > 0 ? Vec3(p * s) : Vec3(0, 0, e.z());
  Vec3 grad = q.cwiseQuotient(e2);
  grad.normalize();
  g.overlap = r + (q - p).norm();
  g.n = -grad;
  g.point = q;
  return g;
}

}  // namespace

ShapeGap shape_gap(const BodyModel& b, const Shape& sh, const Vec3& p, double r, double reach) {
  const Vec3 ps = sh.rot.conjugate() * (p - sh.pos);  // centre in the shape frame
  ShapeGap g;
  switch (sh.type) {
    case ShapeType::Sphere: g = sphere_gap(ps, sh.size.x(), r); break;
    case ShapeType::Box: g = box_gap(ps, sh.size, r); break;
    case ShapeType::Cylinder: g = cylinder_gap(ps, sh.size.x(), sh.size.z(), r); break;
    case ShapeType::Ellipsoid: g = ellipsoid_gap(ps, sh.size, r); break;
    case ShapeType::Mesh:
      if (sh.mesh < 0 || sh.mesh >= static_cast<int>(b.surfaces.size()) || !b.surfaces[sh.mesh])
        throw std::logic_error("shape_gap: body '" + b.name + "' has a mesh shape without a surface (finalize_body)");
      g = mesh_gap(*b.surfaces[sh.mesh], ps, r, reach);
      if (g.overlap == -1e300) return g;
      break;
  }
  g.n = sh.rot * g.n;
  g.point = sh.pos + sh.rot * g.point;
  return g;
}

}  // namespace rt
