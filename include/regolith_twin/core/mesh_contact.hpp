// Grain–triangle-mesh contacts (docs/model.md §6.3): the surface of a mesh
// shape prepared for sphere queries, and the touched features of a sphere.
//
// Surface. Vertices closer than 1e-9 of the mesh's size are welded (an STL
// file repeats every vertex in each facet), degenerate triangles dropped, and
// the edge and vertex adjacency recorded. Bullet's quantized BVH
// (btBvhTriangleMeshShape, double precision) finds the triangles whose bounds
// meet a query box. A surface is immutable once built: queries only read it,
// so any number of threads may query it at once; the caller passes its own
// scratch.
//
// Features. For a sphere (centre p, radius r) every triangle within r gives
// its closest point, which lies in the triangle's interior (a face), on an
// edge or on a vertex. A feature is a contact only where the distance has a
// local minimum on the surface: an edge point must be the closest point of
// every triangle that shares the edge, a vertex that of every triangle
// around it (its Voronoi region). So a sphere on the interior of a face does
// not also touch the edges and vertices around it, a convex edge or corner is
// one contact however many triangles meet there, and a concave corner gives
// one contact per face. Contacts whose closest points coincide (within
// 1e-9 r: the same feature reported by several triangles, or a point on the
// edge between coplanar triangles) are one contact; a face is preferred to an
// edge and an edge to a vertex, so a grain on a tessellated plane always sees
// the plane's exact normal and distance. Distances are unsigned: the surface
// pushes a sphere away from the side it is on.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/body.hpp"

namespace rt {

// Welded mesh, adjacency and BVH of one TriangleMesh (defined in mesh_contact.cpp).
struct MeshSurface;

// Builds the surface of a mesh; throws InputError (naming `what`) when the
// mesh has no usable triangle or an index out of range.
std::shared_ptr<const MeshSurface> build_mesh_surface(const TriangleMesh& mesh, const std::string& what);

// Number of triangles and welded vertices of a surface.
int mesh_surface_triangles(const MeshSurface& ms);
int mesh_surface_vertices(const MeshSurface& ms);

// Touched features of the surface for a sphere with centre p (mesh frame) and
// radius r, in a fixed order (by triangle). tris and out are the caller's
// scratch (cleared here; they keep their capacity, so a warmed-up caller does
// not allocate). Returns out.size().
int mesh_hits(const MeshSurface& ms, const Vec3& p, double r, std::vector<int>& tris, std::vector<MeshHit>& out);

// Nearest surface point of a sphere (mesh frame), as shape_gap reports it:
// overlap r - distance, n from the centre towards the surface. Only
// triangles within r + reach are searched (reach < 0 or infinite: all); with
// none in reach, overlap is -1e300. For a closed mesh (every edge shared by
// two triangles) a centre inside the solid gets overlap r + distance and n
// pointing away from the surface point (the sign from the angle-weighted
// pseudo-normal of the nearest feature).
ShapeGap mesh_gap(const MeshSurface& ms, const Vec3& p, double r, double reach);

}  // namespace rt
