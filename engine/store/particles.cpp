#include "store/particles.hpp"

#include <algorithm>

namespace asperity::detail {

namespace {
template <class V>
void permute_column(V& col, const std::vector<std::int32_t>& order) {
  V out(col.size());
  for (std::size_t i = 0; i < order.size(); ++i) out[i] = col[order[i]];
  for (std::size_t i = order.size(); i < col.size(); ++i) out[i] = col[i];
  col.swap(out);
}
}  // namespace

void ParticleStore::resize(std::size_t new_n) {
  std::size_t cap = round_up(new_n + 2, kMaxLanes);
  auto grow = [&](auto& col, auto fill) { col.resize(cap, fill); };
  for (auto* c : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass, &inertia,
                  &inv_inertia, &fx, &fy, &fz, &tx, &ty, &tz, &x0, &y0, &z0})
    grow(*c, 0.0);
  if (has_applied)
    for (auto* c : {&ax, &ay, &az}) grow(*c, 0.0);
  density.resize(new_n, 0.0);
  rotation_locked.resize(cap, 1);
  group.resize(cap, -1);
  tag.resize(cap, 0);
  flags.resize(cap, 0);
  inert.resize(cap, 0);
  id.resize(cap, -1);
  n = new_n;
  capacity = cap;
  // Null particles: everything zero, parked 2e10 m apart so a pair of them never overlaps.
  for (std::size_t i = n; i < cap; ++i) {
    x[i] = (i % 2 == 0 ? -1e10 : 1e10) * double(1 + (i - n) / 2);
    y[i] = z[i] = 0;
    vx[i] = vy[i] = vz[i] = wx[i] = wy[i] = wz[i] = 0;
    radius[i] = mass[i] = inv_mass[i] = inertia[i] = inv_inertia[i] = 0;
    rotation_locked[i] = 1;
    group[i] = -1;
    tag[i] = 0;
    flags[i] = 0;
    inert[i] = 0;
    id[i] = -1;
  }
}

void ParticleStore::permute(const std::vector<std::int32_t>& order) {
  for (auto* c : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass, &inertia,
                  &inv_inertia, &fx, &fy, &fz, &tx, &ty, &tz, &x0, &y0, &z0})
    permute_column(*c, order);
  if (has_applied)
    for (auto* c : {&ax, &ay, &az}) permute_column(*c, order);
  permute_column(density, order);
  permute_column(rotation_locked, order);
  permute_column(group, order);
  permute_column(tag, order);
  permute_column(flags, order);
  permute_column(inert, order);
  permute_column(id, order);
  for (std::size_t i = 0; i < n; ++i) index_of_id[id[i]] = static_cast<std::int64_t>(i);
}

}  // namespace asperity::detail
