// The materials of contacts and bonds (model.md 4, 5): part of the public API (WorldSettings,
// World), and all that the engine's bond and wall stores need of it.
#pragma once

#include <limits>
#include <type_traits>

#include "asperity/fields.hpp"

namespace asperity {

// The stiffnesses a contact accepts (kn; ks may be 0), N/m: wide enough for any scene, narrow
// enough that the critical time step and the forces stay finite.
inline constexpr double kMinStiffness = 1e-12, kMaxStiffness = 1e15;

// Contact springs and friction (model.md 4). Source values: kn = 0.1 N/m, ks = kn/10, mu = 0.5.
struct ContactMaterial {
  double kn = 0.1;         // normal stiffness, N/m
  double ks = 0.01;        // shear stiffness, N/m
  double friction = 0.5;   // Coulomb coefficient mu
  bool operator==(const ContactMaterial&) const = default;
};

// Contact bond + parallel bond installed together (model.md 5). The beam of radius
// Rb = radius_factor * min(Ra, Rb) acts as springs of stiffness kbn A = beam_kn and kbs A = beam_ks
// (0, the default: as stiff as the world's contact springs, kbn A = kn, and kbs = kbn / 10; the
// world installs the bonds with these values). The two break separately: the
// beam by the elliptic criterion, the contact bond when its tensile normal force or its shear
// force reaches c st A (PFC's contact bond, Fcn = Fcs = c st A, A the beam's area), where
// c = contact_strength; c = inf: it never breaks; c = 0: it breaks with the beam (the pair
// becomes an ordinary contact the step its beam breaks, and never breaks on its own). The shear
// strength may differ: Fcs = cs st A with cs = contact_shear_strength (0: cs = c), and may grow
// with the compression the contact bond carries, Mohr-Coulomb fashion: Fcs = cs st A + mu_b Fn
// for Fn > 0 (mu_b = contact_bond_friction; 0, the default, is model.md 5's contact bond).
struct BondMaterial {
  double beam_kn = 0.0;            // kbn * A, N/m; 0: the world's contact kn
  double beam_ks = 0.0;            // kbs * A, N/m; 0: beam_kn / 10
  double radius_factor = 1.0;      // lambda
  double tensile_strength = 0.0;   // st, Pa (elliptic criterion [3-46..3-49])
  bool breakable = true;           // false: the elastic model (bonds never break)
  double contact_strength = 0.0;   // c: Fcn = Fcs = c st A; 0: breaks with the beam
  double contact_shear_strength = 0.0;  // cs: Fcs = cs st A instead; 0: as contact_strength
  double contact_bond_friction = 0.0;   // mu_b: Fcs grows by mu_b Fn under compression
  bool operator==(const BondMaterial&) const = default;
};

// visit(field, member) for each field of a contact material.
template <class Material, class Visit>
void for_each_field(Material& m, Visit&& visit)
  requires std::is_same_v<std::remove_const_t<Material>, ContactMaterial>
{
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(Field{"kn", "kn", 1, {kMinStiffness, kMaxStiffness, false, false, nullptr, "N/m"},
              "normal stiffness, N/m"},
        m.kn);
  visit(Field{"ks", "ks", 1, {0, kMaxStiffness, false, false, nullptr, "N/m"}, "shear stiffness, N/m"},
        m.ks);
  visit(Field{"friction", "friction", 1, {0, inf, false, true}, "Coulomb coefficient mu"}, m.friction);
}

// visit(field, member) for each field of a bond material (checked when bonds are installed, read
// by the Lua binding, saved by a checkpoint). A breakable bond also needs tensile_strength > 0
// (bond_material_problem, field_problems.hpp: the rule between two fields).
template <class Material, class Visit>
  requires std::is_same_v<std::remove_const_t<Material>, BondMaterial>
void for_each_field(Material& m, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(Field{"beam_kn", "beam_kn", 1, {0, inf, true, true, "the world's contact kn", "N/m"}, "kbn A, N/m"}, m.beam_kn);
  visit(Field{"beam_ks", "beam_ks", 1, {0, inf, true, true, "beam_kn / 10", "N/m"}, "kbs A, N/m"}, m.beam_ks);
  visit(Field{"radius_factor", "radius_factor", 1, {0, inf, true, true}, "lambda: Rb = lambda min(Ra, Rb) [3-26]"},
        m.radius_factor);
  visit(Field{"tensile_strength", "tensile_strength", 1, {0, inf, false, true, nullptr, "Pa"},
              "st, Pa (elliptic criterion [3-46..3-49])"},
        m.tensile_strength);
  visit(Field{"breakable", "breakable", 1, {}, "false: the elastic model (bonds never break)"}, m.breakable);
  visit(Field{"contact_strength", "contact_strength", 9, {0, inf, true, false, "breaks with the beam"},
              "c: the contact bond breaks at a tensile or shear force c st A (model.md 5), inf never"},
        m.contact_strength);
  visit(Field{"contact_shear_strength", "contact_shear_strength", 9, {0, inf, true, false, "as contact_strength"},
              "cs: the contact bond's shear strength cs st A instead of c st A, inf never"},
        m.contact_shear_strength);
  visit(Field{"contact_bond_friction", "contact_bond_friction", 9, {0, inf, false, true},
              "mu_b: the contact bond's shear strength grows by mu_b Fn under compression Fn > 0"},
        m.contact_bond_friction);
}

}  // namespace asperity
