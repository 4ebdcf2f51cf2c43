// What is wrong with a value of a described field (fields.hpp; the tables of world.hpp and
// materials.hpp), by its type; empty when the field accepts it. The World's checks turn a problem
// into an error, the checkpoint's validation into a damaged file: one rule for both.
#pragma once
#include <array>
#include <cmath>
#include <string>

#include "asperity/world.hpp"

namespace asperity::detail {

inline std::string field_problem(const Field& f, double v) { return range_problem(f.name, v, f.range); }
inline std::string field_problem(const Field& f, int v) { return field_problem(f, double(v)); }
inline std::string field_problem(const Field&, bool) { return {}; }
// Text settings: the simd name is checked by the kernel registry.
inline std::string field_problem(const Field&, const std::string&) { return {}; }
inline std::string field_problem(const Field& f, const Vec3& v) {
  if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) return {};
  return std::string(f.name) + " must be finite, got (" + short_number_text(v.x) + ", " +
         short_number_text(v.y) + ", " + short_number_text(v.z) + ")";
}
inline std::string field_problem(const Field& f, Dof d) {
  if (d == Dof::free || d == Dof::fixed || d == Dof::velocity || d == Dof::servo) return {};
  return std::string("unknown ") + f.name + " mode";
}
inline std::string field_problem(const Field& f, const std::array<Dof, 3>& modes) {
  for (Dof d : modes)
    if (auto p = field_problem(f, d); !p.empty()) return p;
  return {};
}
// A motion's servos: each is checked where it is used (a servo axis), by its own table.
inline std::string field_problem(const Field&, const std::array<Servo, 3>&) { return {}; }
// A struct with a table of its own (a material, a servo): its first field with a problem.
template <class Table>
  requires requires(const Table& t) { for_each_field(t, [](const Field&, const auto&) {}); }
std::string field_problem(const Field& f, const Table& t) {
  std::string problem;
  for_each_field(t, [&](const Field& g, const auto& v) {
    if (problem.empty()) problem = field_problem(g, v);
  });
  return problem.empty() ? problem : std::string(f.name) + ": " + problem;
}

// The rule between two fields of a bond material, checked where bonds get a material (installed,
// their strength set): a breakable bond needs a strength. (A checkpoint of a world without bonds
// holds the default material, breakable without one: not a damaged file.)
inline std::string bond_material_problem(const BondMaterial& m) {
  if (!m.breakable || (m.tensile_strength > 0 && std::isfinite(m.tensile_strength))) return {};
  return "a breakable bond needs tensile_strength > 0 (Pa), got " + short_number_text(m.tensile_strength) +
         ": give it, or breakable = false for unbreakable bonds";
}

}  // namespace asperity::detail
