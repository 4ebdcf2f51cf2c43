// The bond list's whole life (bond_list.cpp): installed, broken, frozen inside rigid bodies,
// removed. The step's bond forces are stages/bonds.cpp.
#pragma once
#include <cstdint>
#include <span>

#include "state.hpp"

namespace asperity::detail {

// Bonds between the chosen particles (all when `ids` is empty) at most `tolerance` apart, merged
// into the bond list (material, tolerance and ids checked by the caller); returns how many.
std::size_t install_bonds(State& s, const BondMaterial& material, double tolerance,
                          std::span<const std::int64_t> ids, bool stress_free);
void remove_bonds(State& s);  // every bond, no events, no energy booked
// The breaks the bond stage flagged (after the step): events, energy, compaction.
void process_breaks(State& s);
// Moves the bonds inside lazy groups (Group::lazy, set by the caller) to State::frozen_bonds and
// the others back; true if any moved (the topology is then refreshed).
bool settle_frozen_bonds(State& s);
// Every bond, active and frozen, in one store sorted by (a, b) (checkpoints).
BondStore all_bonds(const State& s);
// x and y (each sorted by (a, b), no bond in both) in one store sorted by (a, b); its material
// and `any` are left to the caller.
BondStore merge_bonds(const BondStore& x, const BondStore& y);

}  // namespace asperity::detail
