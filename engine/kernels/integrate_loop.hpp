// Stage `integrate` (model.md 2): leapfrog with Cundall's local damping [3-5..3-7, 3-28, 3-29],
// written once for the scalar reference and the SIMD kernels (see pair_loop.hpp). It advances
// the particles [begin, end) whose force and torque the gather has just summed into fx..tz.
//
// Per particle two 0/1 masks (block-local arrays, index i - begin) say what to do: `free` (not in
// a rigid group, not inert: integrate it) and `spin` (free and rotation unlocked). Lanes that are
// not free are computed and thrown away by select, so their columns are written back unchanged.
//
// One degree of freedom:
//   unbalanced = F + m a                      (gravity included: model.md 2, a body resting on a
//                                              floor carries -m g from its contacts and must not
//                                              be damped; steady motion under zero net force is
//                                              not damped either)
//   Fd = -alpha |unbalanced| sign(v)           [3-28]
//   v' = v + (F + Fd) / m dt + a dt,  x' = x + v' dt
// The damping work is counted with the mean of the old and new velocities, which makes the change
// of kinetic energy over a step equal the work of its forces.
#pragma once
#include <cmath>

#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"

namespace asperity::kernels {

// Not `x != x`: xsimd compares with ordered predicates, for which NaN != NaN is false.
using std::isnan;

template <class T>
inline T sign_of(const T& v) {
  return select(v > T(0.0), T(1.0), select(v < T(0.0), T(-1.0), T(0.0)));
}

// Returns the new velocity; adds the damping work (>= 0 when dissipating) to `damping`.
template <class T>
inline T advance_dof(const T& v, const T& f, const T& unbalanced, const T& inv_m, const T& accel,
                     const T& alpha, const T& dt, T& damping) {
  const T fd = -alpha * abs(unbalanced) * sign_of(v);
  const T vn = v + (f + fd) * inv_m * dt + accel * dt;
  damping = damping - fd * (0.5 * (v + vn)) * dt;
  return vn;
}

template <class Lanes, bool Rotation>
void integrate_loop(const IntegrateArgs& k, std::size_t begin, std::size_t end, IntegrateSums& out) {
  using T = typename Lanes::Real;
  const T dt(k.dt), alpha(k.alpha), gx(k.gx), gy(k.gy), gz(k.gz), zero(0.0);
  const bool applied = k.ax != nullptr;
  T damping(0.0), gravity(0.0), work(0.0), kinetic(0.0), max_d2(0.0), worst(0.0), worst_i(-1.0);
  T index = Lanes::iota(double(begin));
  for (std::size_t i = begin; i < end; i += Lanes::size, index = index + T(double(Lanes::size))) {
    const auto free = Lanes::load(k.free + (i - begin)) != zero;
    const T m = Lanes::load(k.mass + i), im = Lanes::load(k.inv_mass + i);
    const T fx = Lanes::load(k.fx + i), fy = Lanes::load(k.fy + i), fz = Lanes::load(k.fz + i);
    const T vx = Lanes::load(k.vx + i), vy = Lanes::load(k.vy + i), vz = Lanes::load(k.vz + i);
    T dmp(0.0);
    const T nvx = advance_dof(vx, fx, fx + m * gx, im, gx, alpha, dt, dmp);
    const T nvy = advance_dof(vy, fy, fy + m * gy, im, gy, alpha, dt, dmp);
    const T nvz = advance_dof(vz, fz, fz + m * gz, im, gz, alpha, dt, dmp);
    const T mvx = 0.5 * (vx + nvx), mvy = 0.5 * (vy + nvy), mvz = 0.5 * (vz + nvz);
    T grav = m * (gx * mvx + gy * mvy + gz * mvz) * dt;
    T wrk(0.0);
    if (applied)
      wrk = (Lanes::load(k.ax + i) * mvx + Lanes::load(k.ay + i) * mvy + Lanes::load(k.az + i) * mvz) * dt;
    const T x = Lanes::load(k.x + i) + nvx * dt, y = Lanes::load(k.y + i) + nvy * dt,
            z = Lanes::load(k.z + i) + nvz * dt;
    Lanes::store(k.vx + i, select(free, nvx, vx));
    Lanes::store(k.vy + i, select(free, nvy, vy));
    Lanes::store(k.vz + i, select(free, nvz, vz));
    Lanes::store(k.x + i, select(free, x, Lanes::load(k.x + i)));
    Lanes::store(k.y + i, select(free, y, Lanes::load(k.y + i)));
    Lanes::store(k.z + i, select(free, z, Lanes::load(k.z + i)));
    T kin = m * (mvx * mvx + mvy * mvy + mvz * mvz);
    T turn(0.0);
    if constexpr (Rotation) {
      const auto spin = Lanes::load(k.spin + (i - begin)) != zero;
      const T ii = Lanes::load(k.inv_inertia + i);
      const T tx = Lanes::load(k.tx + i), ty = Lanes::load(k.ty + i), tz = Lanes::load(k.tz + i);
      const T wx = Lanes::load(k.wx + i), wy = Lanes::load(k.wy + i), wz = Lanes::load(k.wz + i);
      T rdmp(0.0);
      const T nwx = advance_dof(wx, tx, tx, ii, zero, alpha, dt, rdmp);
      const T nwy = advance_dof(wy, ty, ty, ii, zero, alpha, dt, rdmp);
      const T nwz = advance_dof(wz, tz, tz, ii, zero, alpha, dt, rdmp);
      const T mwx = 0.5 * (wx + nwx), mwy = 0.5 * (wy + nwy), mwz = 0.5 * (wz + nwz);
      Lanes::store(k.wx + i, select(spin, nwx, wx));
      Lanes::store(k.wy + i, select(spin, nwy, wy));
      Lanes::store(k.wz + i, select(spin, nwz, wz));
      kin = kin + select(spin, Lanes::load(k.inertia + i) * (mwx * mwx + mwy * mwy + mwz * mwz), zero);
      dmp = dmp + select(spin, rdmp, zero);
      turn = select(spin, sqrt(nwx * nwx + nwy * nwy + nwz * nwz) * dt / 0.1, zero);
    }
    damping = damping + select(free, dmp, zero);
    gravity = gravity + select(free, grav, zero);
    work = work + select(free, wrk, zero);
    kinetic = kinetic + select(free, 0.5 * kin, zero);
    // Rebuild criterion and health check. NaN-safe comparisons: a non-finite value always wins
    // (and stays: a NaN in max_d2 is never replaced).
    const T dx = x - Lanes::load(k.x0 + i), dy = y - Lanes::load(k.y0 + i), dz = z - Lanes::load(k.z0 + i);
    const T d2 = dx * dx + dy * dy + dz * dz;
    max_d2 = select(free & !(d2 <= max_d2) & !isnan(max_d2), d2, max_d2);
    const T move = sqrt(nvx * nvx + nvy * nvy + nvz * nvz) * dt / Lanes::load(k.radius + i);
    const T stepr = select(move < turn, turn, move);
    const auto worse = free & !(stepr <= worst) & !((worst_i >= zero) & isnan(worst));
    worst = select(worse, stepr, worst);
    worst_i = select(worse, index, worst_i);
  }
  out.damping = Lanes::sum(damping);
  out.gravity = Lanes::sum(gravity);
  out.applied = Lanes::sum(work);
  out.kinetic = Lanes::sum(kinetic);
  // Largest over lanes (NaN wins); the worst step: a NaN first, else the largest, ties and NaNs
  // resolved to the lowest index, as a sequential scan finds them.
  out.max_disp2 = 0;
  out.worst_step = 0;
  out.worst = -1;
  for (std::size_t l = 0; l < Lanes::size; ++l) {
    const double d = Lanes::lane(max_d2, l);
    if (!(d <= out.max_disp2) && !std::isnan(out.max_disp2)) out.max_disp2 = d;
    const double w = Lanes::lane(worst, l), wi = Lanes::lane(worst_i, l);
    if (wi < 0) continue;
    const bool cur_nan = out.worst >= 0 && std::isnan(out.worst_step);
    const bool better = std::isnan(w) ? (!cur_nan || wi < double(out.worst))
                                      : (!cur_nan && (w > out.worst_step ||
                                                      (w == out.worst_step && (out.worst < 0 || wi < double(out.worst)))));
    if (better || out.worst < 0) {
      out.worst_step = w;
      out.worst = std::int64_t(wi);
    }
  }
}

}  // namespace asperity::kernels
