// Rigid groups between steps: their lazily moved members brought up to date (sync_lazy) and the
// split of lazy groups into busy and idle members redone at every neighbour build (split_idle).
// The step's stage is stages/groups.cpp.
#include <algorithm>
#include <cmath>

#include "bodies/groups.hpp"
#include "bond_list.hpp"
#include "state.hpp"

namespace asperity::detail {

void sync_lazy(State& s) {
  ParticleStore& p = s.p;
  for (Group& g : s.groups) {
    if (!g.inert.empty() && !(g.inert_shift == Vec3{})) {
      const Vec3 d = g.inert_shift;
      for (std::int32_t i : g.inert) {
        p.x[i] += d.x; p.y[i] += d.y; p.z[i] += d.z;
        p.vx[i] = g.velocity.x; p.vy[i] = g.velocity.y; p.vz[i] = g.velocity.z;
      }
    }
    g.inert_shift = {0, 0, 0};
    if (g.lazy && !(g.idle_shift == Vec3{})) {
      const Vec3 d = g.idle_shift;
      for (std::int32_t i : g.members) {
        if (!s.cache.idle[i]) continue;
        p.x[i] += d.x; p.y[i] += d.y; p.z[i] += d.z;
        p.vx[i] = g.velocity.x; p.vy[i] = g.velocity.y; p.vz[i] = g.velocity.z;
      }
      g.idle_base += norm(d);
    }
    g.idle_shift = {0, 0, 0};
  }
}

void split_idle(State& s) {
  sync_lazy(s);
  for (Group& g : s.groups) g.lazy = g.motion.rotation == Dof::fixed && g.angular_velocity == Vec3{};
  // The bonds inside lazy groups leave the step first: a member held only by them is idle. After
  // a break step's merge alone there are none to move (Caches::idle_pairs_only): a group of fixed
  // rotation never turns, so laziness changes only through the API, and a break adds no bond.
  if (!s.cache.idle_pairs_only) settle_frozen_bonds(s);
  s.cache.idle_pairs_only = false;
  ParticleStore& p = s.p;
  s.cache.idle.assign(p.n, 0);
  const Incidence &inc = s.incidence, &binc = s.cache.bond_incidence;
  const WallContacts& wc = s.walls.contacts;
  auto acted_on = [&](std::size_t i) {
    if (inc.start[i + 1] > inc.start[i] || binc.start[i + 1] > binc.start[i] || wc.start[i + 1] > wc.start[i])
      return true;
    return p.has_applied && (p.ax[i] != 0 || p.ay[i] != 0 || p.az[i] != 0);
  };
  for (Group& g : s.groups) {
    g.busy.clear();
    g.idle_mass = 0;
    g.idle_base = 0;
    if (!g.lazy) continue;
    for (std::int32_t i : g.members) {
      if (acted_on(std::size_t(i))) {
        g.busy.push_back(i);
        continue;
      }
      s.cache.idle[i] = 1;
      g.idle_mass += p.mass[i];
      const double dx = p.x[i] - p.x0[i], dy = p.y[i] - p.y0[i], dz = p.z[i] - p.z0[i];
      g.idle_base = std::max(g.idle_base, std::sqrt(dx * dx + dy * dy + dz * dz));
      p.fx[i] = p.fy[i] = p.fz[i] = 0;  // what the gather would give it until the next build
      p.tx[i] = p.ty[i] = p.tz[i] = 0;
    }
  }
  index_moved(s);
}

void index_moved(State& s) {
  const ParticleStore& p = s.p;
  const std::size_t blocks = (p.n + kParticleBlock - 1) / kParticleBlock;
  s.cache.block_free.assign(blocks, 0);
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.group[i] < 0) s.cache.block_free[i / kParticleBlock] = 1;
  Incidence& bb = s.cache.block_busy;
  bb.start.assign(blocks + 1, 0);
  bb.entry.clear();
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    if (!s.cache.block_free[blk])
      for (std::size_t i = blk * kParticleBlock; i < std::min(p.n, (blk + 1) * kParticleBlock); ++i)
        if (!p.inert[i] && !s.cache.idle[i]) bb.entry.push_back(std::int64_t(i));
    bb.start[blk + 1] = std::int32_t(bb.entry.size());
  }
  // The members the group stages move each step (busy ones of lazy groups, all of the others),
  // in slots by group and member order, and the slots by particle block (group_stages).
  s.ctx.moved_particle.clear();
  s.ctx.moved_start.assign(s.groups.size() + 1, 0);
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    const Group& grp = s.groups[g];
    for (std::int32_t i : grp.lazy ? grp.busy : grp.members) s.ctx.moved_particle.push_back(i);
    s.ctx.moved_start[g + 1] = s.ctx.moved_particle.size();
  }
  Incidence& bm = s.ctx.block_moved;
  bm.start.assign(blocks + 1, 0);
  for (std::int32_t i : s.ctx.moved_particle) ++bm.start[std::size_t(i) / kParticleBlock + 1];
  for (std::size_t blk = 0; blk < blocks; ++blk) bm.start[blk + 1] += bm.start[blk];
  bm.entry.assign(s.ctx.moved_particle.size(), 0);
  std::vector<std::int32_t> fill(bm.start.begin(), bm.start.end() - 1);
  for (std::size_t slot = 0; slot < s.ctx.moved_particle.size(); ++slot)
    bm.entry[std::size_t(fill[std::size_t(s.ctx.moved_particle[slot]) / kParticleBlock]++)] = std::int64_t(slot);
  s.cache.idle_valid = true;
}

}  // namespace asperity::detail
