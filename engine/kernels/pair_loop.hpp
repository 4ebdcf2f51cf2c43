// The pair loop shared by the scalar reference and the SIMD kernels: load a batch of pairs, apply
// the contact law, store the per-pair results. `Lanes` abstracts loading and storing (gather of
// particle columns by pair index, aligned loads of pair columns), `Rotation` whether angular
// velocities exist at all (a scene with rotation locked everywhere never reads them).
#pragma once
#include <type_traits>

#include "kernels/a_side.hpp"
#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"

namespace asperity::kernels {

// Whether the n flags from p are all 0 (PairKernelArgs::live).
inline bool all_dead(const std::uint8_t* p, std::size_t n) {
  unsigned any = 0;
  for (std::size_t j = 0; j < n; ++j) any |= p[j];
  return any == 0;
}

// Every store of batch i: the history (normal, shear force), the rest overlap, and the record.
// A pair's record is "live" where it is not all zeros but for the overlap: the pair touches
// (U > 0), carries a normal force (a broken bond's contact whose rest overlap U0 < 0 pushes
// within U0 < U <= 0) or has no valid overlap (NaN). Where PairKernelArgs::live is given, its
// flag goes there and `live` counts them per lane (PairKernelArgs::touched). A batch whose pairs
// were all dead in the last step and are now leaves its records as they are
// (PairKernelArgs::keep_dead_records).
template <class Lanes, class T = typename Lanes::Real>
inline void store_pair(const PairKernelArgs& k, std::size_t i, const T& nx, const T& ny,
                       const T& nz, const T& U, const T& u0, const T& fx, const T& fy, const T& fz,
                       const T& fn, T& live) {
  bool keep_record = false;
  if (k.live) {
    T lanes = select(U <= T(0.0), T(0.0), T(1.0));
    lanes = select(fn != T(0.0), T(1.0), lanes);
    const bool was_dead = k.keep_dead_records && all_dead(k.live + i, Lanes::size);
    Lanes::store_flags(k.live + i, lanes);
    live = live + lanes;
    keep_record = was_dead && !any(lanes != T(0.0));
  }
  // A pair that no longer touches forgets its rest overlap with its shear force.
  if (k.rest) Lanes::store(k.rest + i, select(U > T(0.0), u0, T(0.0)));
  Lanes::store(k.nx + i, nx); Lanes::store(k.ny + i, ny); Lanes::store(k.nz + i, nz);
  Lanes::store(k.fsx + i, fx); Lanes::store(k.fsy + i, fy); Lanes::store(k.fsz + i, fz);
  // For the gather (stages/integrate.cpp), with the operations it would do per side, and for
  // the readers of fn and U: the record fx fy fz U cx cy cz fn of each pair (store/pairs.hpp).
  // fn and U have no columns of their own to store to.
  if (keep_record) return;
  const T record[8] = {fn * nx + fx, fn * ny + fy, fn * nz + fz, U,
                       ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx, fn};
  if (k.stream)  // large record arrays (kernels.hpp)
    Lanes::template store_records<8, true>(k.out + 8 * i, record);
  else
    Lanes::template store_records<8>(k.out + 8 * i, record);
}

// The contact law of one pair is a chain of some 150 dependent operations (two square roots,
// three divisions) in a body of ~400 instructions, more than the out-of-order window of a core
// holds, so consecutive batches hardly overlap. The loop therefore runs in two passes over
// stages of kPairStage pairs: geometry and kinematics (positions and velocities in, n, U, Vs,
// phi out to an L1 scratch), then the response (history in, forces and records out). Each body
// is about half as long; the operations are those of contact_forces, so the results are the
// same bit for bit.
//
// On AVX-512 machines the touching stages run in one pass instead (Lanes::kOnePass): there the
// out-of-order window overlaps the batches of the whole law, and the scratch's stores and loads
// go. Same operations, same bits.
//
// A stage in which no pair touches (U <= 0 for all its pairs) skips the law in pass 2: the law
// would select zero shear force, zero slip energy and a zero rest overlap for each of them, and
// fn and the record follow from those zeros by the same expressions. In a bonded specimen nearly
// every listed pair is such a near miss (its touching pairs became bonds: a joint in mid-shear
// has a few dozen touching among thousands listed). The choice is per stage, not per batch: a
// check per batch would cost a scene in which everything touches (the lattice) and save it
// nothing.
template <class Lanes, bool Rotation>
double pair_loop(const PairKernelArgs& k, std::size_t begin, std::size_t end) {
  using T = typename Lanes::Real;
  const LawParams<T> p{T(k.kn), T(k.ks), T(k.friction), T(k.dt)};
  T slip_sum(0.0);
  alignas(64) double scratch[10][kPairStage];  // n U Vs phi; la lb on the split path
  T live(0.0);  // per stage, per lane: how many of its records are live (store_pair)
  // PairKernelArgs::touched: with flags the stage's live records, without whether one touches.
  auto mark = [&](std::size_t stage, const T& reach) __attribute__((always_inline)) {
    if (k.touched)
      k.touched[stage] = k.live ? std::uint8_t(Lanes::sum(live)) : std::uint8_t(any(reach > T(0.0)));
  };
  // The law's response for batch i of a touching stage and every store of the pair: history,
  // rest overlap and the record.
  auto respond_batch = [&](std::size_t i, const T& nx, const T& ny, const T& nz, const T& U,
                           const T& vsx, const T& vsy, const T& vsz, const T& phi)
      __attribute__((always_inline)) {
    const T u0 = k.rest ? Lanes::load(k.rest + i) : T(0.0);
    const T ox = Lanes::load(k.nx + i), oy = Lanes::load(k.ny + i), oz = Lanes::load(k.nz + i);
    T fx = Lanes::load(k.fsx + i), fy = Lanes::load(k.fsy + i), fz = Lanes::load(k.fsz + i), fn;
    slip_sum = slip_sum + contact_response<T, Rotation>(nx, ny, nz, U, vsx, vsy, vsz, phi, ox, oy,
                                                        oz, u0, fx, fy, fz, fn, p);
    store_pair<Lanes>(k, i, nx, ny, nz, U, u0, fx, fy, fz, fn, live);
  };
  for (std::size_t first = begin; first < end; first += kPairStage) {
    const std::size_t last = first + kPairStage < end ? first + kPairStage : end;
    const std::size_t stage = first / kPairStage;
    T reach(0.0);  // the largest overlap of the stage (a NaN is not counted: it touches nothing)
    live = T(0.0);
    if (k.touched && !k.touched[stage]) {
      // Nothing touched here in the last step: the geometry first, and the velocities and the
      // kinematics only if something touches now (in a bonded specimen most stages never do).
      for (std::size_t i = first; i < last; i += Lanes::size) {
        const std::size_t j = i - first;
        BatchSides<T> q;
        load_positions<Lanes>(k, i, q);
        T nx, ny, nz, U, la, lb;
        ball_ball_geometry(q.xa, q.ya, q.za, q.xb, q.yb, q.zb, q.ra, q.rb, nx, ny, nz, U, la, lb);
        reach = select(U > reach, U, reach);
        Lanes::store(scratch[0] + j, nx); Lanes::store(scratch[1] + j, ny);
        Lanes::store(scratch[2] + j, nz); Lanes::store(scratch[3] + j, U);
        Lanes::store(scratch[8] + j, la); Lanes::store(scratch[9] + j, lb);
      }
      if (any(reach > T(0.0)))
        for (std::size_t i = first; i < last; i += Lanes::size) {
          const std::size_t j = i - first;
          BatchSides<T> q;
          load_velocities<Lanes, Rotation>(k, i, q);
          T vn, vsx, vsy, vsz, phi;
          contact_kinematics<T, Rotation>(
              Lanes::load(scratch[0] + j), Lanes::load(scratch[1] + j), Lanes::load(scratch[2] + j),
              Lanes::load(scratch[8] + j), Lanes::load(scratch[9] + j), q.vax, q.vay, q.vaz, q.wax,
              q.way, q.waz, q.vbx, q.vby, q.vbz, q.wbx, q.wby, q.wbz, p.dt, vn, vsx, vsy, vsz, phi);
          Lanes::store(scratch[4] + j, vsx); Lanes::store(scratch[5] + j, vsy);
          Lanes::store(scratch[6] + j, vsz); Lanes::store(scratch[7] + j, phi);
        }
    } else {
      for (std::size_t i = first; i < last; i += Lanes::size) {
        const std::size_t j = i - first;
        const BatchSides<T> q = load_sides<Lanes, Rotation>(k, i);
        T nx, ny, nz, U, la, lb;
        ball_ball_geometry(q.xa, q.ya, q.za, q.xb, q.yb, q.zb, q.ra, q.rb, nx, ny, nz, U, la, lb);
        T vn, vsx, vsy, vsz, phi;
        contact_kinematics<T, Rotation>(nx, ny, nz, la, lb, q.vax, q.vay, q.vaz, q.wax, q.way,
                                        q.waz, q.vbx, q.vby, q.vbz, q.wbx, q.wby, q.wbz, p.dt, vn,
                                        vsx, vsy, vsz, phi);
        reach = select(U > reach, U, reach);
        if constexpr (Lanes::kOnePass) {
          respond_batch(i, nx, ny, nz, U, vsx, vsy, vsz, phi);
        } else {
          Lanes::store(scratch[0] + j, nx); Lanes::store(scratch[1] + j, ny);
          Lanes::store(scratch[2] + j, nz); Lanes::store(scratch[3] + j, U);
          Lanes::store(scratch[4] + j, vsx); Lanes::store(scratch[5] + j, vsy);
          Lanes::store(scratch[6] + j, vsz); Lanes::store(scratch[7] + j, phi);
        }
      }
      if constexpr (Lanes::kOnePass) {
        // Done in the one pass. A stage that touched nothing after all got what the no-touch
        // branch below gives (the law selects zero forces where U <= 0).
        mark(stage, reach);
        continue;
      }
    }
    auto respond = [&](auto touching) __attribute__((always_inline)) {
      for (std::size_t i = first; i < last; i += Lanes::size) {
        const std::size_t j = i - first;
        const T nx = Lanes::load(scratch[0] + j), ny = Lanes::load(scratch[1] + j),
                nz = Lanes::load(scratch[2] + j), U = Lanes::load(scratch[3] + j);
        if constexpr (decltype(touching)::value) {
          respond_batch(i, nx, ny, nz, U, Lanes::load(scratch[4] + j), Lanes::load(scratch[5] + j),
                        Lanes::load(scratch[6] + j), Lanes::load(scratch[7] + j));
        } else {
          // What contact_response gives where nothing touches: the shear force forgotten (+0),
          // no slip (+0, which leaves the sum as it is), the normal force by the same select.
          const T u0 = k.rest ? Lanes::load(k.rest + i) : T(0.0);
          const T fn = select(U > u0, p.kn * (U - u0), T(0.0)), zero(0.0);
          store_pair<Lanes>(k, i, nx, ny, nz, U, u0, zero, zero, zero, fn, live);
        }
      }
    };
    if (any(reach > T(0.0)))
      respond(std::true_type{});
    else
      respond(std::false_type{});
    mark(stage, reach);
  }
  return Lanes::sum(slip_sum);
}

}  // namespace asperity::kernels
