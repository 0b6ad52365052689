// Body–body contacts (docs/model.md §6): contact points, normals and depths from
// Bullet's narrow phase, turned into the spring–dashpot law of the pair.
// Bullet objects live in Model::body_geometry (see model.hpp); State keeps
// only plain data (State::body_points), so it can be copied and saved.
//
// Geometry. Every body shape becomes one Bullet collision object, with all
// collision margins set to 0 so the shapes are exact:
//   Box       btBoxShape (box–box pairs go through btBoxBoxDetector; other
//             polyhedral pairs through SAT and face clipping)
//   Sphere    btSphereShape
//   Cylinder  btCylinderShapeZ (axis along the shape's z)
//   Ellipsoid an exact ellipsoid: a convex shape whose support point in
//             direction d is A^2 d / |A d| (A = diag of the semi-axes), used by
//             GJK–EPA (a sphere when the semi-axes are equal)
//   Mesh      a fixed body: btBvhTriangleMeshShape (exact triangles);
//             a movable body: the convex hull of the mesh vertices
//             (approximation: concave parts of a moving mesh are filled)
// Curved convex pairs use GJK–EPA with Bullet's multipoint perturbation (three
// extra queries with the smaller shape tilted), so a flat face resting on a
// curved or polyhedral partner gets several points in one call. Every
// reported point is collected (before Bullet's 4-point manifold reduction,
// which depends on insertion order); duplicates within the matching distance
// collapse into the deepest, points inside the patch outline that are not
// deeper than it are dropped (a box on two floor triangles also reports
// points along their shared edge), and a longer outline is thinned to n_max
// spread-out points. No Bullet state survives from one step to the next.
//
// History. State::body_points holds the points of the last force pass,
// sorted by (a, b, shape_a, shape_b) and, within a shape pair, by the point's
// position on body a. A new point takes over the tangential spring of the
// previous step's point of the same shape pair that lies within the pair's
// matching distance (Bullet's contact-breaking threshold, 2 % of the smaller
// shape's size) on either body: a corner sliding over a face keeps its
// position on the body it belongs to. Closest pairs are matched first, one to
// one; unmatched points start with a zero spring.
//
// Law. Each shape pair is one contact of at most n_max points (4; 1 when a
// sphere or ellipsoid is involved: strictly convex shapes touch at one point,
// the deepest one is kept). Springs: every point carries a fixed share
// k_n/n_max and k_t/n_max, so a face contact (n_max points) has the pair's
// k_n exactly (docs/model.md §6: k/n with n = 4), while an edge (2 points) has
// k_n/2 and a corner k_n/4. Decision: the literal k/n with the current n is
// not conservative (a point entering at zero depth halves the others'
// stiffness, one leaving doubles it): a box tumbling onto a plate at ε = 1
// gained or lost up to 24 % of its energy with it, against < 1e-4 with fixed
// shares (body_collision_test). Dashpots: C/sqrt(n n_max) per point, the
// damping of n springs k/n_max in parallel, so the pair's restitution holds
// for any n (a face: C/n). m* = M_a M_b / (M_a + M_b) (M of the movable body
// against a fixed one), ε and μ of m.law(material_a, material_b), Coulomb cap
// μ_s f_n per point. k_n = Model::body_kn (the scene k_n if <= 0); k_t and
// the damping scale with it. The law is always linear (a Hertz scene uses the
// linear law for body–body pairs, which have no radius of curvature).
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Build (or rebuild) the Bullet shapes of every body of m into
// m.body_geometry. Called by finalize_model; call again after changing the
// bodies' shapes. Throws InputError if two bodies could touch and neither
// body_kn nor the scene k_n is > 0.
void build_body_geometry(const Model& m);

// Find the contact points of every pair of bodies (at least one movable),
// carry the tangential history of points that persist, and add the forces
// and torques to State::bodies[].force / torque (about each centre of mass;
// the caller zeroes them). Part of the force stage. With
// State::hold_body_springs set (prime()), each point keeps the spring it
// carried into the pass: forces are evaluated, the history is not advanced. Uses
// BodyState::vel/omega (predicted end of step) for the dashpots and
// vel_mid/omega_mid for the spring increments.
void body_body_forces(const Model& m, State& s);

// Largest number of body–body contact points the bodies of m can have at once
// (every shape pair of two bodies, at least one movable, at its n_max), capped
// at kMaxReservedBodyPoints. make_state reserves State::body_points (and its
// double buffer) for this many, so body_body_forces does not allocate; beyond
// the cap the list may grow (and reallocate) like the grain lists. Scratch of
// the query lives in the geometry (reserved for 256 reported points per shape
// pair; a query with more grows it once).
constexpr size_t kMaxReservedBodyPoints = size_t(1) << 16;
size_t max_body_points(const Model& m);

// Elastic energy stored in the body–body contacts of the last force pass
// (1/2 k_n/n x^2 + 1/2 k_t/n |S|^2 per point), J.
double body_body_elastic_energy(const Model& m, const State& s);

// Body–body stiffness and damping of one shape pair (all n points together).
struct BodyPairLaw {
  double kn = 0, kt = 0;  // N/m
  double cn = 0, ct = 0;  // N s/m (already multiplied by sqrt(m*))
  double mu_s = 0;
  double mstar = 0;       // kg
};
BodyPairLaw body_pair_law(const Model& m, int a, int b);

}  // namespace rt
