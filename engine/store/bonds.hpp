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

#include "asperity/materials.hpp"
#include "core/aligned.hpp"
#include "kernels/kernels.hpp"
#include "store/columns.hpp"

namespace asperity::detail {

inline constexpr std::size_t kBondRecord = 12;  // doubles per bond in BondStore::out

// What of a bond still holds (BondStore::holds; the bond kernel's encoding, kernels.hpp).
using kernels::kBeamHolds;
using kernels::kBothHold;
using kernels::kContactBondHolds;

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
  AVec<double> holds;                     // kBeamHolds | kContactBondHolds (installed: both).
                                          // Without the beam its forces and moments are 0;
                                          // without the contact bond the contact springs follow
                                          // the ordinary contact law (model.md 4). 0: a dead
                                          // record (dead(), below)
  AVec<double> broken;                    // what broke this step (kBeamHolds | kContactBondHolds
                                          // of the parts that broke); 0 between steps (the
                                          // kernel writes only where one breaks)
  // For the gather, computed by the SIMD kernel (outputs of the step only, like PairStore's): the
  // record of bond k is out[kBondRecord k + j], j = 0..11: fx fy fz U cx cy cz 0 mx my mz 0, the
  // force on b (fn + fbn) n + fs + fbs, the overlap, n x (fs + fbs) (torque per lever arm,
  // negated) and the beam moment on b mbn n + mbs (on a: its negative). While every moment is zero
  // the kernel without moments writes records of 8 (the first eight values, from out + 8 k: one
  // 64-byte line a bond instead of 1.5), and where besides no end of a bond turns, records of 4
  // (from out + 4 k); Caches::bond_records says which (kernels::BondRecord). One more record
  // after the padded ones, zero_record(), which the bond stage fills with zeros each step.
  AVec<double> out;
  BondMaterial material;
  bool any = false;                       // a material was set by a first installation

  // Every column but a and b once: f(info, this column of each of `q`...). What a copy carries,
  // a reorder flips and a checkpoint saves.
  template <class F, class... Stores>
  static void columns(F&& f, Stores&... q) {
    f(ColumnInfo{"beam_radius", 0}, q.beam_radius...);  // 0 in padding: never acts or breaks
    contact_columns(f, 0, q...);  // the contact bond
    f(ColumnInfo{"fbn", 0}, q.fbn...);
    f(ColumnInfo{"fbsx", 0, true}, q.fbsx...);
    f(ColumnInfo{"fbsy", 0, true}, q.fbsy...);
    f(ColumnInfo{"fbsz", 0, true}, q.fbsz...);
    f(ColumnInfo{"mbn", 0, true}, q.mbn...);
    f(ColumnInfo{"mbsx", 0, true}, q.mbsx...);
    f(ColumnInfo{"mbsy", 0, true}, q.mbsy...);
    f(ColumnInfo{"mbsz", 0, true}, q.mbsz...);
    f(ColumnInfo{"holds", kBothHold, false, 9}, q.holds...);
    f(ColumnInfo{"broken", 0}, q.broken...);
  }

  void resize(std::size_t count) {
    n = count;
    padded = round_up(count, kMaxLanes);
    for (auto* c : {&a, &b}) c->resize(padded);
    columns([&](const ColumnInfo&, auto& c) { c.resize(padded); }, *this);
    size_outputs();
  }
  // The gather's columns are not saved: a store read from a checkpoint sizes them here.
  void size_outputs() {
    out.resize(kBondRecord * (padded + 1));
  }
  // A bond of which nothing holds any more, left in its slot until the next neighbour build
  // (process_breaks, compact_bonds): zero beam radius, so the kernel neither acts nor breaks on
  // it, and nothing holds, so every pass over the bonds leaves it out (for_each_bond). Leaving it
  // there spares a break step the passes over the whole list that taking it out would cost.
  bool dead(std::size_t k) const { return holds[k] == 0; }
  // The record the incidence entries of dead bonds point to (Caches::bond_incidence): its force
  // and moment -0 and its lever arm term +0, taken with the sign of b (+1), adds -0 to every sum
  // of the gather, which leaves each sum's bits as they were without the term (x + -0 = x).
  std::size_t zero_record() const { return padded; }
  void fill_padding(std::int64_t null_a, std::int64_t null_b) {
    pad_column(a, n, padded, double(null_a));
    pad_column(b, n, padded, double(null_b));
    columns([&](const ColumnInfo& c, auto& col) { pad_column(col, n, padded, c.pad); }, *this);
    std::fill(out.begin() + std::ptrdiff_t(kBondRecord * n), out.begin() + std::ptrdiff_t(kBondRecord * padded), 0.0);
  }
  // Copy bond o of `from` into slot k of this store.
  void copy_from(const BondStore& from, std::size_t o, std::size_t k) {
    a[k] = from.a[o];
    b[k] = from.b[o];
    columns([&](const ColumnInfo&, auto& to, const auto& src) { to[k] = src[o]; }, *this, from);
  }
  // The bonds `rows` (ascending) taken out, the others kept in order (the padding is left to
  // fill_padding).
  void remove(const std::vector<std::size_t>& rows) {
    if (rows.empty()) return;
    remove_slots(a, rows, n);
    remove_slots(b, rows, n);
    columns([&](const ColumnInfo&, auto& c) { remove_slots(c, rows, n); }, *this);
    resize(n - rows.size());
  }
  // Bond k seen from the other side (a and b swap roles, as a renumbering may ask).
  void swap_roles(std::size_t k) {
    columns([&](const ColumnInfo& c, auto& col) { if (c.flips) col[k] = -col[k]; }, *this);
  }
};

}  // namespace asperity::detail
