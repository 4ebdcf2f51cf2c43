// What each stage of a step reads and writes. A stage takes its view, not the whole State, so its
// signature says what it touches and the stage files do not see State at all (they include this
// header, not state.hpp); step.cpp hands them out (step.hpp, pair_view...). Members are references
// into the State (read-only where the stage only reads) or values the stage reads once when it
// is set up.
#pragma once
#include <cstdint>
#include <vector>

#include "step_context.hpp"
#include "store/bonds.hpp"
#include "store/groups.hpp"
#include "store/pairs.hpp"
#include "store/particles.hpp"
#include "store/walls.hpp"

namespace asperity::detail {

// Stage 2, contacts (stages/pairs.cpp).
struct PairStageView {
  const ParticleStore& p;      // positions, velocities, spins, radii
  PairStore& pairs;            // the kernel's records, touched and live flags
  const ContactMaterial& contact;
  double dt;
  std::uint64_t step;          // live flags are refreshed every 64th step where most pairs touch
  bool any_rotating, rest_overlaps;
  int threads;                 // whether the records are streamed past the caches
  bool spin_known;             // Caches::spin_known and what it says of the reachable particles
  std::uint64_t spin_reachable;
  bool& records_sparse;        // Caches::pair_records_sparse: kept across neighbour builds
  StepContext& ctx;            // the kernels; per-block slip
  Ledger* ledger;              // friction booked here; null where energy is not tracked
};

// Stage 3, bonds (stages/bonds.cpp).
struct BondStageView {
  const ParticleStore& p;
  BondStore& bonds;            // the kernel's records, forces, moments and break flags
  const ContactMaterial& contact;
  double dt;
  bool any_rotating, rest_overlaps;
  bool spin_known;             // Caches::spin_known and what it says of the bonded particles
  std::uint64_t spin_bonded;
  const std::vector<std::int32_t>& bonded_particles;
  bool bonds_partial;          // Caches::bonds_partial: read what holds of each bond
  bool& moments_zero;          // Caches::bond_moments_zero: cleared by a step with spin
  bool ends_turn;              // Caches::bond_ends_turn: the records carry the levers
  kernels::BondRecord& records;  // Caches::bond_records: the layout written
  StepContext& ctx;            // the kernels; per-block breaks and slip
  Ledger* ledger;              // friction of contact springs whose contact bond broke; or null
};

// Stage 4, walls (stages/walls.cpp).
struct WallStageView {
  const ParticleStore& p;
  WallStore& walls;            // the contacts' state; each wall's force; meshes read
  double dt;
  bool any_rotating;
  const StepContext& ctx;      // the kernels
  Ledger* ledger;              // friction and boundary work; or null
};

// Stages 5 + 7, gather and integrate (stages/integrate.cpp).
struct IntegrateStageView {
  ParticleStore& p;            // forces gathered; free particles moved
  const PairStore& pairs;
  const Incidence& incidence;  // of the pairs
  const WallContacts& wall_contacts;
  const BondStore& bonds;
  const Incidence& bond_incidence;
  const std::vector<std::uint8_t>& bond_held;  // Caches::bond_held: which particles hold a bond
  kernels::BondRecord bond_records;  // the layout the bond stage wrote
  // The idle split of rigid groups (Caches::idle, block_free, block_busy).
  const std::vector<std::uint8_t>& idle;
  const std::vector<std::uint8_t>& block_free;
  const Incidence& block_busy;
  bool spin_known;             // Caches::spin_known and its answers, which the stage renews
  std::uint64_t spin_reachable, spin_bonded;
  Vec3 gravity;
  double local_damping, dt;
  bool any_rotating;
  StepContext& ctx;            // the kernels; per-block results
};

// Stage 6, groups (stages/groups.cpp).
struct GroupStageView {
  ParticleStore& p;            // members' forces read; members moved
  std::vector<Group>& groups;  // each group's motion advanced
  // The servo's stiffness: the contacts between bodies (Caches::servo, retaken when the pair list
  // was rebuilt or the bond list changed) and what they touch.
  const PairStore& pairs;
  const BondStore& bonds;
  const WallStore& walls;
  ServoContacts& servo;
  std::uint64_t rebuilds, bond_version;
  const ContactMaterial& contact;
  Vec3 gravity;
  double local_damping, dt;
  double& kinetic_at_step;     // the groups' share; the free particles' is added in bookkeeping
  StepContext& ctx;            // the members moved each step, by group and by block; per-group results
  Ledger* ledger;              // boundary, damping and gravity work; or null
};

}  // namespace asperity::detail
