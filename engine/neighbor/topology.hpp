// Who is bonded to whom, derived from the bond list and indexed by particle: the gather's
// incidence of the bonds the step computes, each particle's bonded partners (which the neighbour
// search leaves out of the contact list), the particles the bond stage reads and the rotation
// locks (model.md 2). Rebuilt whenever the bonds or the particles' order change: after an
// install, a break, a reorder, a load.
#pragma once
#include "state.hpp"

namespace asperity::detail {

void refresh_bond_topology(State& s);

}  // namespace asperity::detail
