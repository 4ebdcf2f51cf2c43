// Everything a World holds: the world's data (State), what one step works with (StepContext,
// step_context.hpp) and what is derived from the data and redone when it changes (Caches). See
// engine/step.cpp for the order of the stages and stages/views.hpp for what each reads and writes.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "asperity/world.hpp"
#include "core/load.hpp"
#include "kernels/kernels.hpp"
#include "neighbor/cell_grid.hpp"
#include "store/bonds.hpp"
#include "store/groups.hpp"
#include "store/pairs.hpp"
#include "store/particles.hpp"
#include "store/walls.hpp"
#include "step_context.hpp"

namespace asperity::detail {

// An empty slot at the end of a particle's run of bonded partners (Caches::partners): above every
// index, so the run stays sorted for the search's binary search.
inline constexpr std::int32_t kNoPartner = std::numeric_limits<std::int32_t>::max();

// Derived from the world's data and kept between steps because computing them every step costs:
// each says when it is valid, and what the API changes reaches them through changed() (below).
struct Caches {
  // Bonded partners per particle (CSR, sorted): the neighbour search leaves bonded pairs out.
  // With the bond incidence (the gather's CSR of the bonds) and the bonded particles, redone by
  // refresh_bond_topology whenever the bond list changes.
  // A break takes a partner out of its particle's run, which stays sorted and ends in
  // kNoPartner slots (refresh_bond_topology_after_breaks) until the next full refresh.
  // The entries of dead bonds (BondStore::dead) point to the zero record instead, in their place,
  // until compact_bonds takes the bonds out and rebuilds the incidence (the next neighbour build).
  Incidence bond_incidence;
  std::vector<std::size_t> dead_bonds;  // their indices in s.bonds, in no order
  // Per particle, 1 where it holds a bond the step computes (a live entry of bond_incidence).
  std::vector<std::uint8_t> bond_held;
  std::vector<std::int32_t> partner_start, partners;
  // Per particle, its bonds whose parallel bond holds (frozen ones too): kept only while the
  // rotation lock counts beams alone (WorldSettings::rotation_lock_beams).
  std::vector<std::int32_t> beam_count;
  // The particles holding a bond the step computes (frozen ones aside): the bond stage checks
  // their angular velocities each step (stages/bonds.cpp, bond_stage).
  std::vector<std::int32_t> bonded_particles;
  // Whether a particle spins (an angular velocity other than +0) as the last step left them: the
  // bits of wx, wy, wz ORed over the particles a pair can reach (not inert), and over the ones
  // holding a bond the step computes. The gather + integrate stage takes them per block after the
  // block moved, bookkeep adds the moved group members' new spin. Valid while spin_known: set by
  // a step that ran with any_rotating, cleared by the API (spins, inert flags, group motions) and
  // by a new bond topology; the pair and bond stages read them instead of scanning the particles,
  // serially, every step.
  bool spin_known = false;
  std::uint64_t spin_reachable = 0, spin_bonded = 0;
  // Every bond's beam moments are +-0 (set by a scan in refresh_bond_topology, cleared by a bond
  // stage that runs with spin): only spin makes them grow, so the bond stage may take the kernel
  // that neither carries nor stores them (stages/bonds.cpp).
  bool bond_moments_zero = false;
  // Some bond lost its beam or its contact bond (BondStore::holds): the bond kernel reads what
  // holds; else every bond holds both and the column is not read. Set by refresh_bond_topology,
  // with the count of such bonds, which breaks keep up to date.
  bool bonds_partial = false;
  std::size_t partial_bonds = 0;
  // Some particle holding a bond the step computes turns (particle_turns): the bond records must
  // carry the torque of the bonds' shear forces. Valid while bond_ends_turn_known: cleared by a
  // new bond topology and by the API (membership, group motions); a break can only free the
  // broken bonds' ends, which refresh_bond_topology_after_breaks looks at.
  bool bond_ends_turn_known = false, bond_ends_turn = true;
  // The layout of the bond records the last bond stage wrote (store/bonds.hpp, BondRecord): with
  // the moment (12 doubles a bond), without (8: every moment zero) or forces only (4: besides, no
  // end of a bond turns). The gather reads them so, and World::torque adds the terms left out.
  kernels::BondRecord bond_records = kernels::BondRecord::moments;
  // Fewer than half the pair records were live when the pair kernel last counted them
  // (PairStore::live_current): the kernel flags them and the gather skips the dead ones
  // (stages/pairs.cpp). Kept here: a neighbour build replaces the pair store.
  bool pair_records_sparse = false;
  ServoContacts servo;  // the contacts between bodies, for the servo (store/groups.hpp)
  // Stores filled and swapped in place of allocating: the pairs a break step's broken bonds free
  // (process_breaks), and the other halves of the pair list and the wall contact list, which a
  // neighbour build, a reorder or the merge of the freed pairs writes into (build_pairs,
  // build_wall_contacts, reorder, insert_pairs; kept between builds only where builds or merges
  // come often: neighbor/build.cpp, keep_spares).
  PairStore freed_pairs, spare_pairs;
  WallContacts spare_wall_contacts;
  std::vector<std::vector<std::int32_t>> found_pairs;  // a neighbour build's, per chunk of particles
  std::vector<std::vector<WallCandidate>> found_wall_contacts;  // the same for the walls
  std::uint64_t last_build_step = 0;  // State::step at the last neighbour build
  CellGrid grid;  // the last neighbour build's cells (neighbor/cell_grid.hpp)
  // Idle group members (see Group::busy), per particle index; valid while idle_valid (the split
  // is redone at every neighbour build and after the API changes motions or applied forces).
  std::vector<std::uint8_t> idle;
  bool idle_valid = false;
  // The split went stale only because a break step merged freed pairs into the list
  // (insert_pairs) since it was made: the groups, their laziness and the bonds that may be
  // frozen are as they were, so the next split need not look for bonds to freeze or thaw. Cleared
  // by every other change (changed(), a neighbour build).
  bool idle_pairs_only = false;
  // Per particle block (kParticleBlock): whether it holds a free particle (to integrate), and for
  // the blocks that do not, their busy group members (the only ones the gather has to visit).
  std::vector<std::uint8_t> block_free;
  Incidence block_busy;
};

// The world's data: everything a checkpoint keeps, and the neighbour list built from it.
struct State {
  WorldSettings settings;
  ParticleStore p;
  PairStore pairs;
  Incidence incidence;  // of `pairs`, rebuilt with them: the gather walks it
  WallStore walls;
  std::vector<Group> groups;
  BondStore bonds;
  // Bonds held still: both ends in one rigid group that does not turn (Group::lazy). Such a bond
  // never deforms and its forces cancel within the body, so the step leaves it out; it keeps its
  // state, counts in the API, the energies and checkpoints, and goes back to `bonds` when its
  // group may turn (settle_frozen_bonds). Sorted by (a, b) like `bonds`; never breaks while frozen.
  BondStore frozen_bonds;
  // Raised whenever the bond list changes (refresh_bond_topology): caches of bond indices check it.
  std::uint64_t bond_version = 0;
  // Contacts that a broken bond left behind, waiting for a rebuild to merge them into the pair
  // list: only a checkpoint written before breaks entered the list at once (process_breaks,
  // insert_pairs) can hold some; the first rebuild after loading takes them.
  PairStore inherited;
  std::vector<BreakEvent> break_events;
  bool any_rotating = true;  // some particle can rotate: kernels read angular velocities
  // Some bond was installed stress-free: the pair and bond kernels read rest overlaps (which are
  // all 0 otherwise, so a world without such bonds never reads the columns). Never reset.
  bool rest_overlaps = false;

  double dt = 0;             // in use
  double dt_estimate = 0;    // last critical estimate (no safety factor)
  bool dt_fixed = false;
  std::uint64_t step = 0;
  double time = 0;
  std::uint64_t last_estimate_step = 0;

  double skin = 0;
  bool need_rebuild = true;
  // A step stopped by the health check left non-finite values behind (kept for inspection): the
  // next cycle looks for them before it steps (World::cycle), so that no later cycle can succeed
  // while, e.g., a fixed group's member still holds a NaN the step does not touch.
  bool unhealthy = false;
  bool force_reorder = false;
  std::uint64_t rebuilds = 0, reorders = 0, rebuilds_since_reorder = 0;

  Ledger ledger;
  // Kinetic energy at the time level of the last step's forces (mean of the half-step velocities
  // around it), so that Ek and Es are measured at the same instant; invalid after the user
  // changes velocities or positions, when it is computed from the stored velocities instead.
  double kinetic_at_step = 0;
  bool kinetic_valid = false;
  double reference_energy = -1;  // Ek + Es when the run started (runaway check); <0: unset
  double reference_input = 0;    // boundary + gravity work at that moment
  std::atomic<bool> stop_requested{false};

  StepContext ctx;
  Caches cache;
};

// Whether particle i turns: its rotation is neither locked (settings, API, bonds: model.md 2) nor
// fixed by its group (the joint's halves and platens; inert members and worlds without rotation
// allow no other). Only then do the contact points and the moments of its forces move it.
inline bool particle_turns(const State& s, std::size_t i) {
  const std::int32_t g = s.p.group[i];
  if (g >= 0) return s.groups[std::size_t(g)].motion.rotation != Dof::fixed;
  return s.p.rotation_locked[i] == 0;
}

// What a World call changed, for changed(): the one place that says what must be redone.
enum class Change {
  particles,       // positions, radii, membership...: rebuild; kinetic energy, its reference, spins
  velocities,      // linear velocities: the kinetic energy and its reference
  spins,           // angular velocities: also which particles spin
  applied_forces,  // a group member with a force is busy: the idle split
  group_motion,    // a group that may now rotate has no idle members; its members may spin
  time_step,       // dt or its safety: a fresh estimate (and its check) before the next step
  skin,            // the neighbour list
  added,           // new particles: a reorder at the next build
};
inline void changed(State& s, Change c) {
  s.cache.idle_pairs_only = false;  // the next split looks at everything
  switch (c) {
    case Change::particles:
      s.need_rebuild = true;  // the rebuild also redoes the busy / idle split of the groups
      s.reference_energy = -1;
      s.kinetic_valid = false;
      s.cache.spin_known = false;
      s.cache.bond_ends_turn_known = false;  // group membership
      break;
    case Change::velocities:
      s.reference_energy = -1;
      s.kinetic_valid = false;
      break;
    case Change::spins:
      s.reference_energy = -1;
      s.kinetic_valid = false;
      s.cache.spin_known = false;
      break;
    case Change::applied_forces: s.cache.idle_valid = false; break;
    case Change::group_motion:
      s.cache.idle_valid = false;  // the split syncs the lazy members first
      s.cache.spin_known = false;
      s.cache.bond_ends_turn_known = false;
      break;
    case Change::time_step:
      s.last_estimate_step = 0;
      s.need_rebuild = true;  // the build makes a fresh estimate and checks it
      break;
    case Change::skin: s.need_rebuild = true; break;
    case Change::added: s.force_reorder = true; break;
  }
}

// f(store, k) for every bond: the ones the step computes (s.bonds), then the frozen ones.
// Dead records (BondStore::dead) are no bonds and are left out.
template <class F>
void for_each_bond(const State& s, F&& f) {
  for (const BondStore* q : {&s.bonds, &s.frozen_bonds})
    for (std::size_t k = 0; k < q->n; ++k)
      if (!q->dead(k)) f(*q, k);
}

// Threads for a parallel stage. Automatic (settings.threads == 0): one per 10 000 units of
// force work, a pair counting one and a bond two (its kernel and gather cost about twice a
// pair's), or one per 20 000 particles if that is more (before the first pair list), up to the
// cores available. Below that, thread start-up and barriers cost more than they save, and on a
// loaded machine a spinning thread makes a small scene many times slower (perf/README.md,
// "Threads"). The results do not depend on the count. Also no more than the cores that other
// processes leave free (StepContext::load_limit): a thread that shares its core with a busy
// process holds the others up at every barrier.
inline int thread_count(const State& s) {
  if (s.settings.threads > 0) return s.settings.threads;
  const std::size_t work = s.pairs.n + 2 * s.bonds.n;
  const std::size_t extra = std::max(work / 10000, s.p.n / 20000);
  const int cores = s.ctx.load_limit > 0 ? std::min(s.ctx.max_threads, s.ctx.load_limit) : s.ctx.max_threads;
  return std::clamp(int(std::min<std::size_t>(extra, 1024)) + 1, 1, std::max(1, cores));
}

}  // namespace asperity::detail
