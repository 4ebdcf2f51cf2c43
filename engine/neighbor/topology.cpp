// Who is bonded to whom (neighbor/topology.hpp).
#include "neighbor/topology.hpp"

#include <algorithm>
#include <vector>

#include "kernels/bond_law.hpp"
#include "neighbor/build.hpp"

namespace asperity::detail {

namespace {

// Rotation locks [thesis 3.3]: "restricting the particle rotation when they are bonded together";
// how far the restriction goes is the calibration's choice (model.md 2). A particle none of whose
// bonds has broken does not rotate; a damaged one stays locked while it holds rotation_lock_bonds
// intact bonds. So the lock holds while intact >= min(rotation_lock_bonds, installed): damage
// frees the inside of the material (compression softens, scenarios.md 2.5), and an intact
// particle with few bonds, as on a joint's face, stays locked until it is damaged.
// Which bonds count (model.md 5): a pair either part of which holds (`listed`, the partners), or
// with rotation_lock_beams only those whose parallel bond holds; installed = listed + fully broken.
// Returns whether particle i is locked now.
bool set_lock(State& s, std::size_t i, std::int64_t listed) {
  ParticleStore& p = s.p;
  const std::int64_t intact = s.settings.rotation_lock_beams ? s.cache.beam_count[i] : listed;
  const std::int64_t needed = std::min<std::int64_t>(s.settings.rotation_lock_bonds, listed + p.bonds_broken[i]);
  const bool bonded = intact >= 1 && intact >= needed;
  const bool locked = !s.settings.rotation || p.user_rotation_locked[i] ||
                      (s.settings.lock_bonded_rotation && bonded);
  if (locked && !p.rotation_locked[i]) p.wx[i] = p.wy[i] = p.wz[i] = 0;
  p.rotation_locked[i] = locked ? 1 : 0;
  return locked;
}

// The partners of particle i still listed (its run ends in kNoPartner slots after breaks).
std::int64_t listed_partners(const Caches& c, std::size_t i) {
  const auto first = c.partners.begin() + c.partner_start[i], last = c.partners.begin() + c.partner_start[i + 1];
  return std::lower_bound(first, last, kNoPartner) - first;
}

// Partner o taken out of i's run: the ones above it move down, an empty slot closes the run.
void drop_partner(Caches& c, std::size_t i, std::int32_t o) {
  const auto first = c.partners.begin() + c.partner_start[i], last = c.partners.begin() + c.partner_start[i + 1];
  const auto at = std::lower_bound(first, last, o);
  std::copy(at + 1, last, at);
  *(last - 1) = kNoPartner;
}

// The flags the bond kernel is chosen by, over the bonds the step computes.
// Some bond lost a part: the kernel reads what holds (BondStore::holds).
bool any_partial(const BondStore& q) {
  for (std::size_t k = 0; k < q.n; ++k)
    if (q.holds[k] != kBothHold) return true;
  return false;
}
// Beam moments: new bonds start without one, and a checkpoint or a break may bring back some.
bool moments_zero(const BondStore& q) {
  for (std::size_t k = 0; k < q.n; ++k)
    if (!kernels::beam_moments_zero(q, k)) return false;
  return true;
}

}  // namespace

void refresh_bond_topology(State& s) {
  ParticleStore& p = s.p;
  BondStore& q = s.bonds;
  q.fill_padding(p.null_a(), p.null_b());
  s.frozen_bonds.fill_padding(p.null_a(), p.null_b());
  ++s.bond_version;
  s.cache.spin_known = false;  // the bonded particles changed (State::spin_known)
  s.cache.bond_ends_turn_known = false;  // and their locks
  // The gather's incidence: the bonds the step computes. Partners and rotation locks: every bond
  // (a frozen one still ties its particles).
  build_incidence(p.n, q.a.data(), q.b.data(), q.n, s.cache.bond_incidence);
  s.cache.partner_start.assign(p.n + 1, 0);
  for_each_bond(s, [&](const BondStore& b, std::size_t k) {
    ++s.cache.partner_start[b.a[k] + 1];
    ++s.cache.partner_start[b.b[k] + 1];
  });
  for (std::size_t i = 0; i < p.n; ++i) s.cache.partner_start[i + 1] += s.cache.partner_start[i];
  s.cache.partners.resize(std::size_t(s.cache.partner_start[p.n]));
  std::vector<std::int32_t> fill(s.cache.partner_start.begin(), s.cache.partner_start.end() - 1);
  for_each_bond(s, [&](const BondStore& b, std::size_t k) {
    s.cache.partners[fill[b.a[k]]++] = std::int32_t(b.b[k]);
    s.cache.partners[fill[b.b[k]]++] = std::int32_t(b.a[k]);
  });
  for (std::size_t i = 0; i < p.n; ++i)
    std::sort(s.cache.partners.begin() + s.cache.partner_start[i], s.cache.partners.begin() + s.cache.partner_start[i + 1]);
  s.cache.bonded_particles.clear();  // what the bond stage reads: the ends of the bonds it computes
  for (std::size_t i = 0; i < p.n; ++i)
    if (s.cache.bond_incidence.start[i + 1] > s.cache.bond_incidence.start[i]) s.cache.bonded_particles.push_back(std::int32_t(i));
  s.cache.bonds_partial = any_partial(q);
  s.cache.bond_moments_zero = moments_zero(q);
  s.cache.beam_count.clear();
  if (s.settings.rotation_lock_beams) {
    s.cache.beam_count.assign(p.n, 0);
    for_each_bond(s, [&](const BondStore& b, std::size_t k) {
      if (static_cast<int>(b.holds[k]) & int(kBeamHolds)) {
        ++s.cache.beam_count[b.a[k]];
        ++s.cache.beam_count[b.b[k]];
      }
    });
  }
  s.any_rotating = false;
  for (std::size_t i = 0; i < p.n; ++i)
    s.any_rotating = !set_lock(s, i, s.cache.partner_start[i + 1] - s.cache.partner_start[i]) || s.any_rotating;
}

void refresh_bond_topology_after_breaks(State& s, const BondLosses& losses) {
  if (losses.gone.empty() && losses.beam_ends.empty() && !losses.partial_left) return;
  ParticleStore& p = s.p;
  BondStore& q = s.bonds;
  Caches& c = s.cache;
  q.fill_padding(p.null_a(), p.null_b());  // frozen bonds never break
  ++s.bond_version;
  c.spin_known = false;
  if (!losses.gone.empty()) {
    build_incidence(p.n, q.a.data(), q.b.data(), q.n, c.bond_incidence);
    for (std::size_t e = 0; e < losses.gone_ends.size(); e += 2) {
      const auto a = std::size_t(losses.gone_ends[e]), b = std::size_t(losses.gone_ends[e + 1]);
      drop_partner(c, a, std::int32_t(b));
      drop_partner(c, b, std::int32_t(a));
    }
    // A particle whose last computed bond went leaves the bonded particles.
    std::erase_if(c.bonded_particles, [&](std::int32_t i) {
      return c.bond_incidence.start[std::size_t(i) + 1] == c.bond_incidence.start[std::size_t(i)];
    });
  }
  // A break only takes parts and moments away: the flags are looked for again only where that
  // may have changed them.
  if (c.bonds_partial && !losses.gone.empty()) c.bonds_partial = any_partial(q);
  else c.bonds_partial = c.bonds_partial || losses.partial_left;
  if (!c.bond_moments_zero) c.bond_moments_zero = moments_zero(q);
  if (s.settings.rotation_lock_beams)
    for (const auto i : losses.beam_ends) --c.beam_count[std::size_t(i)];
  // A break only frees particles (fewer intact bonds, as many installed): any_rotating can only
  // become true, and only the ends of the broken bonds can change.
  for (const auto* ends : {&losses.gone_ends, &losses.beam_ends})
    for (const auto i : *ends) {
      const auto k = std::size_t(i);
      s.any_rotating = !set_lock(s, k, listed_partners(c, k)) || s.any_rotating;
      // An end freed while it still holds a bond the step computes: its records need the levers.
      if (c.bond_incidence.start[k + 1] > c.bond_incidence.start[k] && particle_turns(s, k)) c.bond_ends_turn = true;
    }
}

}  // namespace asperity::detail
