// Body–body contacts (MODEL.md §6): contact points, normals and depths from
// Bullet's narrow phase, turned into the spring–dashpot law of the pair.
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

// Find the contact points of every pair of bodies (at least one movable),
// carry the tangential history of points that persist, and add the forces
// and torques to State::bodies[].force / torque. Part of the force stage.
void body_body_forces(const Model& m, State& s);

}  // namespace rt
