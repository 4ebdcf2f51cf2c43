// Bond store (model.md 5): the persistent list of contact + parallel bonds, never rebuilt by the
// neighbour search. Sorted by (a, b) current index with a < b, like the pair list; padded to the
// SIMD width with bonds between two null particles (zero beam radius: they never act or break).
//
// Per bond, the history the incremental law needs (normal, contact shear force, beam force and
// moments) and the outputs of the step (contact normal force, overlap, break flag). Forces and
// moments act on b; their negatives (plus lever-arm torques) on a.
#pragma once
#include <cstdint>
#include <vector>

#include "asperity/world.hpp"
#include "core/aligned.hpp"

namespace asperity::detail {

inline constexpr std::size_t kBondRecord = 12;  // doubles per bond in BondStore::out

struct BondStore {
  std::size_t n = 0;
  std::size_t padded = 0;
  AVec<std::int64_t> a, b;
  AVec<double> beam_radius;               // Rb
  AVec<double> nx, ny, nz;                // normal of the last step
  AVec<double> fsx, fsy, fsz;             // contact bond shear force (history)
  AVec<double> fn;                        // contact bond normal force kn (U - rest) (may be < 0)
  AVec<double> overlap;                   // U
  AVec<double> rest;                      // overlap of the unloaded contact bond (stress-free
                                          // installation; else 0): fn = kn (U - rest)
  AVec<double> fbn;                       // parallel bond normal force (> 0 compression)
  AVec<double> fbsx, fbsy, fbsz;          // parallel bond shear force
  AVec<double> mbn;                       // twisting moment (along n)
  AVec<double> mbsx, mbsy, mbsz;          // bending moment
  AVec<double> broken;                    // 1 when the criterion was met this step; 0 between
                                          // steps (the kernel writes only where one breaks)
  // For the gather, computed by the SIMD kernel (outputs of the step only, like PairStore's): the
  // record of bond k is out[kBondRecord k + j], j = 0..11: fx fy fz U cx cy cz 0 mx my mz 0, the
  // force on b (fn + fbn) n + fs + fbs, the overlap, n x (fs + fbs) (torque per lever arm,
  // negated) and the beam moment on b mbn n + mbs (on a: its negative). While every moment is zero
  // the kernel without moments writes records of 8 (the first eight values, from out + 8 k: one
  // 64-byte line a bond instead of 1.5; State::bond_records_with_moments says which).
  AVec<double> out;
  BondMaterial material;
  bool any = false;                       // a material was set by a first installation

  void resize(std::size_t count) {
    n = count;
    padded = round_up(count, kMaxLanes);
    for (auto* c : {&a, &b}) c->resize(padded);
    for (auto* c : {&beam_radius, &nx, &ny, &nz, &fsx, &fsy, &fsz, &fn, &overlap, &rest, &fbn, &fbsx,
                    &fbsy, &fbsz, &mbn, &mbsx, &mbsy, &mbsz, &broken})
      c->resize(padded);
    size_outputs();
  }
  // The gather's columns are not saved: a store read from a checkpoint sizes them here.
  void size_outputs() {
    out.resize(kBondRecord * padded);
  }
  void fill_padding(std::int64_t null_a, std::int64_t null_b) {
    for (std::size_t i = n; i < padded; ++i) {
      a[i] = null_a;
      b[i] = null_b;
      beam_radius[i] = 0;
      nx[i] = 1;
      ny[i] = nz[i] = fsx[i] = fsy[i] = fsz[i] = fn[i] = overlap[i] = rest[i] = fbn[i] = 0;
      fbsx[i] = fbsy[i] = fbsz[i] = mbn[i] = mbsx[i] = mbsy[i] = mbsz[i] = broken[i] = 0;
      for (std::size_t j = 0; j < kBondRecord; ++j) out[kBondRecord * i + j] = 0;
    }
  }
  // Copy bond o of `from` into slot k of this store.
  void copy_from(const BondStore& from, std::size_t o, std::size_t k) {
    a[k] = from.a[o]; b[k] = from.b[o]; beam_radius[k] = from.beam_radius[o];
    nx[k] = from.nx[o]; ny[k] = from.ny[o]; nz[k] = from.nz[o];
    fsx[k] = from.fsx[o]; fsy[k] = from.fsy[o]; fsz[k] = from.fsz[o];
    fn[k] = from.fn[o]; overlap[k] = from.overlap[o]; rest[k] = from.rest[o]; fbn[k] = from.fbn[o];
    fbsx[k] = from.fbsx[o]; fbsy[k] = from.fbsy[o]; fbsz[k] = from.fbsz[o];
    mbn[k] = from.mbn[o]; mbsx[k] = from.mbsx[o]; mbsy[k] = from.mbsy[o]; mbsz[k] = from.mbsz[o];
    broken[k] = from.broken[o];
  }
};

}  // namespace asperity::detail
