// Who is bonded to whom, derived from the bond list and indexed by particle: the gather's
// incidence of the bonds the step computes, each particle's bonded partners (which the neighbour
// search leaves out of the contact list), the particles the bond stage reads and the rotation
// locks (model.md 2). Rebuilt whenever the bonds or the particles' order change: after an
// install, a break, a reorder, a load.
#pragma once
#include <vector>

#include "state.hpp"

namespace asperity::detail {

void refresh_bond_topology(State& s);

// What a break step did to the bond list (process_breaks): the bonds of which nothing holds any
// more, now dead (BondStore::dead: their indices, ascending, and their ends a, b in pairs), and
// the ends of the bonds whose parallel bond broke.
struct BondLosses {
  std::vector<std::size_t> gone;
  std::vector<std::int64_t> gone_ends, beam_ends;
  bool partial_left = false;  // some bond lost one part and keeps the other
};
// The topology brought up to date after such a step in what the step changed (the dead bonds'
// incidence entries, the partners, locks and counts of their particles): the same as
// refresh_bond_topology, in work proportional to the breaks, not to the particles and bonds.
void refresh_bond_topology_after_breaks(State& s, const BondLosses& losses);

// The dead bonds taken out of the list and the incidence rebuilt without them (at a neighbour
// build, before the particles may be reordered). The forces, their sums and every flag stay as
// they were; only the bond indices move (bond_version).
void compact_bonds(State& s);

}  // namespace asperity::detail
