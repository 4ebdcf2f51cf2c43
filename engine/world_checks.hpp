// What the World's functions share: the checks of their input (each says which argument and what
// was wrong) and a few helpers over State. For the world*.cpp files only.
#pragma once

#include <cmath>
#include <concepts>
#include <numbers>
#include <string>
#include <string_view>

#include "asperity/world.hpp"
#include "bodies/groups.hpp"
#include "field_problems.hpp"
#include "state.hpp"

namespace asperity::world_checks {

using detail::State;


inline void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

inline std::string num(double v) { return short_number_text(v); }

inline std::string vec_text(const Vec3& v) {
  return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}

// A value against its field (field_problems.hpp): `where` names the call, e.g. "set_dt_safety: ".
template <class T>
inline void check_value(const std::string& where, const Field& f, const T& v) {
  const std::string problem = detail::field_problem(f, v);
  if (!problem.empty()) throw Error(where + problem);
}

inline void require_finite(const Vec3& v, const char* what) { check_value("", Field{what}, v); }

// Positions (particles, plane points, mesh vertices) within kMaxCoordinate of the origin: the
// cell grids take differences of coordinates, which must not overflow (NaN fails too).
inline bool position_within_bounds(const Vec3& v) {
  return std::fabs(v.x) <= kMaxCoordinate && std::fabs(v.y) <= kMaxCoordinate &&
         std::fabs(v.z) <= kMaxCoordinate;
}

// The messages of these are built only when the check fails: a genesis calls them for every
// particle at every one of its hundreds of radius updates.
inline void require_position(const Vec3& v, const char* what) {
  require_finite(v, what);
  if (!position_within_bounds(v))
    throw Error(std::string(what) + " " + vec_text(v) + " outside [-" + num(kMaxCoordinate) + ", " +
                num(kMaxCoordinate) + "] m on some axis");
}

// what(): which position, e.g. "add_particle: position of particle 3".
template <class What>
  requires std::invocable<What>
inline void require_position(const Vec3& v, What&& what) {
  if (!position_within_bounds(v)) require_position(v, std::string(what()).c_str());  // throws, naming it
}

// what(): which radius, e.g. "set_radius: radius".
template <class What>
inline void require_radius(double r, What&& what) {
  if (!(r >= kMinRadius && r <= kMaxRadius))
    throw Error(std::string(what()) + " " + num(r) + " outside [" + num(kMinRadius) + ", " +
                num(kMaxRadius) + "] m");
}

inline void check_material(const ContactMaterial& m, const std::string& where) {
  check_value("", Field{where.c_str()}, m);
}
// The field of WorldSettings called `name`.
inline Field setting_field(const char* name) {
  WorldSettings defaults;
  Field found{nullptr};
  for_each_setting(defaults, [&](const Field& f, const auto&) {
    if (std::string_view(f.name) == name) found = f;
  });
  return found;
}
inline void check_setting(const char* where, const char* name, double v) {
  check_value(std::string(where) + ": ", setting_field(name), v);
}

inline void set_mass(detail::ParticleStore& p, std::size_t i) {
  const double r = p.radius[i];
  p.mass[i] = p.density[i] * 4.0 / 3.0 * std::numbers::pi * r * r * r;  // [3-4]
  p.inertia[i] = 0.4 * p.mass[i] * r * r;
  p.inv_mass[i] = 1.0 / p.mass[i];
  p.inv_inertia[i] = 1.0 / p.inertia[i];
}

inline void recompute_group(State& s, detail::Group& g) {
  detail::sync_lazy(s);
  const auto& p = s.p;
  g.mass = 0;
  g.inert_mass = 0;
  Vec3 c{0, 0, 0};
  for (auto i : g.members) {
    g.mass += p.mass[i];
    c += Vec3{p.x[i], p.y[i], p.z[i]} * p.mass[i];
  }
  for (auto i : g.inert) {
    g.mass += p.mass[i];
    g.inert_mass += p.mass[i];
    c += Vec3{p.x[i], p.y[i], p.z[i]} * p.mass[i];
  }
  g.centre = g.mass > 0 ? c / g.mass : Vec3{};
}

// Inert and idle group members are moved lazily; reads bring them up to date first. This changes no
// observable state, so const readers may do it.
inline const State& synced(const State& s) {
  bool pending = false;
  for (const auto& g : s.groups) pending = pending || !(g.inert_shift == Vec3{}) || !(g.idle_shift == Vec3{});
  if (pending) detail::sync_lazy(const_cast<State&>(s));
  return s;
}


// Ids and numbers given by the caller, checked against what the world holds.
inline std::size_t index_of(const State& s, std::int64_t id) {
  if (id < 0 || id >= static_cast<std::int64_t>(s.p.index_of_id.size()))
    throw Error("no particle with id " + std::to_string(id) + " (valid ids: 0.." +
                std::to_string(static_cast<std::int64_t>(s.p.index_of_id.size()) - 1) + ")");
  return static_cast<std::size_t>(s.p.index_of_id[id]);
}
inline int check_wall(const State& s, int wall) {
  if (wall < 0 || wall >= int(s.walls.walls.size()))
    throw Error("no wall " + std::to_string(wall) + " (walls: 0.." +
                std::to_string(int(s.walls.walls.size()) - 1) + ")");
  return wall;
}
inline int check_group(const State& s, int group) {
  if (group < 0 || group >= int(s.groups.size()))
    throw Error("no group " + std::to_string(group) + " (groups: 0.." +
                std::to_string(int(s.groups.size()) - 1) + ")");
  return group;
}

}  // namespace asperity::world_checks
