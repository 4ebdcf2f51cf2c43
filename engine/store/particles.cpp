#include "store/particles.hpp"

#include <algorithm>
#include <type_traits>

namespace asperity::detail {

void ParticleStore::resize(std::size_t new_n) {
  const std::size_t cap = round_up(new_n + 2, kMaxLanes);
  slot_columns([&](const ColumnInfo& c, auto& col) {
    if (c.optional && !has_applied) return;
    col.resize(cap);
    pad_column(col, new_n, cap, c.pad);
  }, *this);
  particle_columns([&](const ColumnInfo& c, auto& col) { col.resize(new_n, c.pad); }, *this);
  n = new_n;
  capacity = cap;
  // Null particles: parked 2e10 m apart so a pair of them never overlaps.
  for (std::size_t i = n; i < cap; ++i) x[i] = (i % 2 == 0 ? -1e10 : 1e10) * double(1 + (i - n) / 2);
}

void ParticleStore::permute(const std::vector<std::int32_t>& order) {
  // The double columns, most of the store, all `capacity` long, through one scratch column.
  AVec<double> scratch;
  slot_columns([&](const ColumnInfo& c, auto& col) {
    if (c.optional && !has_applied) return;
    if constexpr (std::is_same_v<std::decay_t<decltype(col)>, AVec<double>>) permute_column(col, order, scratch);
    else permute_column(col, order);
  }, *this);
  particle_columns([&](const ColumnInfo&, auto& col) { permute_column(col, order); }, *this);
  for (std::size_t i = 0; i < n; ++i) index_of_id[id[i]] = static_cast<std::int64_t>(i);
}

}  // namespace asperity::detail
