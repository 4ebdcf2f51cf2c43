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

// Slots [from, to) of a column set to its padding value.
template <class V>
void pad_column(V& col, std::size_t from, std::size_t to, double pad) {
  std::fill(col.begin() + std::ptrdiff_t(from), col.begin() + std::ptrdiff_t(to),
            static_cast<typename V::value_type>(pad));
}

// New slot i holds old slot order[i]; the slots past `order` keep theirs.
template <class V>
void permute_column(V& col, const std::vector<std::int32_t>& order) {
  V out(col.size());
  for (std::size_t i = 0; i < order.size(); ++i) out[i] = col[order[i]];
  for (std::size_t i = order.size(); i < col.size(); ++i) out[i] = col[i];
  col.swap(out);
}

}  // namespace asperity::detail
