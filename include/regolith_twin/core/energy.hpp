// Energy bookkeeping and contact statistics computed on demand from a state.
#pragma once

#include <functional>

#include "regolith_twin/core/contact_law.hpp"
#include "regolith_twin/core/state.hpp"

namespace rt {

struct Energy {
  double translational = 0;  // sum 1/2 m v^2, J
  double rotational = 0;     // sum 1/2 I w^2, J
  double potential = 0;      // gravitational, -sum m g.x, J
  double elastic = 0;        // springs of live contacts (normal, tangential, rolling, twisting), J
  double kinetic() const { return translational + rotational; }
  double total() const { return translational + rotational + potential + elastic; }
};

Energy energy(const Model& m, const State& s);

// One live grain contact and its elastic energy by spring type.
struct ElasticContact {
  enum Kind { GrainGrain, GrainWall, GrainBody };
  Kind kind;
  int i;                // grain (GrainGrain: the lower index)
  int j;                // partner: grain, wall index or body index
  ElasticSplit energy;  // J
};

// Calls f for every live grain–grain, grain–wall and grain–body contact, each
// once (a mesh contact once per touched feature), in list order: the terms
// whose sum is Energy::elastic (body–body points aside). Nothing while the
// lists are not built.
void for_each_elastic_contact(const Model& m, const State& s, const std::function<void(const ElasticContact&)>& f);

// Kinetic energy of free grains and bodies alone (no pass over the contact
// lists), J: what a status display needs at a few hertz.
double kinetic_energy(const Model& m, const State& s);

// Mean number of grain-grain contacts per free grain (2 * pairs / grains).
double coordination_number(const Model& m, const State& s);

}  // namespace rt
