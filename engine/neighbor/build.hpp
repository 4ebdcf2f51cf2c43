// Stage 1 of a step: the neighbour list (neighbor/build.cpp).
#pragma once
#include <cstdint>

#include "state.hpp"

namespace asperity::detail {

// The pair list, wall contacts and incidence rebuilt (with a reorder every reorder_interval
// builds), the history carried over, the time step re-estimated.
void build_neighbors(State& s);
void ensure_skin(State& s);  // derive the automatic skin if unset
// The lists a build keeps to write the next one into (Caches::spare_pairs ...) released.
void release_spares(State& s);
// Pair k of q (a and b set) as the search starts a new one: the current direction as its
// previous normal, no shear or normal force, no rest overlap. Returns the centres' distance.
double start_pair(PairStore& q, std::size_t k, const ParticleStore& p);
// Pairs the list lacks (sorted by (a, b), with their history) merged into it between two
// rebuilds; the incidence is rebuilt and the group split redone at the next step.
void insert_pairs(State& s, const PairStore& add);
// CSR of the pairs (a, b) per particle, entries (k << 1) | (particle is b), ascending k.
void build_incidence(std::size_t particles, const std::int64_t* a, const std::int64_t* b,
                     std::size_t count, Incidence& inc);

}  // namespace asperity::detail
