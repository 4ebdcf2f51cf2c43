// Pair store: the Verlet list of ball-ball pairs within the skin, touching or not, sorted by
// (a, b) current indices with a < b. Per pair it keeps the contact normal and the shear force
// (both are also the history for the next step), the normal force and the overlap; and, for the
// gather, one record per pair with the pair's force on b and n x Fs, which the SIMD kernel
// computes eight pairs at a time instead of the scalar gather computing them once per side.
// The pair kernel leaves the normal force and the overlap in the record too, not in their
// columns (two stores a pair fewer in the hottest loop); read them with normal_force(k) and
// overlap_at(k), which know where they are.
//
// Sign convention (model.md 4): n points from a to b; fn, fs act on b; -(fn n + fs) acts on a.
#pragma once
#include <cstdint>
#include <vector>

#include "core/aligned.hpp"
#include "store/columns.hpp"

namespace asperity::detail {

inline constexpr std::size_t kPairRecord = 8;  // doubles per pair in PairStore::out

struct PairStore {
  std::size_t n = 0;       // real pairs
  std::size_t padded = 0;  // n rounded up to kMaxLanes; the tail points at null particles
  AVec<std::int64_t> a, b;
  AVec<double> nx, ny, nz;     // unit normal a -> b (history: normal of the last step)
  AVec<double> fsx, fsy, fsz;  // shear force on b (history)
  // Normal force on b along n (>= 0) and overlap U = Ra + Rb - d (negative: not touching), as the
  // neighbour build or a checkpoint set them; after a step they are in the records
  // (outputs_in_records): read them through normal_force(k) and overlap_at(k). A pair that has
  // neither touched nor carried a force for two steps or more may keep an older record (kernels.hpp,
  // PairKernelArgs::keep_dead_records): fn 0 as now, but for U the gap (<= 0) of the step that
  // wrote it, not the current one. Every reader asks only whether U > 0.
  AVec<double> fn;
  AVec<double> overlap;
  // Rest overlap (history): the overlap at which the normal spring is unloaded, Fn = kn (U - rest)
  // (model.md 4 has rest = 0). Only a contact left behind by a bond installed stress-free has
  // rest > 0 (World::install_bonds); it is forgotten with the shear force when U <= 0. The pair
  // kernel reads it only when State::rest_overlaps is set.
  AVec<double> rest;
  // The gather's record of pair k: out[kPairRecord k + j], j = 0..7: fx fy fz U cx cy cz fn, the
  // force on b fn n + fs (on a: its negative), the overlap, n x fs (the torque on either
  // particle is -(R - U/2) times it) and the normal force. One 64-byte line per pair: the gather
  // reaches a pair through the incidence list in one line instead of seven columns. Outputs of
  // the step: not carried by rebuilds nor saved.
  AVec<double> out;
  // Per stage of kTouchStage pairs: how many of its records the last pair stage found live
  // (kernels.hpp, PairKernelArgs::touched); 1 where not known. Chooses how the kernel computes
  // the stage, and (summed: stages/pairs.cpp) whether it writes the live flags.
  static constexpr std::size_t kTouchStage = 128;
  std::vector<std::uint8_t> touched;
  // Per pair: 1 where its record is live (not all zeros but for the overlap), written by the pair
  // kernel where live_written (kernels.hpp, PairKernelArgs::live) for the gather in the same step.
  std::vector<std::uint8_t> live;
  bool live_written = false;  // this step's pair kernel writes `live` (stages/pairs.cpp)
  // `live` and `touched` hold the flags and per-stage counts of the last pair kernel's run.
  bool live_current = false;
  // Set by the pair stage: the current normal forces and overlaps are in the records (slots 7
  // and 3), the fn and overlap columns are stale. Cleared where the columns are written.
  bool outputs_in_records = false;

  double normal_force(std::size_t k) const {
    return outputs_in_records ? out[kPairRecord * k + 7] : fn[k];
  }
  double overlap_at(std::size_t k) const {
    return outputs_in_records ? out[kPairRecord * k + 3] : overlap[k];
  }
  // The columns brought up to date from the records (before they are saved).
  void columns_from_records() {
    if (!outputs_in_records) return;
    for (std::size_t k = 0; k < padded; ++k) {
      fn[k] = out[kPairRecord * k + 7];
      overlap[k] = out[kPairRecord * k + 3];
    }
    outputs_in_records = false;
  }

  // Every history column once: f(info, this column of each of `q`...). The history a rebuild
  // carries over, a reorder flips and a checkpoint saves (besides a and b).
  template <class F, class... Stores>
  static void history_columns(F&& f, Stores&... q) {
    contact_columns(f, -1, q...);  // padding pairs never touch
  }

  void resize(std::size_t count) {
    n = count;
    padded = round_up(count, kMaxLanes);
    for (auto* c : {&a, &b}) c->resize(padded);
    history_columns([&](const ColumnInfo&, auto& c) { c.resize(padded); }, *this);
    size_outputs();  // which also marks the columns as current
  }
  // The gather's columns are not saved: a store read from a checkpoint sizes them here.
  void size_outputs() {
    out.resize(kPairRecord * padded);
    touched.assign(padded / kTouchStage + 1, 1);
    live.assign(padded, 1);
    live_written = false;
    live_current = false;
    outputs_in_records = false;
  }
  // Padding entries: pair of two null particles, no force, not touching.
  void fill_padding(std::int64_t null_a, std::int64_t null_b) {
    pad_column(a, n, padded, double(null_a));
    pad_column(b, n, padded, double(null_b));
    history_columns([&](const ColumnInfo& c, auto& col) { pad_column(col, n, padded, c.pad); }, *this);
    for (std::size_t i = n; i < padded; ++i) {
      for (std::size_t j = 0; j < kPairRecord; ++j) out[kPairRecord * i + j] = 0;
      out[kPairRecord * i + 3] = -1;
    }
  }
  // Copy the history of pair o of `from` into slot k of this store.
  void copy_history(const PairStore& from, std::size_t o, std::size_t k) {
    history_columns([&](const ColumnInfo&, auto& to, const auto& src) { to[k] = src[o]; }, *this, from);
    fn[k] = from.normal_force(o);  // the last step's, wherever they are
    overlap[k] = from.overlap_at(o);
  }
  // Pair k seen from the other side (a and b swap roles, as a renumbering may ask).
  void swap_roles(std::size_t k) {
    history_columns([&](const ColumnInfo& c, auto& col) { if (c.flips) col[k] = -col[k]; }, *this);
  }
};

// Per-particle incidence (CSR) into the pair list: entries (pair << 1) | (particle is b), in
// increasing pair order. The gather walks it, so its sums have a fixed order for any thread count.
struct Incidence {
  std::vector<std::int32_t> start;  // n + 1 offsets
  std::vector<std::int64_t> entry;
};

}  // namespace asperity::detail
