// asperity.World's binding, split by area (wrap_world_*.cpp): what the areas share, and the
// method list each contributes to the type (open_world, wrap_world.cpp).
#pragma once

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
