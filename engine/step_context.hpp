// What one step works with besides the world's data (StepContext), the stage loops it runs
// (StageLoop) and their block sizes: what the stages see of a step (stages/views.hpp), apart from
// the State that holds them (state.hpp).
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "asperity/world.hpp"
#include "core/load.hpp"
#include "kernels/kernels.hpp"
#include "store/pairs.hpp"

namespace asperity::detail {

// A rigid group's motion in the current step, for its members' moves and the ledgers
// (stages/groups.cpp, group_stages).
struct GroupStep {
  bool moves = false;  // the group has members (its motion was advanced)
  Vec3 old_centre{0, 0, 0}, centre{0, 0, 0}, velocity{0, 0, 0}, angular_velocity{0, 0, 0};
  Vec3 mean_angular_velocity{0, 0, 0}, theta{0, 0, 0};
  bool spins = false;
  double boundary = 0, damping = 0, gravity = 0;  // its terms of the ledgers
  double kinetic = 0;                             // of its inert and idle members
};

// Cumulative ledgers of model.md 8 (kinetic and strain are computed on demand).
struct Ledger {
  double friction = 0, damping = 0, boundary = 0, gravity = 0, released = 0;
};

// Work units: pairs and particles are processed in fixed blocks; per-block partial sums are
// combined in block order, so sums do not depend on how blocks are spread over threads.
inline constexpr std::size_t kPairBlock = 1024;      // multiple of kMaxLanes
inline constexpr std::size_t kParticleBlock = 512;
// The pair and bond stages' block for a list of `total` entries: kPairBlock, or smaller (down to
// 256) so that a short list still makes 32 blocks, which two threads can share out evenly by
// taking each other's last blocks (step.cpp, run_stages); long lists keep the larger blocks,
// which cost less per entry. A function of the list alone, never of the thread count: the
// blocks' partial sums are combined in order.
inline std::size_t pair_block_size(std::size_t total) {
  constexpr std::size_t stage = PairStore::kTouchStage;  // blocks of whole pair stages
  const std::size_t want = (total / 32 + stage - 1) / stage * stage;
  return std::min(kPairBlock, std::max(std::size_t(256), want));
}

// A per-pair or per-bond record array this large is taken to be past the caches: the pair kernel
// writes it with non-temporal stores (stages/pairs.cpp) and the gather prefetches it
// (stages/integrate.cpp); both pay only where the records do not stay in cache.
inline bool records_past_caches(const AVec<double>& records) {
  return records.size() * sizeof(double) > (std::size_t(4) << 20);
}

struct ParticleBlockResult {
  double damping = 0, gravity = 0, applied = 0;
  double kinetic = 0;        // at the step's time level: from the mean of old and new velocities
  double max_disp2 = 0;      // squared displacement since the last build
  double worst_step = 0;     // max of |v| dt / R and |w| dt / 0.1 rad (1 = health limit)
  std::int32_t worst = -1;   // its particle index
  // The block's angular velocities after the stage, bits ORed (State::spin_known): over its
  // particles that are not inert, and over those that hold a bond the step computes.
  std::uint64_t spin_reachable = 0, spin_bonded = 0;
};

// A stage split around its block loop, so that step.cpp runs the loops of the pair, bond and
// wall stages and then of the gather + integrate stage in one parallel region (run_stages)
// instead of one region each: every fork and join costs the step a wait of all its threads.
// `run(blk)` writes only block blk's slots; `finish` sums the blocks in order, so the results are
// those of separate regions, bit for bit.
struct StageLoop {
  std::size_t blocks = 0;
  bool after_barrier = false;  // its blocks start once every earlier stage's blocks are done
  std::function<void(std::size_t)> run;
  std::function<void()> finish;  // may be empty
};

// What a step works with besides the world's data: the kernels and threads it runs on, and its
// scratch (per-block partial results, the group stages' member slots), rewritten every step.
struct StepContext {
  const kernels::KernelSet* kernels = nullptr;
  int max_threads = 1;
  // Automatic threads (settings.threads = 0): the cores other processes leave free, sampled every
  // half second for the whole process (core/load.hpp, watch_load in step.cpp); 0: not known.
  LoadWatch* load = &process_load();
  int load_limit = 0;

  std::vector<double> pair_block_slip;
  std::vector<double> bond_block_breaks;
  std::vector<double> bond_block_slip;
  std::vector<ParticleBlockResult> particle_blocks;
  // The group stages (stages/groups.cpp): the members moved every step (busy members of lazy
  // groups, all members of the others) in slots by group (group g: moved_start[g] to
  // moved_start[g + 1]) and member order, their slots by particle block (split_idle); per group
  // its motion in this step, per slot the member's kinetic energy, squared displacement since
  // the last build and whether its new position is finite.
  std::vector<std::int32_t> moved_particle;
  std::vector<std::size_t> moved_start;
  Incidence block_moved;
  std::vector<GroupStep> group_steps;
  std::vector<double> member_kinetic, member_disp2;
  std::vector<std::uint8_t> member_finite;
};

}  // namespace asperity::detail
