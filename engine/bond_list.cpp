// The bond list's whole life: installed, broken (an event each, the released strain energy, the
// contact a broken bond leaves behind, compaction of the list and the rotation locks), frozen
// inside rigid bodies and thawed, removed.
#include <algorithm>
#include <cmath>

#include "bond_list.hpp"
#include "kernels/bond_law.hpp"
#include "neighbor/build.hpp"
#include "neighbor/topology.hpp"

namespace asperity::detail {

namespace {
// The contact springs of bond k as an ordinary contact (model.md 4) from now on: Fn = kn (U - rest)
// >= 0 and Fs capped at mu Fn while the pair touches, nothing once it does not. Returns the
// strain energy they keep and gives the factor of the cap on Fs (0 once apart).
double kept_as_contact(const BondStore& q, std::size_t k, const ContactMaterial& m, double& fn,
                       double& fs_scale) {
  fn = 0;
  fs_scale = 0;
  if (!(q.overlap[k] > 0)) return 0;
  fn = std::max(q.fn[k], 0.0);
  const double fs2 = q.fsx[k] * q.fsx[k] + q.fsy[k] * q.fsy[k] + q.fsz[k] * q.fsz[k];
  const double limit = m.friction * fn, fs = std::sqrt(fs2);
  fs_scale = fs > limit ? limit / fs : 1.0;
  return kernels::contact_spring_energy(fn, fs2 * fs_scale * fs_scale, m.kn, m.ks);
}
}  // namespace



BondStore merge_bonds(const BondStore& x, const BondStore& y) {
  BondStore out;
  out.resize(x.n + y.n);
  std::size_t i = 0, j = 0;
  for (std::size_t k = 0; k < out.n; ++k) {
    const bool from_x = j >= y.n || (i < x.n && (x.a[i] != y.a[j] ? x.a[i] < y.a[j] : x.b[i] < y.b[j]));
    if (from_x) out.copy_from(x, i++, k);
    else out.copy_from(y, j++, k);
  }
  return out;
}

BondStore all_bonds(const State& s) {
  BondStore all = merge_bonds(s.bonds, s.frozen_bonds);
  all.material = s.bonds.material;
  all.any = s.bonds.any;
  return all;
}

bool settle_frozen_bonds(State& s) {
  const ParticleStore& p = s.p;
  auto frozen_here = [&](std::int64_t a, std::int64_t b) {
    const std::int32_t g = p.group[std::size_t(a)];
    return g >= 0 && g == p.group[std::size_t(b)] && s.groups[std::size_t(g)].lazy;
  };
  // A dead bond (BondStore::dead) stays where it is until compact_bonds takes it out.
  auto goes_frozen = [&](const BondStore& q, std::size_t k) { return !q.dead(k) && frozen_here(q.a[k], q.b[k]); };
  std::size_t to_freeze = 0, to_thaw = 0;
  for (std::size_t k = 0; k < s.bonds.n; ++k) to_freeze += goes_frozen(s.bonds, k);
  for (std::size_t k = 0; k < s.frozen_bonds.n; ++k)
    to_thaw += !frozen_here(s.frozen_bonds.a[k], s.frozen_bonds.b[k]);
  if (to_freeze == 0 && to_thaw == 0) return false;
  // Split each store into the bonds that stay and the ones that move, then merge: both stores stay
  // sorted by (a, b), so the partition is the same whatever the history (checkpoints hold one list).
  BondStore stores[2][2];  // [from active, from frozen][stays active, goes frozen]
  const BondStore* from[2] = {&s.bonds, &s.frozen_bonds};
  for (int f = 0; f < 2; ++f) {
    const BondStore& q = *from[f];
    std::size_t count[2] = {0, 0};
    for (std::size_t k = 0; k < q.n; ++k) ++count[goes_frozen(q, k)];
    for (int t = 0; t < 2; ++t) stores[f][t].resize(count[t]);
    std::size_t at[2] = {0, 0};
    for (std::size_t k = 0; k < q.n; ++k) {
      const int t = goes_frozen(q, k);
      stores[f][t].copy_from(q, k, at[t]++);
    }
  }
  const BondMaterial material = s.bonds.material;
  const bool any = s.bonds.any;
  s.bonds = merge_bonds(stores[0][0], stores[1][0]);
  s.frozen_bonds = merge_bonds(stores[0][1], stores[1][1]);
  for (BondStore* q : {&s.bonds, &s.frozen_bonds}) {
    q->material = material;
    q->any = any;
  }
  refresh_bond_topology(s);
  return true;
}

void process_breaks(State& s) {
  BondStore& q = s.bonds;
  double any = 0;
  for (double b : s.ctx.bond_block_breaks) any += b;
  if (any == 0) {
    s.ctx.bond_block_breaks.clear();
    return;
  }
  // Only the bond stage's blocks that flagged a break are looked at (bond_stage's blocks).
  const std::vector<double>& block_breaks = s.ctx.bond_block_breaks;
  const std::size_t block = pair_block_size(q.padded);
  const ParticleStore& p = s.p;
  // The broken bonds are handled in place; those of which nothing holds any more stay in their
  // slots, dead, until the next neighbour build (compact_bonds): a break step does no pass over
  // the whole bond list.
  BondLosses losses;
  // The freed pairs (bonds of which nothing holds any more), in bond order (sorted by (a, b) like
  // the bond list they come from), made while the bond's slot is still intact. A touching one
  // keeps the contact's normal and shear force capped at the friction limit; the others start as
  // the search starts a new pair (no shear force, the current direction as the previous normal).
  PairStore& freed = s.cache.freed_pairs;
  std::size_t nfreed = 0;
  const ContactMaterial& m = s.settings.contact;
  const BondMaterial& bm = q.material;
  const bool with_beam = bm.contact_strength == 0;
  for (std::size_t k = 0; k < q.n; ++k) {
    if (block_breaks[k / block] == 0) {  // none in this block: on to the next
      k = (k / block + 1) * block - 1;
      continue;
    }
    if (q.broken[k] == 0) continue;
    const auto parts = static_cast<int>(q.broken[k]);
    const int held = static_cast<int>(q.holds[k]);
    const int holds = held & ~parts;
    const auto a = q.a[k], b = q.b[k];
    const Vec3 n{q.nx[k], q.ny[k], q.nz[k]};
    BreakEvent ev;
    ev.step = s.step;
    ev.time = s.time;
    ev.position = Vec3{p.x[a], p.y[a], p.z[a]} + n * (p.radius[a] - 0.5 * q.overlap[k]);
    ev.id_a = p.id[a];
    ev.id_b = p.id[b];
    auto book = [&](double released) {
      ev.released_energy = released;
      if (s.settings.track_energy) s.ledger.released += released;
      s.break_events.push_back(ev);
    };
    // What the contact springs keep when the contact bond goes: an ordinary contact's forces.
    double fn_kept = 0, fs_scale = 0, spring_kept = 0;
    const bool contact_goes = (parts & int(kContactBondHolds)) != 0;
    if (contact_goes) spring_kept = kept_as_contact(q, k, m, fn_kept, fs_scale);
    if (parts & int(kBeamHolds)) {
      // Mode: the stress closest (relative to its own failure value: st in tension, 10 st in
      // compression, 5 st in shear) to failing on its own dominates.
      kernels::beam_stresses(q, k, ev.sigma, ev.tau);
      const double st = bm.tensile_strength;
      const double normal_part = ev.sigma >= 0 ? ev.sigma / st : -ev.sigma / (10 * st);
      const double shear_part = ev.tau / (5 * st);
      ev.mode = shear_part > normal_part ? BreakEvent::Mode::shear
                : (ev.sigma >= 0 ? BreakEvent::Mode::tension : BreakEvent::Mode::compression);
      ev.kind = BreakEvent::Kind::beam;
      // Breaking with the beam, the contact bond's lost energy is the beam event's too.
      const double contact_part = with_beam ? kernels::spring_energy(q, k, m) - spring_kept : 0.0;
      book(kernels::beam_energy(q, k, bm) + contact_part);
      kernels::unload_beam(q, k);
      losses.beam_ends.push_back(a);
      losses.beam_ends.push_back(b);
    }
    if (contact_goes && !with_beam) {
      const double rb = q.beam_radius[k], A = kernels::kPi * rb * rb;
      const double fs = std::sqrt(q.fsx[k] * q.fsx[k] + q.fsy[k] * q.fsy[k] + q.fsz[k] * q.fsz[k]);
      ev.sigma = -q.fn[k] / A;
      ev.tau = fs / A;
      double fcn, fcs;  // the kernel's verdict: tension where the tension reached Fcn, else shear
      kernels::contact_bond_strengths(bm.tensile_strength, rb, bm.contact_strength, bm.contact_shear_strength,
                                      bm.contact_bond_friction, q.fn[k], fcn, fcs);
      ev.mode = kernels::contact_bond_failure(q.fn[k], q.fsx[k], q.fsy[k], q.fsz[k], fcn, fcs) == 1.0
                    ? BreakEvent::Mode::tension : BreakEvent::Mode::shear;
      ev.kind = BreakEvent::Kind::contact_bond;
      book(kernels::spring_energy(q, k, m) - spring_kept);
    }
    if (contact_goes) {  // the springs become an ordinary contact's (the kernel's law from now on)
      q.fn[k] = fn_kept;
      q.fsx[k] *= fs_scale; q.fsy[k] *= fs_scale; q.fsz[k] *= fs_scale;
    }
    q.broken[k] = 0;
    if (holds != 0) {  // the other part holds: the bond stays, with what is left of it
      q.holds[k] = holds;
      losses.partial_left = true;
      if (held == int(kBothHold)) ++s.cache.partial_bonds;
      continue;
    }
    if (held != int(kBothHold)) --s.cache.partial_bonds;
    // Dead (BondStore::dead): the kernel neither acts nor breaks on a bond of zero radius.
    q.holds[k] = 0;
    q.beam_radius[k] = 0;
    losses.gone.push_back(k);
    losses.gone_ends.push_back(a);
    losses.gone_ends.push_back(b);
    ++s.p.bonds_broken[a];
    ++s.p.bonds_broken[b];
    // The pair enters the contact list now (the search never listed it while it was bonded),
    // unless the search never would: two members of one rigid group, or an inert particle.
    const bool listed = !p.inert[a] && !p.inert[b] && (p.group[a] < 0 || p.group[a] != p.group[b]);
    if (!listed) continue;
    const std::size_t t = nfreed++;
    if (t >= freed.n) freed.resize(std::max<std::size_t>(16, 2 * freed.n));
    freed.a[t] = q.a[k]; freed.b[t] = q.b[k];
    freed.overlap[t] = q.overlap[k];
    if (q.overlap[k] > 0) {
      // Keeps the contact's normal and shear force (capped at the friction limit above, or as
      // the ordinary contact law left them).
      freed.nx[t] = q.nx[k]; freed.ny[t] = q.ny[k]; freed.nz[t] = q.nz[k];
      freed.fsx[t] = q.fsx[k]; freed.fsy[t] = q.fsy[k]; freed.fsz[t] = q.fsz[k];
      freed.fn[t] = q.fn[k];
      // A stress-free bond's contact stays unloaded at its rest overlap; a gap bond's (rest < 0)
      // becomes an ordinary contact, which never pulls.
      freed.rest[t] = std::max(q.rest[k], 0.0);
    } else {
      start_pair(freed, t, p);  // the overlap stays the bond's last, as for a touching one
    }
  }
  freed.resize(nfreed);
  s.ctx.bond_block_breaks.clear();
  refresh_bond_topology_after_breaks(s, losses);
  // Into the pair list without a rebuild: a fracture run breaks bonds on most of its steps, and a
  // rebuild for each would rebuild the list (and reorder the particles) nearly every step.
  insert_pairs(s, freed);
}

std::size_t install_bonds(State& s, const BondMaterial& material, double tolerance,
                          std::span<const std::int64_t> ids, bool stress_free) {
  auto& p = s.p;
  // Candidates come from the neighbour list; make sure it is current and reaches the tolerance.
  // (The skin is derived first: a world never built has none yet, and 2 x tolerance alone, about
  // 1e-3 R, would leave it rebuilding the list at every step.)
  ensure_skin(s);
  if (s.skin < 2 * tolerance) s.skin = 2 * tolerance;
  build_neighbors(s);
  // The bonds' store is made beside the pair list, not beside its spares too (a genesis's, kept
  // at its widest list: its peak memory); the relaxation's builds make them again at their size.
  release_spares(s);
  // The chosen particles by index after the build: it may have reordered the store (marked
  // before it, other particles were bonded: across the mould of the 4 cm joint).
  std::vector<std::uint8_t> chosen(p.n, ids.empty() ? 1 : 0);
  for (auto id : ids) chosen[std::size_t(s.p.index_of_id[std::size_t(id)])] = 1;
  const auto& q = s.pairs;
  std::vector<std::size_t> picked;
  for (std::size_t k = 0; k < q.n; ++k) {
    const auto a = q.a[k], b = q.b[k];
    if (!chosen[a] || !chosen[b]) continue;
    const double dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
    const double gap = std::sqrt(dx * dx + dy * dy + dz * dz) - p.radius[a] - p.radius[b];
    if (gap <= tolerance) picked.push_back(k);
  }
  // The new bonds, in the pair list's (a, b) order, merged into the sorted bond list.
  BondStore fresh;
  fresh.resize(picked.size());
  for (std::size_t k = 0; k < picked.size(); ++k) {
    const std::size_t c = picked[k];
    const auto a = q.a[c], b = q.b[c];
    const double dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    fresh.a[k] = a;
    fresh.b[k] = b;
    fresh.beam_radius[k] = material.radius_factor * std::min(p.radius[a], p.radius[b]);  // [3-26]
    fresh.nx[k] = dx / d; fresh.ny[k] = dy / d; fresh.nz[k] = dz / d;
    // An existing contact's forces are kept by the contact bond (model.md 5); stress-free, the
    // contact bond is unloaded at the current overlap instead. The beam starts unloaded.
    fresh.fsx[k] = stress_free ? 0.0 : q.fsx[c];
    fresh.fsy[k] = stress_free ? 0.0 : q.fsy[c];
    fresh.fsz[k] = stress_free ? 0.0 : q.fsz[c];
    fresh.overlap[k] = p.radius[a] + p.radius[b] - d;
    fresh.rest[k] = stress_free ? fresh.overlap[k] : 0.0;
    fresh.fn[k] = s.settings.contact.kn * (fresh.overlap[k] - fresh.rest[k]);
    kernels::unload_beam(fresh, k);
    fresh.broken[k] = 0;
    fresh.holds[k] = kBothHold;
  }
  // The first installation (the genesis's) takes the new store as the list: a merge would hold a
  // second store of the bonds' size at once (10 cm: 345 000 bonds, about 100 MB).
  if (s.bonds.n == 0) s.bonds = std::move(fresh);
  else s.bonds = merge_bonds(s.bonds, fresh);
  fresh = BondStore();
  s.bonds.material = material;
  s.bonds.any = true;
  s.frozen_bonds.material = material;
  s.frozen_bonds.any = true;
  if (stress_free && !picked.empty()) s.rest_overlaps = true;
  refresh_bond_topology(s);
  return picked.size();
}

void remove_bonds(State& s) {
  s.bonds.resize(0);
  s.frozen_bonds.resize(0);
  s.p.bonds_broken.assign(s.p.n, 0);  // no bond left, none counts as broken
  refresh_bond_topology(s);
}

}  // namespace asperity::detail
