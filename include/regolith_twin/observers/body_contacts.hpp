// Contacts of one body in the current state: every grain and body contact
// point, and those with the bed (a body, or a grain whose centre is at most
// bed_top high).
#pragma once

#include "regolith_twin/core/state.hpp"

namespace rt {

struct BodyContacts {
  long total = 0;
  long bed = 0;
};
BodyContacts body_contacts(const State& s, int b, double bed_top);

}  // namespace rt
