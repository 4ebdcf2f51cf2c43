// The pair loop shared by the scalar reference and the SIMD kernels: load a batch of pairs, apply
// the contact law, store the per-pair results. `Lanes` abstracts loading and storing (gather of
// particle columns by pair index, aligned loads of pair columns), `Rotation` whether angular
// velocities exist at all (a scene with rotation locked everywhere never reads them).
#pragma once
#include "kernels/a_side.hpp"
#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"

namespace asperity::kernels {

template <class Lanes, bool Rotation>
double pair_loop(const PairKernelArgs& k, std::size_t begin, std::size_t end) {
  using T = typename Lanes::Real;
  const LawParams<T> p{T(k.kn), T(k.ks), T(k.friction), T(k.dt)};
  T slip_sum(0.0);
  for (std::size_t i = begin; i < end; i += Lanes::size) {
    const auto ia = Lanes::index(k.a + i);
    const auto ib = Lanes::index(k.b + i);
    const ASide<Lanes> A(k.a + i, ia, k.columns);
    const T xa = A.gather(k.x), ya = A.gather(k.y), za = A.gather(k.z);
    const T xb = Lanes::gather(k.x, ib), yb = Lanes::gather(k.y, ib), zb = Lanes::gather(k.z, ib);
    const T ra = A.gather(k.radius), rb = Lanes::gather(k.radius, ib);
    T nx, ny, nz, U, la, lb;
    ball_ball_geometry(xa, ya, za, xb, yb, zb, ra, rb, nx, ny, nz, U, la, lb);

    const T vax = A.gather(k.vx), vay = A.gather(k.vy), vaz = A.gather(k.vz);
    const T vbx = Lanes::gather(k.vx, ib), vby = Lanes::gather(k.vy, ib), vbz = Lanes::gather(k.vz, ib);
    T wax(0.0), way(0.0), waz(0.0), wbx(0.0), wby(0.0), wbz(0.0);
    if constexpr (Rotation) {
      wax = A.gather(k.wx); way = A.gather(k.wy); waz = A.gather(k.wz);
      wbx = Lanes::gather(k.wx, ib); wby = Lanes::gather(k.wy, ib); wbz = Lanes::gather(k.wz, ib);
    }
    const T ox = Lanes::load(k.nx + i), oy = Lanes::load(k.ny + i), oz = Lanes::load(k.nz + i);
    T fx = Lanes::load(k.fsx + i), fy = Lanes::load(k.fsy + i), fz = Lanes::load(k.fsz + i);
    const T u0 = k.rest ? Lanes::load(k.rest + i) : T(0.0);
    T fn;
    slip_sum = slip_sum + contact_forces(nx, ny, nz, U, la, lb, vax, vay, vaz, wax, way, waz, vbx,
                                         vby, vbz, wbx, wby, wbz, ox, oy, oz, u0, fx, fy, fz, fn, p);
    // A pair that no longer touches forgets its rest overlap with its shear force.
    if (k.rest) Lanes::store(k.rest + i, select(U > T(0.0), u0, T(0.0)));
    Lanes::store(k.nx + i, nx); Lanes::store(k.ny + i, ny); Lanes::store(k.nz + i, nz);
    Lanes::store(k.fsx + i, fx); Lanes::store(k.fsy + i, fy); Lanes::store(k.fsz + i, fz);
    Lanes::store(k.fn + i, fn);
    Lanes::store(k.overlap + i, U);
    // For the gather (kernels/integrate.cpp), with the operations it would do per side: the
    // record fx fy fz U cx cy cz 0 of each pair (store/pairs.hpp).
    const T record[8] = {fn * nx + fx, fn * ny + fy, fn * nz + fz, U,
                         ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx, T(0.0)};
    Lanes::template store_records<8>(k.out + 8 * i, record);
  }
  return Lanes::sum(slip_sum);
}

}  // namespace asperity::kernels
