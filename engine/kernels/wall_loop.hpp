// The plane wall loop shared by the scalar reference and the SIMD kernels: per contact, the
// plane's geometry [3-10, 3-11 with a plane for body a] and the contact law of model.md 4 with
// the plane as body a (velocity of the plane, no spin, lever arm 0 on its side). The scalar
// reference and every SIMD set run this one loop, so their results are the same bit for bit; a
// contact that does not touch gets no force and forgets its shear history.
#pragma once
#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"

namespace asperity::kernels {

template <class Lanes, bool Rotation>
void plane_wall_loop(const PlaneWallArgs& k, std::size_t begin, std::size_t end) {
  using T = typename Lanes::Real;
  for (std::size_t i = begin; i + Lanes::size <= end; i += Lanes::size) {
    const auto ip = Lanes::index32(k.particle + i);
    const auto iw = Lanes::index32(k.wall + i);
    const T x = Lanes::gather(k.x, ip), y = Lanes::gather(k.y, ip), z = Lanes::gather(k.z, ip);
    const T r = Lanes::gather(k.radius, ip);
    const T nx = Lanes::lookup(k.pnx, iw, k.walls), ny = Lanes::lookup(k.pny, iw, k.walls),
            nz = Lanes::lookup(k.pnz, iw, k.walls);
    // Signed distance of the centre from the plane, along its normal.
    const T d = (x - Lanes::lookup(k.px, iw, k.walls)) * nx +
                (y - Lanes::lookup(k.py, iw, k.walls)) * ny +
                (z - Lanes::lookup(k.pz, iw, k.walls)) * nz;
    const T U = r - d;
    const T lb = r - 0.5 * U;
    const T vbx = Lanes::gather(k.vx, ip), vby = Lanes::gather(k.vy, ip), vbz = Lanes::gather(k.vz, ip);
    T wbx(0.0), wby(0.0), wbz(0.0);
    if constexpr (Rotation) {
      wbx = Lanes::gather(k.wx, ip); wby = Lanes::gather(k.wy, ip); wbz = Lanes::gather(k.wz, ip);
    }
    const T vax = Lanes::lookup(k.pvx, iw, k.walls), vay = Lanes::lookup(k.pvy, iw, k.walls),
            vaz = Lanes::lookup(k.pvz, iw, k.walls);
    // A fresh contact (zero normal stored) starts from the current normal.
    T ox = Lanes::load_u(k.nx + i), oy = Lanes::load_u(k.ny + i), oz = Lanes::load_u(k.nz + i);
    const auto fresh = (ox * ox + oy * oy + oz * oz) == T(0.0);
    ox = select(fresh, nx, ox);
    oy = select(fresh, ny, oy);
    oz = select(fresh, nz, oz);
    T fx = Lanes::load_u(k.fsx + i), fy = Lanes::load_u(k.fsy + i), fz = Lanes::load_u(k.fsz + i), fn;
    const LawParams<T> law{Lanes::lookup(k.kn, iw, k.walls), Lanes::lookup(k.ks, iw, k.walls),
                           Lanes::lookup(k.friction, iw, k.walls), T(k.dt)};
    const T zero(0.0);
    // Without rotation both sides have w = +0: the law without spin (contact_law.hpp).
    const T slip = contact_forces<T, Rotation>(nx, ny, nz, U, zero, lb, vax, vay, vaz, zero, zero,
                                               zero, vbx, vby, vbz, wbx, wby, wbz, ox, oy, oz, zero,
                                               fx, fy, fz, fn, law);
    Lanes::store_u(k.nx + i, nx); Lanes::store_u(k.ny + i, ny); Lanes::store_u(k.nz + i, nz);
    Lanes::store_u(k.fsx + i, fx); Lanes::store_u(k.fsy + i, fy); Lanes::store_u(k.fsz + i, fz);
    Lanes::store_u(k.fn + i, fn);
    Lanes::store_u(k.overlap + i, U);
    Lanes::store_u(k.slip + i, slip);
  }
}

}  // namespace asperity::kernels
