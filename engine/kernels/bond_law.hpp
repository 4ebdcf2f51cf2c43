// The bond law of model.md section 5 [3-23..3-27, 3-46..3-49], as a template on the number type
// (double for the scalar reference, xsimd batches for the SIMD kernels), like contact_law.hpp.
//
// While intact, a bond is a contact bond (the contact springs of section 4 acting in tension
// too, shear without slip) plus a parallel bond (an elastic beam of radius Rb whose force and
// moments grow incrementally from zero). With kbn A = beam_kn and kbs A = beam_ks:
//   dFbn = beam_kn (-(V.n)) dt                  dFbs = -beam_ks Vs dt
//   dMbn = -kbs J (wrel.n) dt = -beam_ks Rb^2/2 (wrel.n) dt
//   dMbs = -kbn I wrel_s dt   = -beam_kn Rb^2/4 wrel_s dt
// (J / A = Rb^2 / 2, I / A = Rb^2 / 4 [3-26]). Periphery stresses [3-27], tension positive:
//   sigma = -Fbn / A + |Mbs| Rb / I,   tau = |Fbs| / A + |Mbn| Rb / J.
// Elliptic criterion: ((sigma - h) / a)^2 + (tau / b)^2 >= 1, a = 5.5 st, h = -4.5 st,
// b = 5 st a / sqrt(a^2 - h^2): fails at sigma = st, sigma = -10 st, tau = 5 st.
#pragma once
#include <cmath>
#include <cstddef>

#include "asperity/materials.hpp"
#include "asperity/vec3.hpp"
#include "kernels/contact_law.hpp"

namespace asperity::kernels {

inline constexpr double kPi = 3.14159265358979323846;

template <class T>
struct BondParams {
  T kn, ks, beam_kn, beam_ks, dt;
  T strength;   // st; 0 or less: unbreakable
};

// The contact bond's failure (model.md 5, PFC's contact bond): its tensile normal force (fn < 0)
// reaches Fcn or its shear force Fcs (c st A both by default). Compression never breaks it. Per
// lane: 0 where it holds, else 1 where the tension reached Fcn, 2 where only the shear did.
template <class T>
inline T contact_bond_failure(const T& fn, const T& fsx, const T& fsy, const T& fsz, const T& fcn, const T& fcs) {
  const auto tension = fn <= -fcn;
  const auto shear = fsx * fsx + fsy * fsy + fsz * fsz >= fcs * fcs;
  return select(tension, T(1.0), select(shear, T(2.0), T(0.0)));
}

// The contact bond's shear strength factor: cs, or c where cs is 0 (BondMaterial).
inline double contact_shear_factor(double c, double cs) { return cs > 0 ? cs : c; }

// The contact bond's strengths (model.md 5) for a beam of radius rb: Fcn = c st A in tension,
// Fcs = cs st A in shear (cs = 0: c), plus mu_b Fn under compression where mu_b > 0 (PFC's
// Mohr-Coulomb contact bond). The bond kernel and the break events' modes (bond_list.cpp) both
// take them from here.
template <class T>
inline void contact_bond_strengths(const T& st, const T& rb, double c, double cs, double mu_b, const T& fn,
                                   T& fcn, T& fcs) {
  const T st_area = st * (kPi * rb * rb);  // st A
  fcn = T(c) * st_area;
  fcs = T(contact_shear_factor(c, cs)) * st_area;
  if (mu_b > 0) fcs = fcs + T(mu_b) * select(fn > T(0.0), fn, T(0.0));
}

// Criterion value ((sigma - h) / a)^2 + (tau / b)^2 for strength st (>= 1: the bond fails).
template <class T>
inline T elliptic_criterion(const T& sigma, const T& tau, const T& st) {
  const T a = 5.5 * st, h = -4.5 * st;
  const T b = 5.0 * st * a / sqrt(a * a - h * h);
  const T u = (sigma - h) / a, v = tau / b;
  return u * u + v * v;
}

// Everything one bond needs; in/out fields hold the history on entry and the new state on exit.
template <class T>
struct BondState {
  T fsx, fsy, fsz;        // contact bond shear
  T fn;                   // contact bond normal force (out)
  T fbn, fbsx, fbsy, fbsz;
  T mbn, mbsx, mbsy, mbsz;
};

// Returns the criterion value (>= 1: broken); sigma and tau are returned too. U0: the contact
// bond's rest overlap. Spin = false: both bodies have w = +0 (a bonded particle does not rotate,
// model.md 5), and every term of w is left out: it would add or rotate by an exact +-0, so the
// values are those of Spin = true except for the sign of an exact zero (carry_shear), in about
// half the multiplies and adds per batch.
// Moments = false (only with Spin = false): the beam carries no moment, mbn = mbs = +-0 on entry;
// without spin no increment reaches them and carrying a zero gives a zero, so they stay +-0 and
// are neither carried nor read (the caller leaves their columns alone). Their terms of the
// periphery stresses are exact zeros, added as +0: sigma and tau are the same bits.
template <class T, bool Spin = true, bool Moments = true>
inline T bond_forces(const T& nx, const T& ny, const T& nz, const T& U, const T& la, const T& lb,
                     const T& rb, const T& vax, const T& vay, const T& vaz, const T& wax,
                     const T& way, const T& waz, const T& vbx, const T& vby, const T& vbz,
                     const T& wbx, const T& wby, const T& wbz, const T& ox, const T& oy,
                     const T& oz, const T& U0, BondState<T>& s, T& sigma, T& tau,
                     const BondParams<T>& p) {
  static_assert(Moments || !Spin, "the moments grow wherever the bodies spin");
  // Relative velocity at the contact point [3-17, 3-18] and spin angle, as for a contact.
  T vn, vsx, vsy, vsz, phi;
  contact_kinematics<T, Spin>(nx, ny, nz, la, lb, vax, vay, vaz, wax, way, waz, vbx, vby, vbz, wbx,
                              wby, wbz, p.dt, vn, vsx, vsy, vsz, phi);
  // Shear force, beam shear force and bending moment are carried with the contact plane.
  carry_shear<T, Spin>(ox, oy, oz, nx, ny, nz, phi, s.fsx, s.fsy, s.fsz);
  carry_shear<T, Spin>(ox, oy, oz, nx, ny, nz, phi, s.fbsx, s.fbsy, s.fbsz);
  if constexpr (Moments) carry_shear<T, Spin>(ox, oy, oz, nx, ny, nz, phi, s.mbsx, s.mbsy, s.mbsz);

  // Contact bond: springs in tension too, no slip; unloaded at the rest overlap U0 (0 unless the
  // bond was installed stress-free).
  s.fn = p.kn * (U - U0);
  s.fsx = s.fsx - p.ks * vsx * p.dt;
  s.fsy = s.fsy - p.ks * vsy * p.dt;
  s.fsz = s.fsz - p.ks * vsz * p.dt;

  // Parallel bond increments (the moments' only with a relative rotation).
  const T r2 = rb * rb;
  s.fbn = s.fbn - p.beam_kn * vn * p.dt;
  s.fbsx = s.fbsx - p.beam_ks * vsx * p.dt;
  s.fbsy = s.fbsy - p.beam_ks * vsy * p.dt;
  s.fbsz = s.fbsz - p.beam_ks * vsz * p.dt;
  if constexpr (Spin) {
    const T rx = wbx - wax, ry = wby - way, rz = wbz - waz;
    const T rn = rx * nx + ry * ny + rz * nz;
    const T rsx = rx - rn * nx, rsy = ry - rn * ny, rsz = rz - rn * nz;
    s.mbn = s.mbn - p.beam_ks * (0.5 * r2) * rn * p.dt;
    const T kbend = p.beam_kn * (0.25 * r2);
    s.mbsx = s.mbsx - kbend * rsx * p.dt;
    s.mbsy = s.mbsy - kbend * rsy * p.dt;
    s.mbsz = s.mbsz - kbend * rsz * p.dt;
  }

  // Periphery stresses [3-27] with A = pi Rb^2, I = pi Rb^4 / 4, J = pi Rb^4 / 2.
  const T A = kPi * r2;
  const T fbs = sqrt(s.fbsx * s.fbsx + s.fbsy * s.fbsy + s.fbsz * s.fbsz);
  if constexpr (Moments) {
    const T mbs = sqrt(s.mbsx * s.mbsx + s.mbsy * s.mbsy + s.mbsz * s.mbsz);
    const T mbn = select(s.mbn < T(0.0), -s.mbn, s.mbn);
    sigma = -s.fbn / A + mbs * 4.0 / (A * rb);
    tau = fbs / A + mbn * 2.0 / (A * rb);
  } else {  // mbs = +0 and |mbn| = +-0 give +0 and +-0, either of which adds as +0 does
    sigma = -s.fbn / A + T(0.0);
    tau = fbs / A + T(0.0);
  }
  return elliptic_criterion(sigma, tau, p.strength);
}

// --- one stored bond k of a bond store (store/bonds.hpp), read in double precision: what the
// break processing, the step's energy and the world's queries all take from here -------------

// Periphery stresses of the beam [3-27], tension positive.
template <class Store>
inline void beam_stresses(const Store& q, std::size_t k, double& sigma, double& tau) {
  const double rb = q.beam_radius[k], A = kPi * rb * rb;
  const double fbs = std::sqrt(q.fbsx[k] * q.fbsx[k] + q.fbsy[k] * q.fbsy[k] + q.fbsz[k] * q.fbsz[k]);
  const double mbs = std::sqrt(q.mbsx[k] * q.mbsx[k] + q.mbsy[k] * q.mbsy[k] + q.mbsz[k] * q.mbsz[k]);
  sigma = -q.fbn[k] / A + mbs * 4.0 / (A * rb);
  tau = fbs / A + std::fabs(q.mbn[k]) * 2.0 / (A * rb);
}

// Strain energy of the beam (model.md 8): Fbn^2/(2 kbn A) + |Fbs|^2/(2 kbs A) + Mbn^2/(2 kbs J)
// + |Mbs|^2/(2 kbn I), with kbs J = beam_ks Rb^2 / 2 and kbn I = beam_kn Rb^2 / 4.
template <class Store>
inline double beam_energy(const Store& q, std::size_t k, const BondMaterial& bm) {
  const double r2 = q.beam_radius[k] * q.beam_radius[k];
  return q.fbn[k] * q.fbn[k] / (2 * bm.beam_kn) +
         (q.fbsx[k] * q.fbsx[k] + q.fbsy[k] * q.fbsy[k] + q.fbsz[k] * q.fbsz[k]) / (2 * bm.beam_ks) +
         q.mbn[k] * q.mbn[k] / (2 * bm.beam_ks * 0.5 * r2) +
         (q.mbsx[k] * q.mbsx[k] + q.mbsy[k] * q.mbsy[k] + q.mbsz[k] * q.mbsz[k]) / (2 * bm.beam_kn * 0.25 * r2);
}

// The beam's twisting moment (along n) and bending moment, on b (on a: their negatives).
template <class Store>
inline void beam_moments(const Store& q, std::size_t k, double& twisting, Vec3& bending) {
  twisting = q.mbn[k];
  bending = {q.mbsx[k], q.mbsy[k], q.mbsz[k]};
}

// Whether the beam carries no moment (+-0): only spin makes one grow (BondStore's layouts).
template <class Store>
inline bool beam_moments_zero(const Store& q, std::size_t k) {
  return q.mbn[k] == 0 && q.mbsx[k] == 0 && q.mbsy[k] == 0 && q.mbsz[k] == 0;
}

// The beam unloaded: forces and moments zero (a new beam, or one that broke).
template <class Store>
inline void unload_beam(Store& q, std::size_t k) {
  q.fbn[k] = q.fbsx[k] = q.fbsy[k] = q.fbsz[k] = 0;
  q.mbn[k] = q.mbsx[k] = q.mbsy[k] = q.mbsz[k] = 0;
}

// Strain energy of the contact springs (model.md 8): Fn^2/(2 kn) + |Fs|^2/(2 ks).
template <class Store>
inline double spring_energy(const Store& q, std::size_t k, const ContactMaterial& m) {
  return contact_spring_energy(q.fn[k], q.fsx[k] * q.fsx[k] + q.fsy[k] * q.fsy[k] + q.fsz[k] * q.fsz[k], m.kn, m.ks);
}

}  // namespace asperity::kernels
