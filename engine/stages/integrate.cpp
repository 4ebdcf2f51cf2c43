// Stages `gather` and `integrate`, fused per block of kParticleBlock particles: the gather sums
// each particle's pair, bond and wall contributions in the fixed order of its incidence lists
// into fx..tz, then the integrate kernel advances the block with leapfrog and local damping
// (kernels/integrate_loop.hpp, SIMD; particles of rigid groups are moved by stages/groups.cpp).
// The block's forces are still in L1/L2 when the kernel reads them back.
//
// Per-pair results give force and torques without anything else (model.md 4):
//   on b: F = Fn n + Fs, torque (xc - xb) x F = -(Rb - U/2) n x Fs
//   on a: -F,            torque (xc - xa) x (-F) = -(Ra - U/2) n x Fs
// F and n x Fs (and a bond's beam moment) are computed by the SIMD pair and bond kernels, eight
// pairs at a time; here only the lever arm, which differs per side, is applied. A pair's numbers
// are one 64-byte record (store/pairs.hpp), a bond's a 96-byte one (store/bonds.hpp), which the
// gather kernels (gather_loop.hpp) read as 256-bit vectors; the wall and applied terms follow in
// scalar passes. The operations are those the scalar gather did (so the results are bitwise the
// same).
#include <cmath>

#include "stages/integrate.hpp"

namespace asperity::detail {

StageLoop integrate_stage(const IntegrateStageView& s) {
  ParticleStore& p = s.p;
  const PairStore& q = s.pairs;
  const Incidence& inc = s.incidence;
  const WallContacts& wc = s.wall_contacts;
  const BondStore& bq = s.bonds;
  const Incidence& binc = s.bond_incidence;
  const std::size_t n = p.n;
  const std::size_t blocks = (n + kParticleBlock - 1) / kParticleBlock;
  s.ctx.particle_blocks.assign(blocks, {});
  const Vec3 g = s.gravity;
  const bool applied = p.has_applied;
  const std::uint8_t* idle = s.idle.data();  // sized p.n by split_idle, which runs before, as are
                                             // block_free and block_busy
  // Blocks in which no particle spins take the kernel without rotation (below).
  const auto integrate = s.any_rotating ? s.ctx.kernels->integrate : s.ctx.kernels->integrate_norot;
  const auto integrate_norot = s.ctx.kernels->integrate_norot;
  const kernels::IntegrateArgs args{
      p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(),
      p.wx.data(), p.wy.data(), p.wz.data(), p.fx.data(), p.fy.data(), p.fz.data(),
      p.tx.data(), p.ty.data(), p.tz.data(), p.x0.data(), p.y0.data(), p.z0.data(),
      p.mass.data(), p.inv_mass.data(), p.inertia.data(), p.inv_inertia.data(), p.radius.data(),
      applied ? p.ax.data() : nullptr, applied ? p.ay.data() : nullptr,
      applied ? p.az.data() : nullptr, nullptr, nullptr,
      s.dt, s.local_damping, g.x, g.y, g.z};

  // The pair sums and the bond terms of a range of particles, in one pass (the kernel skips inert
  // and idle ones, as below).
  const auto gather_records = s.ctx.kernels->gather;
  kernels::GatherArgs pair_args{inc.start.data(), inc.entry.data(), q.out.data(),
                                p.radius.data(), p.inert.data(), idle, p.fx.data(),
                                p.fy.data(), p.fz.data(), p.tx.data(), p.ty.data(),
                                p.tz.data()};
  // Pair records the pair kernel flagged dead (zero forces) are skipped where it flagged them
  // this step (stages/pairs.cpp, GatherArgs::live).
  if (q.live_written) pair_args.live = q.live.data();
  kernels::GatherArgs bond_args = pair_args;
  bond_args.live = nullptr;
  bond_args.start = binc.start.data();
  bond_args.entry = binc.entry.data();
  bond_args.records = bq.out.data();
  bond_args.bond_record = s.bond_records;
  // Records past the caches are prefetched a few particles ahead, as the incidences reach their
  // lines out of order; records in cache are not (the prefetches would cost and hide nothing).
  pair_args.prefetch = records_past_caches(q.out);
  bond_args.prefetch = records_past_caches(bq.out);
  // The wall and applied terms, added in passes after them. Raw pointers captured by value: the
  // stores to the force columns cannot make the compiler reload them (a vector's data pointer
  // reached through a reference can look aliased).
  const std::int32_t* wstart = wc.start.data();
  const double *wnx = wc.nx.data(), *wny = wc.ny.data(), *wnz = wc.nz.data(), *wsx = wc.fsx.data(),
               *wsy = wc.fsy.data(), *wsz = wc.fsz.data(), *wfn = wc.fn.data(), *wu = wc.overlap.data();
  const double *radius = p.radius.data(), *ax = applied ? p.ax.data() : nullptr,
               *ay = applied ? p.ay.data() : nullptr, *az = applied ? p.az.data() : nullptr;
  double *Fx = p.fx.data(), *Fy = p.fy.data(), *Fz = p.fz.data(), *Tx = p.tx.data(), *Ty = p.ty.data(),
         *Tz = p.tz.data();
  const std::int32_t* wparticle = wc.particle.data();
  auto add_wall = [=](std::int32_t k) __attribute__((always_inline)) {
    // A candidate that does not touch holds zero forces (a plane's kernel selects them, a mesh
    // candidate is skipped or zeroed, stages/walls.cpp): adding them would change at most the
    // sign of a zero sum. A particle near a mould has ~40 candidates and touches one to three.
    if (!(wu[k] > 0)) return;
    const std::size_t i = std::size_t(wparticle[k]);
    const double nx = wnx[k], ny = wny[k], nz = wnz[k];
    const double sx = wsx[k], sy = wsy[k], sz = wsz[k], fn = wfn[k];
    Fx[i] += fn * nx + sx;
    Fy[i] += fn * ny + sy;
    Fz[i] += fn * nz + sz;
    const double lever = radius[i] - 0.5 * wu[k];
    Tx[i] -= lever * (ny * sz - nz * sy);
    Ty[i] -= lever * (nz * sx - nx * sz);
    Tz[i] -= lever * (nx * sy - ny * sx);
  };
  auto add_applied = [=](std::size_t i) __attribute__((always_inline)) {
    Fx[i] += ax[i];
    Fy[i] += ay[i];
    Fz[i] += az[i];
  };
  const bool any_bonds = bq.n > 0;
  // The whole gather of one particle (the pair kernel's part included). The lambdas keep copies
  // of the arguments (the stage outlives this function), so the bond list is named through them.
  auto gather = [=](std::size_t i) __attribute__((always_inline)) {
    gather_records(pair_args, any_bonds ? &bond_args : nullptr, i, i + 1);
    for (std::int32_t k = wstart[i]; k < wstart[i + 1]; ++k) add_wall(k);
    if (applied) add_applied(i);
  };

  const std::uint8_t* inert = p.inert.data();
  const std::int32_t* group = p.group.data();
  const std::uint8_t* locked = p.rotation_locked.data();
  // The spin left in particles first..end (Caches::spin_known), read while their lines are at hand.
  // Where the last step's answer holds (spin_known), only blocks the kernel with rotation
  // integrated can add to it: the kernel without rotation and the gather write no w, the group
  // stages give members their group's (bookkeep adds it). Once something spins the answer cannot
  // change until it is cleared, so nothing is read then (the lattice, where both say so).
  const ParticleStore* const ps = &p;
  const std::uint8_t* bond_held = s.bond_held.size() >= n && bq.n > 0 ? s.bond_held.data() : nullptr;
  const bool full = !s.spin_known;  // bookkeep starts the answer afresh then
  const bool track =
      s.any_rotating && (full || s.spin_reachable == 0 || (bq.n > 0 && s.spin_bonded == 0));
  auto spin_of = [=](std::size_t first, std::size_t end, ParticleBlockResult& r) {
    // Branch-free (all-ones masks), so that the loops vectorise.
    auto bits = [=](std::size_t i) { return ps->spin_bits(i); };
    auto is_inert = [=](std::size_t i) { return std::uint64_t(0) - std::uint64_t(inert[i] != 0); };
    std::uint64_t reachable = 0, bonded = 0;
    if (bond_held) {
      for (std::size_t i = first; i < end; ++i) {
        const std::uint64_t b = bits(i);
        reachable |= b & ~is_inert(i);
        bonded |= b & (std::uint64_t(0) - std::uint64_t(bond_held[i] != 0));
      }
    } else {
      for (std::size_t i = first; i < end; ++i) reachable |= bits(i) & ~is_inert(i);
    }
    r.spin_reachable = reachable;
    r.spin_bonded = bonded;
  };
  StageLoop st;
  st.blocks = blocks;
  st.after_barrier = true;  // the forces of every stage before it are needed
  st.run = [=](std::size_t blk) {
    ParticleBlockResult r;
    if (!s.block_free[blk]) {
      // Rigid-group members only: their forces feed the group sums; nothing to integrate, and
      // only the busy members (split_idle) have any.
      for (std::int32_t e = s.block_busy.start[blk]; e < s.block_busy.start[blk + 1]; ++e)
        gather(std::size_t(s.block_busy.entry[e]));
      if (track && full) spin_of(blk * kParticleBlock, std::min(n, (blk + 1) * kParticleBlock), r);
      s.ctx.particle_blocks[blk] = r;
      return;
    }
    const std::size_t first = blk * kParticleBlock;
    const std::size_t end = std::min(n, first + kParticleBlock);
    // 0/1 masks for the integrate kernel, written for every particle of the block and zeroed over
    // the padding lanes beyond n (zero-initialising both would write 8 kB per block per step).
    alignas(64) double free[kParticleBlock], spin[kParticleBlock];
    kernels::IntegrateArgs a = args;
    a.free = free;
    a.spin = spin;
    // The gather in passes over the block, each particle's terms in the order pairs, bonds,
    // walls, applied (as `gather`): inert and idle particles have none and are skipped.
    gather_records(pair_args, any_bonds ? &bond_args : nullptr, first, end);
    for (std::int32_t k = wstart[first]; k < wstart[end]; ++k)
      if (!inert[wparticle[k]] && !idle[wparticle[k]]) add_wall(k);
    if (applied)
      for (std::size_t i = first; i < end; ++i)
        if (!inert[i] && !idle[i]) add_applied(i);
    int spins = 0;
    for (std::size_t i = first; i < end; ++i) {
      // Only free particles are integrated: inert and idle ones move lazily with their group,
      // other members with it (stages/groups.cpp). Without branches (`&`, not `&&`): in a joint
      // the flags vary from particle to particle, and branches on them would be mispredicted.
      const int moves = int(inert[i] == 0) & int(idle[i] == 0) & int(group[i] < 0);
      const int turns = moves & int(locked[i] == 0);
      free[i - first] = double(moves);
      spin[i - first] = double(turns);
      spins |= turns;
    }
    for (std::size_t i = end; i < round_up(end, kMaxLanes); ++i) free[i - first] = spin[i - first] = 0;
    kernels::IntegrateSums sums;
    // Where no particle of the block may turn (a bonded specimen: model.md 5 locks bonded
    // particles), the kernel with rotation would only write w back unchanged and add exact zeros
    // to the kinetic energy and damping work; the one without gives the same bits, without the
    // torque, spin and inertia columns (the test IntegrateWithoutSpinIsTheFullKernelWhereNothingTurns).
    (spins ? integrate : integrate_norot)(a, first, round_up(end, kMaxLanes), sums);
    r.damping = sums.damping;
    r.gravity = sums.gravity;
    r.applied = sums.applied;
    r.kinetic = sums.kinetic;
    r.max_disp2 = sums.max_disp2;
    r.worst_step = sums.worst_step;
    r.worst = std::int32_t(sums.worst);
    if (track && (full || spins)) spin_of(first, end, r);
    s.ctx.particle_blocks[blk] = r;
  };
  return st;
}

}  // namespace asperity::detail
