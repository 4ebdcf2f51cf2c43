// asperity.World's binding, split by area (wrap_world_*.cpp): what the areas share, and the
// method list each contributes to the type (open_world, wrap_world.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "asperity/world.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

inline constexpr const char* kWorldType = "asperity.World";

World& world_arg(lua_State* L);  // the World at argument 1
std::int64_t particle_arg(lua_State* L, int arg, const World& w);
int wall_arg(lua_State* L, int arg, const World& w);
int group_arg(lua_State* L, int arg, const World& w);
// material = {kn=, ks=, friction=}; fields not given keep `base`.
ContactMaterial material_field(lua_State* L, Options& o, const char* key, ContactMaterial base);
void push_material(lua_State* L, const ContactMaterial& m);
// Option f.name of a settings table into v, by its type; an absent option keeps v (fields.hpp).
void read_option(lua_State* L, Options& o, const Field& f, double& v);
void read_option(lua_State* L, Options& o, const Field& f, int& v);
void read_option(lua_State* L, Options& o, const Field& f, bool& v);
void read_option(lua_State* L, Options& o, const Field& f, std::string& v);
void read_option(lua_State* L, Options& o, const Field& f, Vec3& v);
void read_option(lua_State* L, Options& o, const Field& f, ContactMaterial& v);
const char* dof_name(Dof d);  // "free", "fixed", "velocity", "servo"
// The help lines of the servo's, the bond material's and a group motion's fields, from their tables.
std::string servo_fields_help();
void push_servo(lua_State* L, const Servo& s);  // its fields, from their table
// A row (ContactInfo, BondInfo, BreakEvent) as a table, field by field from its table
// (for_each_info, world.hpp): ids from 1, vectors as vec, modes and kinds by name.
inline void push_info_value(lua_State* L, double v) { lua_pushnumber(L, v); }
inline void push_info_value(lua_State* L, bool v) { lua_pushboolean(L, v); }
inline void push_info_value(lua_State* L, std::int64_t id) { lua_pushinteger(L, static_cast<lua_Integer>(id + 1)); }
inline void push_info_value(lua_State* L, std::uint64_t n) { lua_pushinteger(L, static_cast<lua_Integer>(n)); }
inline void push_info_value(lua_State* L, const Vec3& v) { push_vec(L, v); }
inline void push_info_value(lua_State* L, BreakEvent::Mode m) { lua_pushstring(L, name_of(m)); }
inline void push_info_value(lua_State* L, BreakEvent::Kind k) { lua_pushstring(L, name_of(k)); }
// "{a, b, normal, ...}": a row's fields by their table, for help texts.
template <class Row>
std::string row_fields() {
  std::string out = "{";
  const Row row{};
  for_each_info(row, [&](const char* name, const auto&) { out += (out.size() > 1 ? ", " : "") + std::string(name); });
  return out + "}";
}
// Which of a row's fields a listing pushes, in the order of its table: all, or those named by
// option `fields` of the options table at `index` (a list of names; an unknown one is an error
// naming it and the known ones). A row of every field is a Lua table of about 1 kB: the bonds of
// a 10 cm joint listed whole took 300 MB, the two fields a script needed 60.
template <class Row>
std::vector<bool> row_field_mask(lua_State* L, int index, const std::string& context) {
  const Row row{};
  std::vector<std::string> names;
  for_each_info(row, [&](const char* name, const auto&) { names.emplace_back(name); });
  std::vector<bool> mask(names.size(), true);
  Options o(L, index, context, index);
  if (o.push_checked("fields", LUA_TTABLE, "a list of field names") == LUA_TTABLE) {
    mask.assign(names.size(), false);
    const int list = lua_gettop(L);
    const lua_Integer count = static_cast<lua_Integer>(lua_rawlen(L, list));
    for (lua_Integer i = 1; i <= count; ++i) {
      lua_rawgeti(L, list, i);
      const char* want = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : nullptr;
      std::size_t at = names.size();
      for (std::size_t f = 0; want && f < names.size(); ++f)
        if (names[f] == want) at = f;
      if (at == names.size())
        throw ArgError{index, context + ": fields[" + std::to_string(i) + "] is " +
                                  (want ? "\"" + std::string(want) + "\"" : std::string(luaL_typename(L, -1))) +
                                  ", not a field; fields are " + row_fields<Row>()};
      mask[at] = true;
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
  o.finish();
  return mask;
}
template <class Row>
void push_row(lua_State* L, const Row& row, const std::vector<bool>* mask = nullptr) {
  lua_createtable(L, 0, mask ? static_cast<int>(std::count(mask->begin(), mask->end(), true)) : 16);
  std::size_t f = 0;
  for_each_info(row, [&](const char* name, const auto& v) {
    if (!mask || (*mask)[f]) {
      push_info_value(L, v);
      lua_setfield(L, -2, name);
    }
    ++f;
  });
}

std::string bond_material_fields_help();
std::string motion_fields_help();
// Particles named by a list of ids (table or Array) or by a predicate function(id, pos, r).
std::vector<std::int64_t> ids_arg(lua_State* L, int arg, const World& w, const char* context);

std::span<const Function> world_particle_methods();  // and their labels (tags, flags)
std::span<const Function> world_body_methods();      // walls and rigid groups
std::span<const Function> world_bond_methods();      // and checkpoints
std::span<const Function> world_run_methods();
std::span<const Function> world_measure_methods();
int world_settings(lua_State* L);  // world:settings(), with the settings table (wrap_world.cpp)
// Module functions of the bond area: asperity.load, asperity.bond_criterion.
int load_world(lua_State* L);
int bond_criterion(lua_State* L);

}  // namespace asperity::lua
