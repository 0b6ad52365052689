// Plain grain files: the LAMMPS "atom_style sphere" data format (id type
// diameter density x y z), read by the peers of the benchmark as well, and a
// simple text dump of the final state.
#pragma once

#include <string>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

struct GrainRecord {
  long id;
  double radius;   // m
  double density;  // kg/m^3
  Vec3 pos;        // m
};

// Read the Atoms section of a LAMMPS sphere data file. Throws InputError
// naming the file and line on malformed content.
std::vector<GrainRecord> read_sphere_data(const std::string& path);

}  // namespace rt
