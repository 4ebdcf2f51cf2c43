// How the columns of a store are described. Each store lists its columns once, in a function
// that calls f(info, column of each store given...): resizing, padding, copying, reordering and
// the checkpoint walk that list, so a column added there is carried everywhere.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

namespace asperity::detail {

struct ColumnInfo {
  const char* name;       // in a checkpoint
  double pad = 0;         // in padding slots, and of an entry without history
  bool flips = false;     // a vector of b's side: negated when a and b swap roles
  int since = 1;          // the checkpoint version that added it (older files: all `pad`)
  bool optional = false;  // allocated on first use (ParticleStore::has_applied)
};

// The columns of a contact's history, shared by the pair store and the contact bond of the bond
// store: normal and shear force (vectors on b: they flip), normal force, overlap (padding and
// fresh entries: `overlap_pad`) and rest overlap (since checkpoint version 3).
template <class F, class... Stores>
void contact_columns(F&& f, double overlap_pad, Stores&... q) {
  f(ColumnInfo{"nx", 1, true}, q.nx...);  // a unit normal along x in padding
  f(ColumnInfo{"ny", 0, true}, q.ny...);
  f(ColumnInfo{"nz", 0, true}, q.nz...);
  f(ColumnInfo{"fsx", 0, true}, q.fsx...);
  f(ColumnInfo{"fsy", 0, true}, q.fsy...);
  f(ColumnInfo{"fsz", 0, true}, q.fsz...);
  f(ColumnInfo{"fn", 0}, q.fn...);
  f(ColumnInfo{"overlap", overlap_pad}, q.overlap...);
  f(ColumnInfo{"rest", 0, false, 3}, q.rest...);
}

// Slots [from, to) of a column set to its padding value.
template <class V>
void pad_column(V& col, std::size_t from, std::size_t to, double pad) {
  std::fill(col.begin() + std::ptrdiff_t(from), col.begin() + std::ptrdiff_t(to),
            static_cast<typename V::value_type>(pad));
}

// Slots `rows` (ascending, all below n) taken out of the first n of a column, the others moved
// down in order: segment by segment, so a few rows out of a long column cost one pass of copies.
template <class V>
void remove_slots(V& col, const std::vector<std::size_t>& rows, std::size_t n) {
  if (rows.empty()) return;
  auto to = col.begin() + std::ptrdiff_t(rows[0]);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::size_t from = rows[r] + 1, end = r + 1 < rows.size() ? rows[r + 1] : n;
    to = std::copy(col.begin() + std::ptrdiff_t(from), col.begin() + std::ptrdiff_t(end), to);
  }
}

// New slot i holds old slot order[i]; the slots past `order` keep theirs. Written into `out`,
// which then holds the column's old memory: columns of one size permuted through one `out` take
// turns with its pages instead of each allocating fresh ones.
template <class V>
void permute_column(V& col, const std::vector<std::int32_t>& order, V& out) {
  out.resize(col.size());
  for (std::size_t i = 0; i < order.size(); ++i) out[i] = col[order[i]];
  for (std::size_t i = order.size(); i < col.size(); ++i) out[i] = col[i];
  col.swap(out);
}
template <class V>
void permute_column(V& col, const std::vector<std::int32_t>& order) {
  V out;
  permute_column(col, order, out);
}

}  // namespace asperity::detail
