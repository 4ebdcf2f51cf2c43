// Stages `gather` and `integrate`, fused per block of kParticleBlock particles: the gather sums
// each particle's pair, bond and wall contributions in the fixed order of its incidence lists
// into fx..tz (scalar: the incidence lists are irregular), then the integrate kernel advances the
// block with leapfrog and local damping (kernels/integrate_loop.hpp, SIMD; particles of rigid
// groups are moved by bodies/groups.cpp). The block's forces are still in L1/L2 when the kernel
// reads them back.
//
// Per-pair results give force and torques without anything else (model.md 4):
//   on b: F = Fn n + Fs, torque (xc - xb) x F = -(Rb - U/2) n x Fs
//   on a: -F,            torque (xc - xa) x (-F) = -(Ra - U/2) n x Fs
#include <cmath>

#include "state.hpp"

namespace asperity::detail {

void gather_and_integrate(State& s) {
  ParticleStore& p = s.p;
  const PairStore& q = s.pairs;
  const Incidence& inc = s.incidence;
  const WallContacts& wc = s.walls.contacts;
  const BondStore& bq = s.bonds;
  const Incidence& binc = s.bond_incidence;
  const std::size_t n = p.n;
  const std::size_t blocks = (n + kParticleBlock - 1) / kParticleBlock;
  s.particle_blocks.assign(blocks, {});
  const Vec3 g = s.settings.gravity;
  const bool applied = p.has_applied;
  const std::uint8_t* idle = s.idle.data();  // sized p.n by split_idle, which runs before, as are
                                             // block_free and block_busy
  const auto integrate = s.any_rotating ? s.kernels->integrate : s.kernels->integrate_norot;
  const kernels::IntegrateArgs args{
      p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(),
      p.wx.data(), p.wy.data(), p.wz.data(), p.fx.data(), p.fy.data(), p.fz.data(),
      p.tx.data(), p.ty.data(), p.tz.data(), p.x0.data(), p.y0.data(), p.z0.data(),
      p.mass.data(), p.inv_mass.data(), p.inertia.data(), p.inv_inertia.data(), p.radius.data(),
      applied ? p.ax.data() : nullptr, applied ? p.ay.data() : nullptr,
      applied ? p.az.data() : nullptr, nullptr, nullptr,
      s.dt, s.settings.local_damping, g.x, g.y, g.z};

  // One particle's pair, bond and wall contributions, in the fixed order of its incidence lists.
  auto gather = [&](std::size_t i) {
    double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
    const double R = p.radius[i];
    for (std::int32_t e = inc.start[i]; e < inc.start[i + 1]; ++e) {
      const std::int64_t k = inc.entry[e] >> 1;
      const double sgn = (inc.entry[e] & 1) ? 1.0 : -1.0;
      const double nx = q.nx[k], ny = q.ny[k], nz = q.nz[k];
      const double sx = q.fsx[k], sy = q.fsy[k], sz = q.fsz[k], fn = q.fn[k];
      fx += sgn * (fn * nx + sx);
      fy += sgn * (fn * ny + sy);
      fz += sgn * (fn * nz + sz);
      const double lever = R - 0.5 * q.overlap[k];
      tx -= lever * (ny * sz - nz * sy);
      ty -= lever * (nz * sx - nx * sz);
      tz -= lever * (nx * sy - ny * sx);
    }
    for (std::int32_t e = binc.start[i]; e < binc.start[i + 1]; ++e) {
      // Bond: contact bond + parallel bond forces, plus the beam's moments on b (-M on a).
      const std::int64_t k = binc.entry[e] >> 1;
      const double sgn = (binc.entry[e] & 1) ? 1.0 : -1.0;
      const double nx = bq.nx[k], ny = bq.ny[k], nz = bq.nz[k];
      const double sx = bq.fsx[k] + bq.fbsx[k], sy = bq.fsy[k] + bq.fbsy[k], sz = bq.fsz[k] + bq.fbsz[k];
      const double fn = bq.fn[k] + bq.fbn[k];
      fx += sgn * (fn * nx + sx);
      fy += sgn * (fn * ny + sy);
      fz += sgn * (fn * nz + sz);
      const double lever = R - 0.5 * bq.overlap[k];
      tx += sgn * (bq.mbn[k] * nx + bq.mbsx[k]) - lever * (ny * sz - nz * sy);
      ty += sgn * (bq.mbn[k] * ny + bq.mbsy[k]) - lever * (nz * sx - nx * sz);
      tz += sgn * (bq.mbn[k] * nz + bq.mbsz[k]) - lever * (nx * sy - ny * sx);
    }
    for (std::int32_t k = wc.start[i]; k < wc.start[i + 1]; ++k) {
      const double nx = wc.nx[k], ny = wc.ny[k], nz = wc.nz[k];
      const double sx = wc.fsx[k], sy = wc.fsy[k], sz = wc.fsz[k], fn = wc.fn[k];
      fx += fn * nx + sx;
      fy += fn * ny + sy;
      fz += fn * nz + sz;
      const double lever = R - 0.5 * wc.overlap[k];
      tx -= lever * (ny * sz - nz * sy);
      ty -= lever * (nz * sx - nx * sz);
      tz -= lever * (nx * sy - ny * sx);
    }
    if (applied) {
      fx += p.ax[i];
      fy += p.ay[i];
      fz += p.az[i];
    }
    p.fx[i] = fx; p.fy[i] = fy; p.fz[i] = fz;
    p.tx[i] = tx; p.ty[i] = ty; p.tz[i] = tz;
  };

#pragma omp parallel for schedule(static) num_threads(thread_count(s))
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    ParticleBlockResult r;
    if (!s.block_free[blk]) {
      // Rigid-group members only: their forces feed the group sums; nothing to integrate, and
      // only the busy members (split_idle) have any.
      for (std::int32_t e = s.block_busy.start[blk]; e < s.block_busy.start[blk + 1]; ++e)
        gather(std::size_t(s.block_busy.entry[e]));
      s.particle_blocks[blk] = r;
      continue;
    }
    const std::size_t first = blk * kParticleBlock;
    const std::size_t end = std::min(n, first + kParticleBlock);
    // 0/1 masks for the integrate kernel, written for every particle of the block and zeroed over
    // the padding lanes beyond n (not zero-initialised: 8 kB per block per step for a rigid body).
    alignas(64) double free[kParticleBlock], spin[kParticleBlock];
    kernels::IntegrateArgs a = args;
    a.free = free;
    a.spin = spin;
    for (std::size_t i = first; i < end; ++i) {
      if (p.inert[i] || idle[i]) {  // no contacts, moved lazily with its group
        free[i - first] = spin[i - first] = 0;
        continue;
      }
      gather(i);
      free[i - first] = p.group[i] < 0 ? 1.0 : 0.0;  // else: moved with its group
      spin[i - first] = (p.group[i] < 0 && !p.rotation_locked[i]) ? 1.0 : 0.0;
    }
    for (std::size_t i = end; i < round_up(end, kMaxLanes); ++i) free[i - first] = spin[i - first] = 0;
    kernels::IntegrateSums sums;
    integrate(a, first, round_up(end, kMaxLanes), sums);
    r.damping = sums.damping;
    r.gravity = sums.gravity;
    r.applied = sums.applied;
    r.kinetic = sums.kinetic;
    r.max_disp2 = sums.max_disp2;
    r.worst_step = sums.worst_step;
    r.worst = std::int32_t(sums.worst);
    s.particle_blocks[blk] = r;
  }
}

}  // namespace asperity::detail
