// Who is bonded to whom (neighbor/topology.hpp).
#include "neighbor/topology.hpp"

#include <algorithm>
#include <vector>

#include "kernels/bond_law.hpp"
#include "neighbor/build.hpp"

namespace asperity::detail {

void refresh_bond_topology(State& s) {
  ParticleStore& p = s.p;
  BondStore& q = s.bonds;
  q.fill_padding(p.null_a(), p.null_b());
  s.frozen_bonds.fill_padding(p.null_a(), p.null_b());
  ++s.bond_version;
  s.cache.spin_known = false;  // the bonded particles changed (State::spin_known)
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
  // Some bond lost a part: the kernel reads what holds (BondStore::holds).
  s.cache.bonds_partial = false;
  for (std::size_t k = 0; k < q.n && !s.cache.bonds_partial; ++k) s.cache.bonds_partial = q.holds[k] != kBothHold;
  // Beam moments: new bonds start without one, and a checkpoint or a break may bring back some.
  s.cache.bond_moments_zero = true;
  for (std::size_t k = 0; k < q.n && s.cache.bond_moments_zero; ++k)
    s.cache.bond_moments_zero = kernels::beam_moments_zero(q, k);
  // Rotation locks [thesis 3.3]: "restricting the particle rotation when they are bonded together";
  // how far the restriction goes is the calibration's choice (model.md 2). A particle none of whose
  // bonds has broken does not rotate; a damaged one stays locked while it holds rotation_lock_bonds
  // intact bonds. So the lock holds while intact >= min(rotation_lock_bonds, installed): damage
  // frees the inside of the material (compression softens, scenarios.md 2.5), and an intact
  // particle with few bonds, as on a joint's face, stays locked until it is damaged.
  // Which bonds count (model.md 5): a pair either part of which holds (the partners), or with
  // rotation_lock_beams only those whose parallel bond holds; installed = listed + fully broken.
  std::vector<std::int32_t> beams;
  if (s.settings.rotation_lock_beams) {
    beams.assign(p.n, 0);
    for_each_bond(s, [&](const BondStore& b, std::size_t k) {
      if (static_cast<int>(b.holds[k]) & int(kBeamHolds)) {
        ++beams[b.a[k]];
        ++beams[b.b[k]];
      }
    });
  }
  s.any_rotating = false;
  for (std::size_t i = 0; i < p.n; ++i) {
    const std::int64_t listed = s.cache.partner_start[i + 1] - s.cache.partner_start[i];
    const std::int64_t intact = s.settings.rotation_lock_beams ? beams[i] : listed;
    const std::int64_t needed = std::min<std::int64_t>(s.settings.rotation_lock_bonds, listed + p.bonds_broken[i]);
    const bool bonded = intact >= 1 && intact >= needed;
    const bool locked = !s.settings.rotation || p.user_rotation_locked[i] ||
                        (s.settings.lock_bonded_rotation && bonded);
    if (locked && !p.rotation_locked[i]) p.wx[i] = p.wy[i] = p.wz[i] = 0;
    p.rotation_locked[i] = locked ? 1 : 0;
    s.any_rotating = s.any_rotating || !locked;
  }
}

}  // namespace asperity::detail
