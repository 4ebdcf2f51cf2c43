// world: measurements (energies, unbalanced force, contacts, overlaps).
#include <cmath>
#include <cstdio>
#include <limits>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

namespace {

// ---------------------------------------------------------------------------------------------
// Measurements

void push_energies(lua_State* L, const Energies& e) {
  lua_createtable(L, 0, 7);
  auto put = [&](const char* k, double v) { lua_pushnumber(L, v); lua_setfield(L, -2, k); };
  put("kinetic", e.kinetic);
  put("strain", e.strain);
  put("friction", e.friction);
  put("damping", e.damping);
  put("boundary_work", e.boundary_work);
  put("gravity_work", e.gravity_work);
  put("released", e.released);
}

int world_energies(lua_State* L) {
  return guarded(L, [&] {
    push_energies(L, world_arg(L).energies());
    return 1;
  });
}

int world_energy_balance(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:energy_balance", 2);
    Energies e0;
    e0.kinetic = o.number("kinetic", 0);
    e0.strain = o.number("strain", 0);
    e0.friction = o.number("friction", 0);
    e0.damping = o.number("damping", 0);
    e0.boundary_work = o.number("boundary_work", 0);
    e0.gravity_work = o.number("gravity_work", 0);
    e0.released = o.number("released", 0);
    o.finish();
    lua_pushnumber(L, w.energies().balance_error(e0));
    return 1;
  });
}

int world_unbalanced_force_ratio(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).unbalanced_force_ratio()); return 1; });
}

int world_contacts(lua_State* L) {
  return guarded(L, [&] {
    const std::vector<bool> fields = row_field_mask<ContactInfo>(L, 2, "world:contacts");
    std::vector<ContactInfo> cs = world_arg(L).contacts();
    lua_createtable(L, static_cast<int>(cs.size()), 0);
    for (std::size_t k = 0; k < cs.size(); ++k) {
      push_row(L, cs[k], &fields);
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

int world_max_overlap_ratio(lua_State* L) {
  return guarded(L, [&] {
    const bool turning_only = lua_isnoneornil(L, 2) ? false : check_boolean(L, 2);
    lua_pushnumber(L, world_arg(L).max_overlap_ratio(turning_only));
    return 1;
  });
}

int world_contact_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).contact_count()));
    return 1;
  });
}

}  // namespace

std::span<const Function> world_measure_methods() {
  static const std::string contacts_help = "Touching ball-ball pairs: " + row_fields<ContactInfo>() +
                                           ";\nfields: only those (a row of every field is about 1 kB of Lua memory).";
  static const Function methods[] = {
      {"energies", world_energies, "world:energies() -> table",
       "kinetic, strain (now), friction, damping, boundary_work, gravity_work, released\n"
       "(cumulative), J."},
      {"energy_balance", world_energy_balance, "world:energy_balance(initial) -> J",
       "Input work minus stored and dissipated energy since `initial` (a world:energies() table)."},
      {"unbalanced_force_ratio", world_unbalanced_force_ratio, "world:unbalanced_force_ratio() -> r",
       "Mean unbalanced force of the particles outside rigid groups / mean normal force of the\n"
       "touching contacts, wall contacts and intact bonds (PFC's equilibrium ratio)."},
      {"contacts", world_contacts, "world:contacts([{fields = {name, ...}}]) -> {contact, ...}", contacts_help.c_str()},
      {"contact_count", world_contact_count, "world:contact_count() -> n", "Touching ball-ball pairs."},
      {"max_overlap_ratio", world_max_overlap_ratio, "world:max_overlap_ratio([turning_only]) -> r",
       "Deepest overlap (touching pairs, wall contacts, bonds) / radius of the smaller body; 0 if none.\n"
       "A step past 1 stops with a health error; well before, the contacts are soft for the load.\n"
       "turning_only = true: only contacts with a particle free to turn (not rotation-locked, not\n"
       "inert, not in a group of fixed rotation), where contact point and lever arm enter the motion."},
      {"settings", world_settings, "world:settings() -> table", "The settings the world was made with."},
  };
  return methods;
}

}  // namespace asperity::lua
