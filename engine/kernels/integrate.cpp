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
// F and n x Fs (and a bond's beam moment) are computed by the SIMD pair and bond kernels, eight
// pairs at a time; here only the lever arm, which differs per side, is applied. The operations
// are those this loop did itself before (so the results are bitwise the same), but the scalar
// gather reads 7 numbers per pair incidence instead of 8, and 10 per bond incidence instead of
// 16, and does a third of the arithmetic.
#include <cmath>

#include "state.hpp"

namespace asperity::detail {

namespace {
// What the gather reads of the pair or the bond list: the incidence of each particle, the
// kernels' force on b and n x Fs, the overlap for the lever arm, and for bonds the beam moment.
// Raw pointers held by value: the stores to the force columns cannot make the compiler reload
// them (a vector's data pointer reached through a reference can look aliased).
struct GatherColumns {
  const std::int32_t* start;
  const std::int64_t* entry;  // (index << 1) | (particle is b)
  const double *fx, *fy, *fz, *cx, *cy, *cz, *overlap;
  const double *mx = nullptr, *my = nullptr, *mz = nullptr;  // bonds only
};

// Adds particle i's contributions from one list to (f, t), in the fixed order of its incidence.
template <bool Moment>
inline __attribute__((always_inline)) void add_incidences(const GatherColumns& c, std::size_t i,
                                                          double R, double& fx, double& fy,
                                                          double& fz, double& tx, double& ty,
                                                          double& tz) {
  for (std::int32_t e = c.start[i]; e < c.start[i + 1]; ++e) {
    const std::int64_t k = c.entry[e] >> 1;
    const double sgn = (c.entry[e] & 1) ? 1.0 : -1.0;
    fx += sgn * c.fx[k];
    fy += sgn * c.fy[k];
    fz += sgn * c.fz[k];
    const double lever = R - 0.5 * c.overlap[k];
    if constexpr (Moment) {  // the beam's moment acts on b, its negative on a
      tx += sgn * c.mx[k] - lever * c.cx[k];
      ty += sgn * c.my[k] - lever * c.cy[k];
      tz += sgn * c.mz[k] - lever * c.cz[k];
    } else {
      tx -= lever * c.cx[k];
      ty -= lever * c.cy[k];
      tz -= lever * c.cz[k];
    }
  }
}
}  // namespace

StageLoop integrate_stage(State& s) {
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
  // Raw pointers captured by value (see GatherColumns).
  const GatherColumns pairs{inc.start.data(), inc.entry.data(), q.fx.data(), q.fy.data(),
                            q.fz.data(), q.cx.data(), q.cy.data(), q.cz.data(), q.overlap.data()};
  const GatherColumns bonds{binc.start.data(), binc.entry.data(), bq.fx.data(), bq.fy.data(),
                            bq.fz.data(), bq.cx.data(), bq.cy.data(), bq.cz.data(),
                            bq.overlap.data(), bq.mx.data(), bq.my.data(), bq.mz.data()};
  const std::int32_t* wstart = wc.start.data();
  const double *wnx = wc.nx.data(), *wny = wc.ny.data(), *wnz = wc.nz.data(), *wsx = wc.fsx.data(),
               *wsy = wc.fsy.data(), *wsz = wc.fsz.data(), *wfn = wc.fn.data(), *wu = wc.overlap.data();
  const double *radius = p.radius.data(), *ax = applied ? p.ax.data() : nullptr,
               *ay = applied ? p.ay.data() : nullptr, *az = applied ? p.az.data() : nullptr;
  double *Fx = p.fx.data(), *Fy = p.fy.data(), *Fz = p.fz.data(), *Tx = p.tx.data(), *Ty = p.ty.data(),
         *Tz = p.tz.data();
  auto gather = [=](std::size_t i) __attribute__((always_inline)) {  // two call sites: keep it inline
    double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
    const double R = radius[i];
    add_incidences<false>(pairs, i, R, fx, fy, fz, tx, ty, tz);
    add_incidences<true>(bonds, i, R, fx, fy, fz, tx, ty, tz);  // contact + parallel bond
    for (std::int32_t k = wstart[i]; k < wstart[i + 1]; ++k) {
      const double nx = wnx[k], ny = wny[k], nz = wnz[k];
      const double sx = wsx[k], sy = wsy[k], sz = wsz[k], fn = wfn[k];
      fx += fn * nx + sx;
      fy += fn * ny + sy;
      fz += fn * nz + sz;
      const double lever = R - 0.5 * wu[k];
      tx -= lever * (ny * sz - nz * sy);
      ty -= lever * (nz * sx - nx * sz);
      tz -= lever * (nx * sy - ny * sx);
    }
    if (applied) {
      fx += ax[i];
      fy += ay[i];
      fz += az[i];
    }
    Fx[i] = fx; Fy[i] = fy; Fz[i] = fz;
    Tx[i] = tx; Ty[i] = ty; Tz[i] = tz;
  };

  const std::uint8_t* inert = p.inert.data();
  const std::int32_t* group = p.group.data();
  const std::uint8_t* locked = p.rotation_locked.data();
  StageLoop st;
  st.blocks = blocks;
  st.after_barrier = true;  // the forces of every stage before it are needed
  st.run = [=, &s](std::size_t blk) {
    ParticleBlockResult r;
    if (!s.block_free[blk]) {
      // Rigid-group members only: their forces feed the group sums; nothing to integrate, and
      // only the busy members (split_idle) have any.
      for (std::int32_t e = s.block_busy.start[blk]; e < s.block_busy.start[blk + 1]; ++e)
        gather(std::size_t(s.block_busy.entry[e]));
      s.particle_blocks[blk] = r;
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
    for (std::size_t i = first; i < end; ++i) {
      if (inert[i] || idle[i]) {  // no contacts, moved lazily with its group
        free[i - first] = spin[i - first] = 0;
        continue;
      }
      gather(i);
      free[i - first] = group[i] < 0 ? 1.0 : 0.0;  // else: moved with its group
      spin[i - first] = (group[i] < 0 && !locked[i]) ? 1.0 : 0.0;
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
  };
  return st;
}

void gather_and_integrate(State& s) {
  StageLoop st = integrate_stage(s);
  run_stages(s, {&st});
}

}  // namespace asperity::detail
