// The bond loop shared by the scalar reference and the SIMD kernels (see pair_loop.hpp).
#pragma once
#include <limits>

#include "kernels/a_side.hpp"
#include "kernels/bond_law.hpp"
#include "kernels/kernels.hpp"

namespace asperity::kernels {

// Moments = false (with Rotation = false): the beams carry no moment (bond_law.hpp); their four
// columns are neither read nor written, and the record is the first eight values only (its
// moment would be +-0), eight doubles a bond. Levers = false (with Moments = false): no end of a
// bond turns, and the record is the first four (BondRecord::forces).
template <class Lanes, bool Rotation, bool Moments = true, bool Levers = true>
BondSums bond_loop(const BondKernelArgs& k, std::size_t begin, std::size_t end) {
  static_assert(Levers || !Moments, "a beam moment acts where the ends turn");
  using T = typename Lanes::Real;
  const BondParams<T> p{T(k.kn), T(k.ks), T(k.beam_kn), T(k.beam_ks), T(k.dt), T(k.strength)};
  const LawParams<T> contact{T(k.kn), T(k.ks), T(k.friction), T(k.dt)};  // once the contact bond broke
  const bool breakable = k.strength > 0;
  // The contact bond breaks with the beam (c = 0), never (c = inf) or at c st A (model.md 5).
  const bool with_beam = k.contact_strength == 0;
  const double shear_factor = contact_shear_factor(k.contact_strength, k.contact_shear_strength);
  constexpr double never = std::numeric_limits<double>::infinity();
  const bool contact_breaks = !with_beam && (k.contact_strength < never || shear_factor < never);
  T count(0.0), slip(0.0);
  for (std::size_t i = begin; i < end; i += Lanes::size) {
    const BatchSides<T> q = load_sides<Lanes, Rotation>(k, i);
    T nx, ny, nz, U, la, lb;
    ball_ball_geometry(q.xa, q.ya, q.za, q.xb, q.yb, q.zb, q.ra, q.rb, nx, ny, nz, U, la, lb);
    const T ox = Lanes::load(k.nx + i), oy = Lanes::load(k.ny + i), oz = Lanes::load(k.nz + i);
    BondState<T> s{Lanes::load(k.fsx + i), Lanes::load(k.fsy + i), Lanes::load(k.fsz + i), T(0.0),
                   Lanes::load(k.fbn + i), Lanes::load(k.fbsx + i), Lanes::load(k.fbsy + i),
                   Lanes::load(k.fbsz + i), T(0.0), T(0.0), T(0.0), T(0.0)};
    if constexpr (Moments) {
      s.mbn = Lanes::load(k.mbn + i);
      s.mbsx = Lanes::load(k.mbsx + i); s.mbsy = Lanes::load(k.mbsy + i); s.mbsz = Lanes::load(k.mbsz + i);
    }
    const T rbeam = Lanes::load(k.beam_radius + i);
    // Padding bonds have Rb = 0; give them a harmless radius so no lane divides by zero.
    const auto real = rbeam > T(0.0);
    const T rsafe = select(real, rbeam, T(1.0));
    const T u0 = k.rest ? Lanes::load(k.rest + i) : T(0.0);
    T sigma, tau;
    const T crit = bond_forces<T, Rotation, Moments>(nx, ny, nz, U, la, lb, rsafe, q.vax, q.vay, q.vaz,
                                            q.wax, q.way, q.waz, q.vbx, q.vby, q.vbz, q.wbx, q.wby,
                                            q.wbz, ox, oy, oz, u0, s, sigma, tau, p);
    // A bond that lost a part (BondStore::holds): without its beam the beam's force and moments
    // stay 0 and it cannot break again; without its contact bond the contact springs follow the
    // ordinary contact law (the shear force was carried and incremented above as any contact's).
    auto beam_on = real, contact_on = real;
    if (k.holds != nullptr) {
      const T hold = Lanes::load(k.holds + i);
      beam_on = real & ((hold == T(kBeamHolds)) | (hold == T(kBothHold)));
      contact_on = real & (hold >= T(kContactBondHolds));
      s.fbn = select(beam_on, s.fbn, T(0.0));
      s.fbsx = select(beam_on, s.fbsx, T(0.0));
      s.fbsy = select(beam_on, s.fbsy, T(0.0));
      s.fbsz = select(beam_on, s.fbsz, T(0.0));
      if constexpr (Moments) {
        s.mbn = select(beam_on, s.mbn, T(0.0));
        s.mbsx = select(beam_on, s.mbsx, T(0.0));
        s.mbsy = select(beam_on, s.mbsy, T(0.0));
        s.mbsz = select(beam_on, s.mbsz, T(0.0));
      }
      const auto ordinary = real & !contact_on;
      if (any(ordinary)) {
        T fx = s.fsx, fy = s.fsy, fz = s.fsz, fn;
        // A stress-free bond's contact keeps its rest overlap, a gap bond's (rest < 0) none.
        const T e = contact_cap(U, select(u0 > T(0.0), u0, T(0.0)), fx, fy, fz, fn, contact);
        slip = slip + select(ordinary, e, T(0.0));
        s.fsx = select(ordinary, fx, s.fsx);
        s.fsy = select(ordinary, fy, s.fsy);
        s.fsz = select(ordinary, fz, s.fsz);
        s.fn = select(ordinary, fn, s.fn);
      }
    }
    if (breakable) {
      // The flags stay 0 but where a bond breaks (process_breaks handles those; bond_stage clears
      // the column after a step whose breaks were not processed), so only such a batch stores:
      // no column written at every step for nothing.
      const auto beam_fails = beam_on & (crit >= T(1.0));
      T brk = select(beam_fails, T(with_beam ? kBothHold : kBeamHolds), T(0.0));
      if (contact_breaks) {
        T fcn, fcs;
        contact_bond_strengths(p.strength, rsafe, k.contact_strength, k.contact_shear_strength,
                               k.contact_bond_friction, s.fn, fcn, fcs);
        const T cf = contact_bond_failure(s.fn, s.fsx, s.fsy, s.fsz, fcn, fcs);
        brk = brk + select(contact_on & (cf != T(0.0)), T(kContactBondHolds), T(0.0));
      }
      count = count + select(brk != T(0.0), T(1.0), T(0.0));
      if (any(brk != T(0.0))) Lanes::store(k.broken + i, brk);
    }
    Lanes::store(k.nx + i, nx); Lanes::store(k.ny + i, ny); Lanes::store(k.nz + i, nz);
    Lanes::store(k.fsx + i, s.fsx); Lanes::store(k.fsy + i, s.fsy); Lanes::store(k.fsz + i, s.fsz);
    const T fn = select(real, s.fn, T(0.0));
    Lanes::store(k.fn + i, fn);
    Lanes::store(k.overlap + i, U);
    Lanes::store(k.fbn + i, s.fbn);
    Lanes::store(k.fbsx + i, s.fbsx); Lanes::store(k.fbsy + i, s.fbsy); Lanes::store(k.fbsz + i, s.fbsz);
    if constexpr (Moments) {
      Lanes::store(k.mbn + i, s.mbn);
      Lanes::store(k.mbsx + i, s.mbsx); Lanes::store(k.mbsy + i, s.mbsy); Lanes::store(k.mbsz + i, s.mbsz);
    }
    // For the gather (stages/integrate.cpp), with the operations it would do per side: the
    // record fx fy fz U cx cy cz 0 mx my mz 0 of each bond (store/bonds.hpp).
    const T ftot = fn + s.fbn;
    const T sx = s.fsx + s.fbsx, sy = s.fsy + s.fbsy, sz = s.fsz + s.fbsz;
    // Without moments only the first eight values are stored, without levers the first four.
    constexpr int width = int(Moments ? BondRecord::moments : Levers ? BondRecord::levers : BondRecord::forces);
    const T record[12] = {ftot * nx + sx, ftot * ny + sy, ftot * nz + sz, U,
                          ny * sz - nz * sy, nz * sx - nx * sz, nx * sy - ny * sx, T(0.0),
                          s.mbn * nx + s.mbsx, s.mbn * ny + s.mbsy, s.mbn * nz + s.mbsz, T(0.0)};
    Lanes::template store_records<width>(k.out + width * i, record);
  }
  return {Lanes::sum(count), Lanes::sum(slip)};
}

}  // namespace asperity::kernels
