// World: measurements (stresses, energies, contact summaries, overlaps).
// Every function checks its input and says what was wrong (world_checks.hpp).
#include "asperity/world.hpp"

#include <algorithm>
#include <cmath>

#include "state.hpp"
#include "step.hpp"

#include "world_checks.hpp"

namespace asperity {

using detail::Change;
using detail::changed;
using detail::State;

using namespace world_checks;

// --- measurements --------------------------------------------------------------------------

// After a step nothing the energies need waits in the lazily moved members (the kinetic energy
// was summed by the step, the rest is in the stores and the ledger): reading them does not bring
// the members up to date, which would change how their moves are rounded, and so the run.
Energies World::energies() const {
  return detail::compute_energies(state_->kinetic_valid ? *state_ : synced(*state_));
}

double World::unbalanced_force_ratio() const {
  const State& s = *state_;
  const auto& p = s.p;
  const Vec3 g = s.settings.gravity;
  double unbalanced = 0;
  std::size_t bodies = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.group[i] >= 0) continue;
    const double fx = p.fx[i] + p.mass[i] * g.x, fy = p.fy[i] + p.mass[i] * g.y,
                 fz = p.fz[i] + p.mass[i] * g.z;
    unbalanced += std::sqrt(fx * fx + fy * fy + fz * fz);
    ++bodies;
  }
  double contact = 0;
  std::size_t contacts = 0;
  for (std::size_t k = 0; k < s.pairs.n; ++k)
    if (s.pairs.overlap_at(k) > 0) { contact += s.pairs.normal_force(k); ++contacts; }
  for (std::size_t k = 0; k < s.walls.contacts.n; ++k)
    if (s.walls.contacts.overlap[k] > 0) { contact += s.walls.contacts.fn[k]; ++contacts; }
  // Intact bonds carry contact force too, in tension as well: |contact bond + parallel bond|.
  for (std::size_t k = 0; k < s.bonds.n; ++k) {
    if (s.bonds.dead(k)) continue;
    contact += std::abs(s.bonds.fn[k] + s.bonds.fbn[k]);
    ++contacts;
  }
  if (bodies == 0) return 0;
  // Nothing pushes and nothing is unbalanced (a specimen bonded stress-free): at rest.
  if (contacts == 0 || contact == 0) return unbalanced == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  return (unbalanced / double(bodies)) / (contact / double(contacts));
}

std::vector<ContactInfo> World::contacts() const {
  const State& s = *state_;
  const auto& p = s.p;
  const auto& q = s.pairs;
  std::vector<ContactInfo> out;
  for (std::size_t k = 0; k < q.n; ++k) {
    if (!(q.overlap_at(k) > 0)) continue;
    const auto a = q.a[k], b = q.b[k];
    ContactInfo c;
    c.id_a = p.id[a];
    c.id_b = p.id[b];
    c.normal = {q.nx[k], q.ny[k], q.nz[k]};
    c.overlap = q.overlap_at(k);
    c.point = Vec3{p.x[a], p.y[a], p.z[a]} + c.normal * (p.radius[a] - 0.5 * c.overlap);  // [3-11]
    c.normal_force = q.normal_force(k);
    c.shear_force = {q.fsx[k], q.fsy[k], q.fsz[k]};
    if (c.id_a > c.id_b) {  // report with id_a < id_b: flip the roles
      std::swap(c.id_a, c.id_b);
      c.normal = -c.normal;
      c.shear_force = -c.shear_force;
    }
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const ContactInfo& u, const ContactInfo& v) {
    return u.id_a != v.id_a ? u.id_a < v.id_a : u.id_b < v.id_b;
  });
  return out;
}

double World::max_overlap_ratio(bool turning_only) const {
  return detail::deepest_overlap(*state_, turning_only).ratio;
}

std::size_t World::contact_count() const {
  const auto& q = state_->pairs;
  std::size_t c = 0;
  for (std::size_t k = 0; k < q.n; ++k) c += q.overlap_at(k) > 0;
  return c;
}

}  // namespace asperity
