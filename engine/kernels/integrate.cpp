// Stages `gather` and `integrate`, fused: for each particle, sum its pair and wall contributions
// in the fixed order of its incidence list, then (unless it belongs to a rigid group, which
// bodies/groups.cpp moves) advance it with leapfrog and local damping [3-5..3-7, 3-28, 3-29].
// Fusing saves writing the force and reading it back; the force is still stored for the API.
//
// Per-pair results give force and torques without anything else (model.md 4):
//   on b: F = Fn n + Fs, torque (xc - xb) x F = -(Rb - U/2) n x Fs
//   on a: -F,            torque (xc - xa) x (-F) = -(Ra - U/2) n x Fs
#include <cmath>

#include "state.hpp"

namespace asperity::detail {

namespace {
inline double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// One degree of freedom of leapfrog with local damping. Returns the new velocity; adds the work
// of the damping force (>= 0 when dissipating) using the mean of the old and new velocities,
// which is what makes the kinetic-energy change of a step equal the work of its forces.
//
// The damping force is proportional to the unbalanced force, gravity included [3-28, model.md 2:
// "steady motion under zero net force is not damped"]: a particle resting on a floor carries
// F = -m g from its contacts and must feel no damping. Damping |F| without gravity would push it
// up and down by alpha g dt every step, and a pile would never reach equilibrium.
inline double advance(double v, double f, double inv_m, double accel, double alpha, double dt,
                      double& damping_work) {
  const double unbalanced = f + accel / inv_m;
  const double fd = -alpha * std::fabs(unbalanced) * sign(v);  // [3-28]: opposes the motion
  const double vn = v + (f + fd) * inv_m * dt + accel * dt;
  damping_work -= fd * 0.5 * (v + vn) * dt;
  return vn;
}
}  // namespace

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
  const double dt = s.dt, alpha = s.settings.local_damping;
  const Vec3 g = s.settings.gravity;
  const bool rotation = s.any_rotating, applied = p.has_applied;

#pragma omp parallel for schedule(static) num_threads(thread_count(s))
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    ParticleBlockResult r;
    const std::size_t end = std::min(n, (blk + 1) * kParticleBlock);
    for (std::size_t i = blk * kParticleBlock; i < end; ++i) {
      if (p.inert[i]) continue;  // no contacts, moved lazily with its group
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
      if (p.group[i] >= 0) continue;  // moved with its group

      const double im = p.inv_mass[i], m = p.mass[i];
      const double vx = p.vx[i], vy = p.vy[i], vz = p.vz[i];
      const double nvx = advance(vx, fx, im, g.x, alpha, dt, r.damping);
      const double nvy = advance(vy, fy, im, g.y, alpha, dt, r.damping);
      const double nvz = advance(vz, fz, im, g.z, alpha, dt, r.damping);
      const double mvx = 0.5 * (vx + nvx), mvy = 0.5 * (vy + nvy), mvz = 0.5 * (vz + nvz);
      r.gravity += m * (g.x * mvx + g.y * mvy + g.z * mvz) * dt;
      if (applied) r.applied += (p.ax[i] * mvx + p.ay[i] * mvy + p.az[i] * mvz) * dt;
      p.vx[i] = nvx; p.vy[i] = nvy; p.vz[i] = nvz;
      p.x[i] += nvx * dt;
      p.y[i] += nvy * dt;
      p.z[i] += nvz * dt;
      double kin = m * (mvx * mvx + mvy * mvy + mvz * mvz);
      double spin = 0;
      if (rotation && !p.rotation_locked[i]) {
        const double ii = p.inv_inertia[i];
        const double wx = advance(p.wx[i], tx, ii, 0.0, alpha, dt, r.damping);
        const double wy = advance(p.wy[i], ty, ii, 0.0, alpha, dt, r.damping);
        const double wz = advance(p.wz[i], tz, ii, 0.0, alpha, dt, r.damping);
        const double mwx = 0.5 * (p.wx[i] + wx), mwy = 0.5 * (p.wy[i] + wy), mwz = 0.5 * (p.wz[i] + wz);
        p.wx[i] = wx; p.wy[i] = wy; p.wz[i] = wz;
        kin += p.inertia[i] * (mwx * mwx + mwy * mwy + mwz * mwz);
        spin = std::sqrt(wx * wx + wy * wy + wz * wz) * dt / 0.1;
      }
      r.kinetic += 0.5 * kin;
      const double dx = p.x[i] - p.x0[i], dy = p.y[i] - p.y0[i], dz = p.z[i] - p.z0[i];
      const double d2 = dx * dx + dy * dy + dz * dz;
      // NaN-safe comparisons: a non-finite value always becomes the block's worst.
      if (!(d2 <= r.max_disp2)) r.max_disp2 = d2;
      const double stepr = std::max(std::sqrt(nvx * nvx + nvy * nvy + nvz * nvz) * dt / R, spin);
      if (!(stepr <= r.worst_step) && !(r.worst >= 0 && std::isnan(r.worst_step))) {
        r.worst_step = stepr;
        r.worst = std::int32_t(i);
      }
    }
    s.particle_blocks[blk] = r;
  }
}

}  // namespace asperity::detail
