// Closest-point geometry of spheres against analytic walls.
#include "regolith_twin/core/walls.hpp"

#include <algorithm>
#include <cmath>

namespace rt {
namespace {

// Gap to a surface point q that may be approached from either side.
WallGap gap_to_point(const Vec3& p, const Vec3& q, double r, const Vec3& fallback_n) {
  const Vec3 d = q - p;
  const double dist = d.norm();
  return {dist > 0 ? Vec3(d / dist) : fallback_n, r - dist};
}

// Surface of revolution between radius r0 at axial coordinate 0 and r1 at
// length L (cylinder when r0 == r1; infinite when L <= 0). `inner` grains
// live on the axis side; a centre that crossed the surface gets overlap > r.
WallGap cone_gap(const Wall& w, const Vec3& p, double r) {
  const Vec3 rel = p - w.origin;
  const double z = rel.dot(w.axis);
  Vec3 radial = rel - z * w.axis;
  const double rho = radial.norm();
  // Unit radial direction (any perpendicular when on the axis).
  Vec3 er = rho > 1e-300 ? Vec3(radial / rho) : w.axis.unitOrthogonal();
  // Meridian segment from (r0, 0) to (r1, L) in (rho, z) coordinates.
  const bool infinite = w.length <= 0;
  const double L = infinite ? 1.0 : w.length;
  const double r0 = w.radius, r1 = infinite ? w.radius : w.radius2;
  const double sr = r1 - r0, sz = L;
  const double seg2 = sr * sr + sz * sz;
  double t = ((rho - r0) * sr + z * sz) / seg2;
  if (!infinite) t = std::clamp(t, 0.0, 1.0);
  const double qr = r0 + t * sr, qz = t * sz;
  // Outward (away from axis) normal of the meridian line in (rho, z).
  const double len = std::sqrt(seg2);
  const double nr = sz / len, nz = -sr / len;
  const double dr = rho - qr, dz = z - qz;
  const double signed_out = dr * nr + dz * nz;  // > 0: centre outside the surface
  const bool interior = infinite || (t > 0.0 && t < 1.0);
  const Vec3 n_out = nr * er + nz * w.axis;     // unit, pointing away from the axis
  if (interior) {
    // Signed distance from the surface, positive on the grains' side.
    const double s = w.inner ? -signed_out : signed_out;
    return {w.inner ? n_out : Vec3(-n_out), r - s};
  }
  // Beyond an end: the rim circle is the closest feature.
  const Vec3 q = w.origin + qz * w.axis + qr * er;
  return gap_to_point(p, q, r, w.inner ? n_out : Vec3(-n_out));
}

}  // namespace

WallGap wall_gap(const Wall& w, const Vec3& p, double r) {
  switch (w.type) {
    case WallType::Plane: {
      // Half-space: grains live on the side the normal points to.
      const double d = (p - w.origin).dot(w.axis);
      return {-w.axis, r - d};
    }
    case WallType::Disk: {
      const Vec3 rel = p - w.origin;
      const double h = rel.dot(w.axis);
      Vec3 in_plane = rel - h * w.axis;
      const double rho = in_plane.norm();
      if (rho > w.radius) in_plane *= w.radius / rho;
      return gap_to_point(p, w.origin + in_plane, r, h >= 0 ? Vec3(-w.axis) : w.axis);
    }
    case WallType::Rectangle: {
      const Vec3 rel = p - w.origin;
      const Vec3 v = w.axis.cross(w.u);
      const double a = std::clamp(rel.dot(w.u), -w.half_u, w.half_u);
      const double b = std::clamp(rel.dot(v), -w.half_v, w.half_v);
      const double h = rel.dot(w.axis);
      return gap_to_point(p, w.origin + a * w.u + b * v, r, h >= 0 ? Vec3(-w.axis) : w.axis);
    }
    case WallType::Cylinder:
    case WallType::Cone:
      return cone_gap(w, p, r);
    case WallType::SphereShell: {
      const Vec3 rel = p - w.origin;
      const double d = rel.norm();
      const Vec3 er = d > 1e-300 ? Vec3(rel / d) : Vec3::UnitZ();
      if (w.inner) return {er, r - (w.radius - d)};
      return {-er, r - (d - w.radius)};
    }
  }
  return {Vec3::UnitZ(), -1e300};
}

Wall make_plane(const Vec3& point, const Vec3& normal, int material) {
  Wall w;
  w.type = WallType::Plane;
  w.origin = point;
  w.axis = normal.normalized();
  w.law_material = material;
  return w;
}

Wall make_cylinder(const Vec3& base, const Vec3& axis, double radius, double length, bool inner,
                   int material) {
  Wall w;
  w.type = WallType::Cylinder;
  w.origin = base;
  w.axis = axis.normalized();
  w.radius = w.radius2 = radius;
  w.length = length;
  w.inner = inner;
  w.law_material = material;
  return w;
}

}  // namespace rt
