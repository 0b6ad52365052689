// Reader of LAMMPS "atom_style sphere" data files (id type diameter density x y z).
#include "regolith_twin/scene/data_file.hpp"

#include <fstream>
#include <sstream>

namespace rt {

std::vector<GrainRecord> read_sphere_data(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open grain data file");
  std::string line;
  long declared = -1;
  int line_no = 0;
  bool in_atoms = false;
  std::vector<GrainRecord> out;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    const std::string body = line.substr(0, hash);
    std::istringstream ss(body);
    std::string first;
    if (!(ss >> first)) continue;
    if (!in_atoms) {
      if (body.find("atoms") != std::string::npos && declared < 0) {
        declared = std::stol(first);
      } else if (first == "Atoms") {
        in_atoms = true;
      }
      continue;
    }
    if (first.find_first_not_of("0123456789-+.eE") != std::string::npos) break;  // next section
    GrainRecord r{};
    long type = 0;
    double diameter = 0;
    std::istringstream row(body);
    if (!(row >> r.id >> type >> diameter >> r.density >> r.pos.x() >> r.pos.y() >> r.pos.z()) || !(diameter > 0) ||
        !(r.density > 0))
      throw InputError(path + ":" + std::to_string(line_no) +
                       ": malformed atom line (expected: id type diameter>0 density>0 x y z)");
    r.radius = 0.5 * diameter;
    out.push_back(r);
  }
  if (!in_atoms) throw InputError(path + ": no 'Atoms' section found");
  if (declared >= 0 && long(out.size()) != declared)
    throw InputError(path + ": header declares " + std::to_string(declared) + " atoms but " +
                     std::to_string(out.size()) + " were read (truncated file?)");
  return out;
}

}  // namespace rt
