// Stage `bonds` (model.md 5): the bond kernel over fixed blocks of the bond list. The breaks it
// flags are processed after the step (bond_list.cpp, process_breaks).
#include <algorithm>

#include "stages/bonds.hpp"

namespace asperity::detail {

kernels::BondKernelArgs bond_kernel_args(const BondStageView& s) {
  const ParticleStore& p = s.p;
  BondStore& q = s.bonds;
  const ContactMaterial& m = s.contact;
  const BondMaterial& bm = q.material;
  return {p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(),
          p.wx.data(), p.wy.data(), p.wz.data(), p.radius.data(), q.a.data(), q.b.data(),
          q.beam_radius.data(), q.nx.data(), q.ny.data(), q.nz.data(), q.fsx.data(),
          q.fsy.data(), q.fsz.data(), q.fn.data(), q.overlap.data(), q.fbn.data(), q.fbsx.data(),
          q.fbsy.data(), q.fbsz.data(), q.mbn.data(), q.mbsx.data(), q.mbsy.data(),
          q.mbsz.data(), q.broken.data(), q.out.data(), m.kn, m.ks,
          bm.beam_kn, bm.beam_ks, s.dt, bm.breakable ? bm.tensile_strength : 0.0, p.capacity,
          s.rest_overlaps ? q.rest.data() : nullptr, s.bonds_partial ? q.holds.data() : nullptr,
          m.friction, bm.contact_strength, bm.contact_shear_strength, bm.contact_bond_friction};
}

StageLoop bond_stage(const BondStageView& s) {
  StageLoop st;
  if (s.bonds.n == 0) return st;
  const auto args = bond_kernel_args(s);
  // A bonded particle does not rotate (model.md 5: its rotation is locked), so its angular
  // velocity is +0 unless a rotating rigid group carries it (or bonded rotation was unlocked).
  // Then the kernel that takes w = +0 without reading it gives the same values (-0 counts as
  // spinning: its sign could reach a result; the law without spin differs from the full one at
  // w = +0 only in the sign of an exact zero, bond_law.hpp). It skips six loads and every spin
  // term of the law, which a bonded specimen would otherwise pay at every step for zeros.
  bool spin = s.any_rotating;
  if (spin && s.spin_known) {
    // What the last step left for the particles holding a bond (Caches::spin_known).
    spin = s.spin_bonded != 0;
  } else if (spin) {
    const ParticleStore& p = s.p;
    spin = false;
    for (const std::int32_t i : s.bonded_particles)
      if (p.spin_bits(std::size_t(i))) {
        spin = true;
        break;
      }
  }
  // Without spin no moment grows: while every beam moment is zero (a bonded specimen whose
  // particles never turned: the joints) the kernel leaves the four moment columns alone and its
  // records carry no moment, memory traffic saved at every step. A step with spin may give them
  // values. Where besides no end of a bond turns (the thesis's rotation rule locks every bonded
  // particle; the joint's platens do not turn), nothing the records' torque terms would give
  // moves a particle: records of four, half the bond records' traffic.
  using kernels::BondRecord;
  const auto& ks = *s.ctx.kernels;
  const auto kernel = spin ? ks.bond
                           : !s.moments_zero ? ks.bond_norot
                           : s.ends_turn     ? ks.bond_no_moment
                                             : ks.bond_forces;
  if (spin) s.moments_zero = false;
  s.records = kernel == ks.bond_forces      ? BondRecord::forces
              : kernel == ks.bond_no_moment ? BondRecord::levers
                                            : BondRecord::moments;
  // The zero record in this layout, for the dead bonds' entries (BondStore::zero_record).
  static constexpr double zero_record[kBondRecord] = {-0.0, -0.0, -0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.0, -0.0, -0.0, 0.0};
  const std::size_t width = std::size_t(s.records);
  std::copy_n(zero_record, width, s.bonds.out.data() + width * s.bonds.zero_record());
  const std::size_t total = s.bonds.padded;
  const std::size_t block = pair_block_size(total);
  st.blocks = (total + block - 1) / block;
  // The kernel writes a break flag only where a bond breaks: flags of a step whose breaks were
  // never processed (it stopped before process_breaks) are cleared, not carried into this one.
  for (const double b : s.ctx.bond_block_breaks)
    if (b != 0) {
      std::fill(s.bonds.broken.begin(), s.bonds.broken.end(), 0.0);
      break;
    }
  s.ctx.bond_block_breaks.assign(st.blocks, 0.0);
  s.ctx.bond_block_slip.assign(st.blocks, 0.0);
  double* breaks = s.ctx.bond_block_breaks.data();
  double* slip = s.ctx.bond_block_slip.data();
  st.run = [=](std::size_t blk) {
    const std::size_t begin = blk * block;
    const kernels::BondSums sums = kernel(args, begin, std::min(total, begin + block));
    breaks[blk] = sums.breaks;
    slip[blk] = sums.slip;
  };
  // The breaks are processed after the step (process_breaks); the slip of contact springs whose
  // contact bond broke is booked here, in block order.
  if (args.holds != nullptr && s.ledger)
    st.finish = [ledger = s.ledger, slip, blocks = st.blocks] {
      for (std::size_t blk = 0; blk < blocks; ++blk) ledger->friction += slip[blk];
    };
  return st;
}

}  // namespace asperity::detail
