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

// The flags the bond kernel is chosen by, over the bonds the step computes (dead ones aside).
// Bonds that lost a part: the kernel reads what holds (BondStore::holds).
std::size_t count_partial(const BondStore& q) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < q.n; ++k) n += !q.dead(k) && q.holds[k] != kBothHold;
  return n;
}
// Beam moments: new bonds start without one, and a checkpoint or a break may bring back some.
bool moments_zero(const BondStore& q) {
  for (std::size_t k = 0; k < q.n; ++k)
    if (!q.dead(k) && !kernels::beam_moments_zero(q, k)) return false;
  return true;
}

// The incidence entry of a dead bond: the zero record, with the sign of b (BondStore::zero_record).
std::int64_t zero_entry(const BondStore& q) { return std::int64_t(q.zero_record()) << 1 | 1; }

// Particle i's entry for bond k (`side` 1 where i is its b, 0 where its a) pointed at the zero
// record, in its place: the other entries keep their order, so the gather's sums keep theirs.
void retire_entry(Incidence& inc, std::size_t i, std::size_t k, int side, std::int64_t zero) {
  const std::int64_t mine = std::int64_t(k) << 1 | side;
  for (std::int32_t e = inc.start[i]; e < inc.start[i + 1]; ++e)
    if (inc.entry[std::size_t(e)] == mine) {
      inc.entry[std::size_t(e)] = zero;
      return;
    }
}

// A new bond_version (the bonds' indices or states changed) for a change after which the servo's
// count of bond ends joining two bodies (Caches::servo), if it was current, stays current once
// the ends of the bonds in `gone_ends` (a, b in pairs) are counted out.
void new_bond_version(State& s, const std::vector<std::int64_t>& gone_ends) {
  ServoContacts& servo = s.cache.servo;
  const bool current = servo.bonds_of == s.bond_version;
  ++s.bond_version;
  if (!current) return;
  for (std::size_t e = 0; e < gone_ends.size(); e += 2) servo.count_bond_ends(s.p.group, gone_ends[e], gone_ends[e + 1], -1);
  servo.bonds_of = s.bond_version;
}

// Whether particle i still holds a bond the step computes (an entry not retired).
bool holds_live_bond(const Incidence& inc, std::size_t i, std::int64_t zero) {
  for (std::int32_t e = inc.start[i]; e < inc.start[i + 1]; ++e)
    if (inc.entry[std::size_t(e)] != zero) return true;
  return false;
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
  // Dead bonds (a checkpoint keeps them, as the run that wrote it did until its next build): their
  // entries retired in place, as the breaks that made them did (refresh_bond_topology_after_breaks).
  s.cache.dead_bonds.clear();
  const std::int64_t zero = zero_entry(q);
  for (std::size_t k = 0; k < q.n; ++k)
    if (q.dead(k)) {
      s.cache.dead_bonds.push_back(k);
      retire_entry(s.cache.bond_incidence, std::size_t(q.a[k]), k, 0, zero);
      retire_entry(s.cache.bond_incidence, std::size_t(q.b[k]), k, 1, zero);
    }
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
  s.cache.bond_held.assign(p.n, 0);
  for (std::size_t i = 0; i < p.n; ++i)
    if (holds_live_bond(s.cache.bond_incidence, i, zero)) {
      s.cache.bond_held[i] = 1;
      s.cache.bonded_particles.push_back(std::int32_t(i));
    }
  s.cache.partial_bonds = count_partial(q);
  s.cache.bonds_partial = s.cache.partial_bonds > 0;
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
  BondStore& q = s.bonds;
  Caches& c = s.cache;
  new_bond_version(s, losses.gone_ends);  // the dead bonds' ends leave the servo's count
  c.spin_known = false;
  if (!losses.gone.empty()) {
    // The bonds of which nothing holds stay in their slots, dead (BondStore::dead), until the next
    // neighbour build takes them out (compact_bonds): their entries point at the zero record.
    const std::int64_t zero = zero_entry(q);
    for (std::size_t g = 0; g < losses.gone.size(); ++g) {
      const std::size_t k = losses.gone[g];
      const auto a = std::size_t(losses.gone_ends[2 * g]), b = std::size_t(losses.gone_ends[2 * g + 1]);
      retire_entry(c.bond_incidence, a, k, 0, zero);
      retire_entry(c.bond_incidence, b, k, 1, zero);
      drop_partner(c, a, std::int32_t(b));
      drop_partner(c, b, std::int32_t(a));
      c.dead_bonds.push_back(k);
    }
    // A particle whose last computed bond went leaves the bonded particles.
    for (const auto i : losses.gone_ends) {
      const auto k = std::size_t(i);
      if (!c.bond_held[k] || holds_live_bond(c.bond_incidence, k, zero)) continue;
      c.bond_held[k] = 0;
      const auto at = std::lower_bound(c.bonded_particles.begin(), c.bonded_particles.end(), std::int32_t(k));
      c.bonded_particles.erase(at);
    }
  }
  // A break only takes parts and moments away: the flags are looked for again only where that
  // may have changed them (process_breaks keeps the count of partial bonds).
  c.bonds_partial = c.partial_bonds > 0;
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
      if (c.bond_held[k] && particle_turns(s, k)) c.bond_ends_turn = true;
    }
}

void compact_bonds(State& s) {
  Caches& c = s.cache;
  if (c.dead_bonds.empty()) return;
  BondStore& q = s.bonds;
  std::sort(c.dead_bonds.begin(), c.dead_bonds.end());
  q.remove(c.dead_bonds);
  q.fill_padding(s.p.null_a(), s.p.null_b());
  c.dead_bonds.clear();
  // The same incidence as the breaks' retired one without its retired entries: every other count
  // and flag of the bonds (bonded particles, partners, partial bonds, locks) is already current.
  build_incidence(s.p.n, q.a.data(), q.b.data(), q.n, c.bond_incidence);
  new_bond_version(s, {});  // bond indices moved; the servo's count of bond ends stays
}

}  // namespace asperity::detail
