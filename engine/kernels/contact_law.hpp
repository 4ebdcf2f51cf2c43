// The unbonded contact law of model.md section 4 [3-8..3-22], written once as templates on the
// number type: the scalar reference instantiates them with double, the SIMD kernels with
// xsimd::batch<double, Arch>. Every operation is the same in both (no transcendental functions,
// no fused multiply-add: the project compiles with -ffp-contract=off), so a SIMD lane reproduces
// the scalar result bit for bit.
//
// Branches are masks: a pair that does not touch computes everything and selects zero at the end.
#pragma once
#include <cmath>

namespace asperity::kernels {

// Scalar twins of the xsimd functions the templates call unqualified (found by ADL for batches).
inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
using std::sqrt;
using std::abs;

template <class T>
struct LawParams {
  T kn, ks, friction, dt;
};

// sin and cos of the small spin angle of one step, by their Taylor series through phi^10. For
// |phi| <= 0.1 rad the truncation error is below 3e-19; the health check stops a run in which a
// particle turns more than 0.1 rad in one step, which no resolved simulation does. A polynomial
// (instead of libm's sin/cos) is what lets the SIMD lanes equal the scalar path exactly.
template <class T>
inline void small_sincos(const T& phi, T& s, T& c) {
  const T p2 = phi * phi;
  c = 1.0 - p2 * (1.0 / 2) * (1.0 - p2 * (1.0 / 12) * (1.0 - p2 * (1.0 / 30) * (1.0 - p2 * (1.0 / 56) * (1.0 - p2 * (1.0 / 90)))));
  s = phi * (1.0 - p2 * (1.0 / 6) * (1.0 - p2 * (1.0 / 20) * (1.0 - p2 * (1.0 / 42) * (1.0 - p2 * (1.0 / 72)))));
}

// Carry the shear force with the contact plane [3-14..3-16]:
// (1) the rotation taking the old normal o onto the new normal n, applied to F:
//     R F = c F + s x F + (s.F) s / (1 + c),  c = o.n, s = o x n  (Rodrigues, unnormalised axis);
// (2) the rotation about n by the mean spin angle phi = 0.5 (wA + wB).n dt.
//
// Spin = false: both bodies have w = +0, so phi = +-0, sin = +-0, cos = 1, and step (2) returns its
// input (x * 1 + (+-0) + (+-0) = x for x != 0): it is skipped. Results can differ from Spin =
// true only in the sign of an exact zero, which no later operation turns into a nonzero value.
template <class T, bool Spin = true>
inline void carry_shear(const T& ox, const T& oy, const T& oz, const T& nx, const T& ny,
                        const T& nz, const T& phi, T& fx, T& fy, T& fz) {
  const T c = ox * nx + oy * ny + oz * nz;
  const T sx = oy * nz - oz * ny, sy = oz * nx - ox * nz, sz = ox * ny - oy * nx;
  const T sf = (sx * fx + sy * fy + sz * fz) / (1.0 + c);
  const T rx = c * fx + (sy * fz - sz * fy) + sf * sx;
  const T ry = c * fy + (sz * fx - sx * fz) + sf * sy;
  const T rz = c * fz + (sx * fy - sy * fx) + sf * sz;
  if constexpr (!Spin) {
    fx = rx;
    fy = ry;
    fz = rz;
    return;
  }
  T sn, cs;
  small_sincos(phi, sn, cs);
  const T nr = (nx * rx + ny * ry + nz * rz) * (1.0 - cs);
  fx = rx * cs + (ny * rz - nz * ry) * sn + nx * nr;
  fy = ry * cs + (nz * rx - nx * rz) * sn + ny * nr;
  fz = rz * cs + (nx * ry - ny * rx) * sn + nz * nr;
}

// Kinematics of one contact or bond whose geometry is known: normal n (from a to b), lever arms
// la = |xc - xa|, lb = |xc - xb| (xc - xa = la n, xc - xb = -lb n). Gives the normal and
// tangential relative velocity vn, Vs of b with respect to a at the contact point and the mean
// spin angle of the step about n, phi = 0.5 (wA + wB).n dt (contact_forces, bond_forces).
// Spin = false: w = +0 on both sides, whose terms are left out (see carry_shear).
template <class T, bool Spin = true>
inline void contact_kinematics(const T& nx, const T& ny, const T& nz, const T& la, const T& lb,
                               const T& vax, const T& vay, const T& vaz, const T& wax,
                               const T& way, const T& waz, const T& vbx, const T& vby,
                               const T& vbz, const T& wbx, const T& wby, const T& wbz,
                               const T& dt, T& vn, T& vsx, T& vsy, T& vsz, T& phi) {
  // Relative velocity of b with respect to a at the contact point [3-17, 3-18]:
  // V = (vB + wB x (xc - xB)) - (vA + wA x (xc - xA)) = vB - vA - lb (wB x n) - la (wA x n).
  T vx = vbx - vax, vy = vby - vay, vz = vbz - vaz;
  phi = T(0.0);
  if constexpr (Spin) {
    vx = vx - lb * (wby * nz - wbz * ny) - la * (way * nz - waz * ny);
    vy = vy - lb * (wbz * nx - wbx * nz) - la * (waz * nx - wax * nz);
    vz = vz - lb * (wbx * ny - wby * nx) - la * (wax * ny - way * nx);
    phi = 0.5 * dt * ((wax + wbx) * nx + (way + wby) * ny + (waz + wbz) * nz);
  }
  vn = vx * nx + vy * ny + vz * nz;
  vsx = vx - vn * nx;
  vsy = vy - vn * ny;
  vsz = vz - vn * nz;
}

// The ordinary contact's normal force, slip and loss of contact [3-12, 3-22, model.md 4], from
// the overlap U, the rest overlap U0 (the overlap of the unloaded spring: 0 in model.md 4; > 0
// for a contact left by a bond installed stress-free) and the trial shear force F (the carried
// history plus this step's increment), which it caps. Gives the normal force fn on b; returns
// the energy dissipated by slip. Also the contact springs of a bond whose contact bond broke.
template <class T>
inline T contact_cap(const T& U, const T& U0, T& fx, T& fy, T& fz, T& fn, const LawParams<T>& p) {
  const auto touching = U > T(0.0);
  // Normal force [3-12], no tension. With U0 = 0 this is kn U wherever U > 0, bit for bit; a
  // touching pair with 0 < U <= U0 carries no force (and so, by the slip cap, no shear force).
  fn = select(U > U0, p.kn * (U - U0), T(0.0));
  // Coulomb slip [3-22]: cap |Fs| at mu Fn; the energy dissipated is |Fs_cap| (|Fs_trial| -
  // |Fs_cap|) / ks (model.md 8).
  const T limit = p.friction * fn;
  const T fs2 = fx * fx + fy * fy + fz * fz;
  // The square root and two divisions only where some lane slips (same values: the selects
  // give 1 and 0 to the others).
  const auto slips = fs2 > limit * limit;
  T scale(1.0), slip_energy(0.0);
  if (any(slips)) {
    const T fs = sqrt(fs2);
    scale = select(slips, limit / fs, T(1.0));
    slip_energy = select(slips && touching, limit * (fs - limit) / p.ks, T(0.0));
  }
  // A contact that does not touch has no force and forgets its shear history [model.md 4].
  fx = select(touching, fx * scale, T(0.0));
  fy = select(touching, fy * scale, T(0.0));
  fz = select(touching, fz * scale, T(0.0));
  return slip_energy;
}

// Forces of one contact from its geometry (normal n, overlap U) and kinematics (Vs, phi:
// contact_kinematics), with rest overlap U0 (contact_cap). On entry (o, F) hold the normal and
// shear force of the previous step; on exit F is the new shear force on b and fn the normal
// force on b. Returns the energy dissipated by slip in this step.
template <class T, bool Spin = true>
inline T contact_response(const T& nx, const T& ny, const T& nz, const T& U, const T& vsx,
                          const T& vsy, const T& vsz, const T& phi, const T& ox, const T& oy,
                          const T& oz, const T& U0, T& fx, T& fy, T& fz, T& fn,
                          const LawParams<T>& p) {
  carry_shear<T, Spin>(ox, oy, oz, nx, ny, nz, phi, fx, fy, fz);
  // Incremental shear force [3-19..3-21]: dFs = -ks Vs dt.
  fx = fx - p.ks * vsx * p.dt;
  fy = fy - p.ks * vsy * p.dt;
  fz = fz - p.ks * vsz * p.dt;
  return contact_cap(U, U0, fx, fy, fz, fn, p);
}

// Both in one: the contact law of model.md 4 for a contact whose geometry is known (normal n,
// overlap U, lever arms la, lb), from the two bodies' velocities.
template <class T, bool Spin = true>
inline T contact_forces(const T& nx, const T& ny, const T& nz, const T& U, const T& la,
                        const T& lb, const T& vax, const T& vay, const T& vaz, const T& wax,
                        const T& way, const T& waz, const T& vbx, const T& vby, const T& vbz,
                        const T& wbx, const T& wby, const T& wbz, const T& ox, const T& oy,
                        const T& oz, const T& U0, T& fx, T& fy, T& fz, T& fn,
                        const LawParams<T>& p) {
  T vn, vsx, vsy, vsz, phi;
  contact_kinematics<T, Spin>(nx, ny, nz, la, lb, vax, vay, vaz, wax, way, waz, vbx, vby, vbz,
                              wbx, wby, wbz, p.dt, vn, vsx, vsy, vsz, phi);
  return contact_response<T, Spin>(nx, ny, nz, U, vsx, vsy, vsz, phi, ox, oy, oz, U0, fx, fy, fz,
                                   fn, p);
}

// Geometry of a ball-ball pair [3-10, 3-11].
template <class T>
inline void ball_ball_geometry(const T& xa, const T& ya, const T& za, const T& xb, const T& yb,
                               const T& zb, const T& ra, const T& rb, T& nx, T& ny, T& nz, T& U,
                               T& la, T& lb) {
  const T dx = xb - xa, dy = yb - ya, dz = zb - za;
  const T d = sqrt(dx * dx + dy * dy + dz * dz);
  const T inv = 1.0 / d;
  nx = dx * inv;
  ny = dy * inv;
  nz = dz * inv;
  U = (ra + rb) - d;
  la = ra - 0.5 * U;
  lb = rb - 0.5 * U;
}

// Strain energy of a contact's springs (model.md 8): Fn^2/(2 kn) + |Fs|^2/(2 ks), with fs2 = |Fs|^2.
// The one formula for touching pairs and wall contacts (step.cpp) and for a bond's contact springs
// (bond_law.hpp, bond_list.cpp).
inline double contact_spring_energy(double fn, double fs2, double kn, double ks) {
  return fn * fn / (2 * kn) + fs2 / (2 * ks);
}

}  // namespace asperity::kernels
