// World: bonds (installed, strength set, removed, read) (model.md 5).
// Every function checks its input and says what was wrong (world_checks.hpp).
#include "asperity/world.hpp"

#include <algorithm>

#include "kernels/bond_law.hpp"
#include "bond_list.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"
#include "step.hpp"

#include "world_checks.hpp"

namespace asperity {

using detail::Change;
using detail::changed;
using detail::State;

using namespace world_checks;

// --- bonds ---------------------------------------------------------------------------------

std::size_t World::install_bonds(const BondMaterial& given, double tolerance,
                                 std::span<const std::int64_t> ids, bool stress_free) {
  State& s = *state_;
  check_value("install_bonds: ", Field{"bond material"}, given);
  BondMaterial material = given;  // the beam's stiffness left at 0: the contact springs' (model.md 5)
  if (material.beam_kn == 0) material.beam_kn = s.settings.contact.kn;
  if (material.beam_ks == 0) material.beam_ks = material.beam_kn / 10;
  const std::string problem = detail::bond_material_problem(material);
  require(problem.empty(), "install_bonds: " + problem);
  if (s.bonds.n - s.cache.dead_bonds.size() + s.frozen_bonds.n > 0)  // dead bonds are none
    require(s.bonds.material == material,
            "install_bonds: the world already holds bonds of another material (one bond material "
            "per world)");
  auto& p = s.p;
  require(p.n > 0, "install_bonds: the world has no particles");
  if (tolerance < 0) {
    double mean = 0;
    for (std::size_t i = 0; i < p.n; ++i) mean += p.radius[i];
    tolerance = 1e-3 * mean / double(p.n);
  }
  for (auto id : ids) index_of(s, id);  // every id valid before anything changes
  detail::compact_bonds(s);  // a dead bond's pair may be bonded again
  const std::size_t installed = detail::install_bonds(s, material, tolerance, ids, stress_free);
  changed(s, Change::particles);  // bonded pairs leave the contact list
  return installed;
}

std::size_t World::bond_count() const {
  std::size_t n = 0;  // the parallel bonds that hold (a pair held by its contact bond alone is not one)
  detail::for_each_bond(*state_, [&](const detail::BondStore& q, std::size_t k) { n += q.holds[k] != detail::kContactBondHolds; });
  return n;
}

void World::set_bond_strength(double tensile_strength, bool breakable, std::optional<double> contact_strength,
                              std::optional<double> contact_shear_strength,
                              std::optional<double> contact_bond_friction) {
  BondMaterial m = state_->bonds.material;
  m.tensile_strength = breakable ? tensile_strength : 0.0;
  m.breakable = breakable;
  if (contact_strength) m.contact_strength = *contact_strength;
  if (contact_shear_strength) m.contact_shear_strength = *contact_shear_strength;
  if (contact_bond_friction) m.contact_bond_friction = *contact_bond_friction;
  check_value("set_bond_strength: ", Field{"bond material"}, m);
  const std::string problem = detail::bond_material_problem(m);
  require(problem.empty(), "set_bond_strength: " + problem);
  for (detail::BondStore* q : {&state_->bonds, &state_->frozen_bonds}) q->material = m;
}

void World::remove_bonds() {
  detail::remove_bonds(*state_);
  changed(*state_, Change::particles);  // the freed pairs enter the contact list at the next rebuild
}

double World::bond_criterion(double sigma, double tau, double tensile_strength) {
  return kernels::elliptic_criterion(sigma, tau, tensile_strength);
}

std::vector<BondInfo> World::bonds() const {
  const State& s = *state_;
  const auto& p = s.p;
  std::vector<BondInfo> out;
  out.reserve(s.bonds.n + s.frozen_bonds.n);
  detail::for_each_bond(s, [&](const detail::BondStore& q, std::size_t k) {
    BondInfo b;
    const auto ia = q.a[k], ib = q.b[k];
    b.id_a = p.id[ia];
    b.id_b = p.id[ib];
    b.normal = {q.nx[k], q.ny[k], q.nz[k]};
    b.point = Vec3{p.x[ia], p.y[ia], p.z[ia]} + b.normal * (p.radius[ia] - 0.5 * q.overlap[k]);
    b.gap = -q.overlap[k];
    b.beam_radius = q.beam_radius[k];
    b.normal_force = q.fn[k] + q.fbn[k];
    b.shear_force = {q.fsx[k] + q.fbsx[k], q.fsy[k] + q.fbsy[k], q.fsz[k] + q.fbsz[k]};
    kernels::beam_moments(q, k, b.twisting_moment, b.bending_moment);
    kernels::beam_stresses(q, k, b.sigma, b.tau);
    b.beam = q.holds[k] != detail::kContactBondHolds;
    b.contact_bond = q.holds[k] != detail::kBeamHolds;
    if (b.id_a > b.id_b) {
      std::swap(b.id_a, b.id_b);
      b.normal = -b.normal;
      b.shear_force = -b.shear_force;
      b.twisting_moment = -b.twisting_moment;
      b.bending_moment = -b.bending_moment;
    }
    out.push_back(b);
  });
  std::sort(out.begin(), out.end(), [](const BondInfo& u, const BondInfo& v) {
    return u.id_a != v.id_a ? u.id_a < v.id_a : u.id_b < v.id_b;
  });
  return out;
}

const std::vector<BreakEvent>& World::break_events() const { return state_->break_events; }

}  // namespace asperity
