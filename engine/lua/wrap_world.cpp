// asperity.World: the engine's World (include/asperity/world.hpp) as a Lua userdata.
//
// Each method checks its arguments, makes one engine call and pushes the result (binding.hpp).
// The exceptions to "one call": bulk writes from an Array (a loop in C over the per-particle
// setters, still one Lua call) and group predicates (one Lua call per particle: it is the user's
// function). world:run hands World::run its stop condition, callback and progress line as hooks.
//
// Ids count from 1 in Lua (particles, walls, groups); the engine counts from 0.
// Wall materials default to the world's contact material, not to the C++ default, so that
// `asperity.world{material = {kn = 1e4}}` followed by `add_plane{...}` does what one expects.
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

World& world_arg(lua_State* L) { return *static_cast<World*>(check_udata(L, 1, kWorldType)); }

std::int64_t particle_arg(lua_State* L, int arg, const World& w) {
  return check_id(L, arg, w.particle_count(), "particle");
}
int wall_arg(lua_State* L, int arg, const World& w) {
  return static_cast<int>(check_id(L, arg, w.wall_count(), "wall"));
}
int group_arg(lua_State* L, int arg, const World& w) {
  return static_cast<int>(check_id(L, arg, w.group_count(), "group"));
}

// material = {kn=, ks=, friction=}; fields not given keep `base`.
ContactMaterial material_field(lua_State* L, Options& o, const char* key, ContactMaterial base) {
  if (o.push_checked(key, LUA_TTABLE, "a table {kn=, ks=, friction=}") == LUA_TTABLE) {
    Options m(L, -1, o.context() + " option '" + key + "'", 0);
    for_each_field(base, [&](const Field& f, double& v) { v = m.number(f.name, v); });
    m.finish();
  }
  lua_pop(L, 1);
  return base;
}

void push_material(lua_State* L, const ContactMaterial& m) {
  lua_createtable(L, 0, 3);
  for_each_field(m, [&](const Field& f, double v) {
    lua_pushnumber(L, v);
    lua_setfield(L, -2, f.name);
  });
}

// Particles named by a list of ids (table or Array) or by a predicate function(id, pos, r)
// returning true for the ones wanted. Empty selections are errors: they are always mistakes.
std::vector<std::int64_t> ids_arg(lua_State* L, int arg, const World& w, const char* context) {
  std::vector<std::int64_t> ids;
  std::size_t n = w.particle_count();
  if (lua_type(L, arg) == LUA_TFUNCTION) {
    for (std::size_t i = 0; i < n; ++i) {
      auto id = static_cast<std::int64_t>(i);
      lua_pushvalue(L, arg);
      lua_pushinteger(L, id + 1);
      push_vec(L, w.position(id));
      lua_pushnumber(L, w.radius(id));
      if (lua_pcall(L, 3, 1, 0) != LUA_OK) throw PendingLuaError{};
      if (lua_toboolean(L, -1)) ids.push_back(id);
      lua_pop(L, 1);
    }
    if (ids.empty()) throw Error(std::string(context) + ": the predicate selected no particle");
    return ids;
  }
  std::size_t cols = 1;
  std::vector<double> v = check_numbers(L, arg, &cols);
  if (cols != 1) throw ArgError{arg, "a list of particle ids or a function(id, pos, r)"};
  if (v.empty()) throw ArgError{arg, "the list of particle ids is empty"};
  for (double x : v) {
    if (x != std::floor(x) || x < 1 || x > static_cast<double>(n))
      throw ArgError{arg, "no particle " + number_text(x) + " (valid: 1.." + std::to_string(n) + ")"};
    ids.push_back(static_cast<std::int64_t>(x) - 1);
  }
  return ids;
}

// Option f.name of a settings table into v, by type; an absent option keeps v. The World checks
// the values; an integer is checked here, before it is narrowed.
void read_option(lua_State*, Options& o, const Field& f, double& v) { v = o.number(f.name, v); }
void read_option(lua_State*, Options& o, const Field& f, int& v) {
  const lua_Integer i = o.integer(f.name, v);
  const std::string problem = range_problem(f.name, double(i), f.range);
  if (!problem.empty()) throw Error(o.context() + ": " + problem);
  v = static_cast<int>(i);
}
void read_option(lua_State*, Options& o, const Field& f, bool& v) { v = o.boolean(f.name, v); }
void read_option(lua_State*, Options& o, const Field& f, std::string& v) { v = o.string(f.name, v); }
void read_option(lua_State*, Options& o, const Field& f, Vec3& v) {
  if (auto g = o.vec(f.name)) v = *g;
}
void read_option(lua_State* L, Options& o, const Field& f, ContactMaterial& v) {
  v = material_field(L, o, f.name, v);
}

const char* dof_name(Dof d) {
  switch (d) {
    case Dof::free: return "free";
    case Dof::fixed: return "fixed";
    case Dof::velocity: return "velocity";
    case Dof::servo: return "servo";
  }
  return "?";
}

namespace {

void push_value(lua_State* L, double v) { lua_pushnumber(L, v); }
void push_value(lua_State* L, int v) { lua_pushinteger(L, v); }
void push_value(lua_State* L, bool v) { lua_pushboolean(L, v); }
void push_value(lua_State* L, const std::string& v) { lua_pushstring(L, v.c_str()); }
void push_value(lua_State* L, const Vec3& v) { push_vec(L, v); }
void push_value(lua_State* L, const ContactMaterial& v) { push_material(L, v); }

// A default as help() shows it: 2500, true, "auto", {0, 0, 0}, {kn = 0.1, ...}.
std::string default_text(double v) { return short_number_text(v); }
std::string default_text(int v) { return std::to_string(v); }
std::string default_text(bool v) { return v ? "true" : "false"; }
std::string default_text(const std::string& v) { return "\"" + v + "\""; }
std::string default_text(const Vec3& v) {
  return "{" + short_number_text(v.x) + ", " + short_number_text(v.y) + ", " + short_number_text(v.z) + "}";
}
std::string default_text(Dof d) { return std::string("\"") + dof_name(d) + "\""; }
std::string default_text(const std::array<Dof, 3>& m) {
  return "{" + default_text(m[0]) + ", " + default_text(m[1]) + ", " + default_text(m[2]) + "}";
}
std::string default_text(const std::array<Servo, 3>&) { return "{...}"; }
std::string default_text(const ContactMaterial& m) {
  std::string t;
  for_each_field(m, [&](const Field& f, double v) {
    t += (t.empty() ? "{" : ", ") + std::string(f.name) + " = " + short_number_text(v);
  });
  return t + "}";
}

// One line per field of a table (fields.hpp): name = default, the values it accepts, its meaning.
template <class T>
std::string field_line(const Field& f, const T& v, const char* indent) {
  std::string t = std::string("\n") + indent + f.name + " = " + default_text(v);
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
    t += (f.range.zero != nullptr ? std::string(" (0: ") + f.range.zero + ") or in " : std::string(" in ")) +
         range_text(f.range);
  return t + ": " + f.doc;
}

// asperity.world's help: every setting with its default, accepted values and meaning.
const char* world_settings_help() {
  static const std::string text = [] {
    std::string t = "A new world. Options (default: meaning):";
    const WorldSettings defaults;
    for_each_setting(defaults, [&](const Field& f, const auto& v) { t += field_line(f, v, "  "); });
    return t;
  }();
  return text.c_str();
}

// The fields of a struct with a table, at their defaults, one line each.
template <class Table>
std::string fields_help(const Table& defaults) {
  std::string t;
  for_each_field(defaults, [&](const Field& f, const auto& v) { t += field_line(f, v, "    "); });
  return t;
}

}  // namespace

std::string servo_fields_help() { return fields_help(Servo{}); }
std::string bond_material_fields_help() { return fields_help(BondMaterial{}); }
std::string motion_fields_help() { return fields_help(GroupMotion{}); }

namespace {

// ---------------------------------------------------------------------------------------------
// Creation

int world_new(lua_State* L) {
  return guarded(L, [&] {
    WorldSettings s;
    Options o(L, 1, "asperity.world", 1);
    for_each_setting(s, [&](const Field& f, auto& v) { read_option(L, o, f, v); });
    o.finish();
    // Construct before setting the metatable: if the constructor throws, no __gc will ever run
    // on the uninitialised block.
    // The engine validates the settings (its SIMD registry lists the valid names).
    void* mem = lua_newuserdatauv(L, sizeof(World), 0);
    try {
      new (mem) World(std::move(s));
    } catch (const HealthError&) {
      throw;
    } catch (const Error& e) {
      throw Error(std::string("asperity.world: ") + e.what());
    }
    luaL_setmetatable(L, kWorldType);
    return 1;
  });
}

int world_gc(lua_State* L) {
  if (void* p = luaL_testudata(L, 1, kWorldType)) static_cast<World*>(p)->~World();
  return 0;
}

int world_tostring(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    char buf[160];
    std::snprintf(buf, sizeof buf, "World(%zu particles, %zu walls, %zu groups, step %llu, t = %.6g s)",
                  w.particle_count(), w.wall_count(), w.group_count(),
                  (unsigned long long)w.step_count(), w.time());
    lua_pushstring(L, buf);
    return 1;
  });
}

}  // namespace

int world_settings(lua_State* L) {
  return guarded(L, [&] {
    const WorldSettings& s = world_arg(L).settings();
    lua_newtable(L);
    for_each_setting(s, [&](const Field& f, const auto& v) {
      push_value(L, v);
      lua_setfield(L, -2, f.name);
    });
    return 1;
  });
}

int servo_defaults(lua_State* L) {
  push_servo(L, Servo{});
  return 1;
}

void open_world(lua_State* L) {
  std::vector<Function> methods;
  for (std::span<const Function> part : {world_particle_methods(), world_body_methods(), world_bond_methods(),
                                         world_run_methods(), world_measure_methods()})
    methods.insert(methods.end(), part.begin(), part.end());
  static const luaL_Reg meta[] = {{"__gc", world_gc}, {"__tostring", world_tostring}};
  new_type(L, kWorldType, methods, meta,
           "World: particles, walls and rigid groups advancing in time.\n"
           "  Ids (particles, walls, groups) count from 1. Vectors are {x, y, z}.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"world", world_new,
       "asperity.world{[material=] [, density=] [, damping=] [, gravity=] [, rotation=] [, dt=] ...}\n"
       "  -> World",
       world_settings_help()},
      {"load", load_world, "asperity.load(path [, {threads=, simd=}]) -> World",
       "A world from a checkpoint written by world:save(path)."},
      {"servo_defaults", servo_defaults, "asperity.servo_defaults() -> {target_force=, relaxation=, ...}",
       "The servo's fields at their defaults (the servo table of world:set_group_motion): scripts\n"
       "take their defaults from here rather than writing them again."},
      {"bond_criterion", bond_criterion, "asperity.bond_criterion(sigma, tau, tensile_strength) -> f",
       "The elliptic strength criterion [3-46..3-49]: >= 1 means the bond fails."},
  };
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
