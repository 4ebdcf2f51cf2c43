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
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/interrupt.hpp"
#include "lua/progress.hpp"

namespace asperity::lua {

namespace {

constexpr const char* kWorldType = "asperity.World";

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
std::string default_text(const ContactMaterial& m) {
  std::string t;
  for_each_field(m, [&](const Field& f, double v) {
    t += (t.empty() ? "{" : ", ") + std::string(f.name) + " = " + short_number_text(v);
  });
  return t + "}";
}

// asperity.world's help: every setting with its default, accepted values and meaning.
const char* world_settings_help() {
  static const std::string text = [] {
    std::string t = "A new world. Options (default: meaning):";
    WorldSettings defaults;
    for_each_setting(defaults, [&](const Field& f, const auto& v) {
      using T = std::decay_t<decltype(v)>;
      t += std::string("\n  ") + f.name + " = " + default_text(v);
      if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
        t += (f.range.zero != nullptr ? std::string(" (0: ") + f.range.zero + ") or in " : std::string(" in ")) +
             range_text(f.range);
      t += std::string(": ") + f.doc;
    });
    return t;
  }();
  return text.c_str();
}

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

// ---------------------------------------------------------------------------------------------
// Particles

int world_add_particle(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Vec3 x = check_vec(L, 2);
    double r = check_number(L, 3);
    double rho = opt_number(L, 4, 0.0);
    lua_pushinteger(L, w.add_particle(x, r, rho) + 1);
    return 1;
  });
}

int world_add_particles(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::size_t cols = 1;
    std::vector<double> xyz = check_numbers(L, 2, &cols);
    if (cols != 3 && !(cols == 1 && xyz.size() % 3 == 0))
      throw ArgError{2, "positions must be n x 3 (an Array, {{x,y,z},...} or a flat {x1,y1,z1,...})"};
    std::size_t n = xyz.size() / 3;
    std::vector<double> radii;
    if (lua_type(L, 3) == LUA_TNUMBER) {
      radii.assign(n, lua_tonumber(L, 3));
    } else {
      std::size_t rc = 1;
      radii = check_numbers(L, 3, &rc);
      if (rc != 1 || radii.size() != n)
        throw ArgError{3, "radii: one number per particle (" + std::to_string(n) + "), or a number"};
    }
    double rho = opt_number(L, 4, 0.0);
    if (n == 0) {
      lua_pushnil(L);
      lua_pushnil(L);
      return 2;
    }
    std::int64_t first = w.add_particles(xyz, radii, rho);
    lua_pushinteger(L, first + 1);
    lua_pushinteger(L, first + static_cast<std::int64_t>(n));
    return 2;
  });
}

int world_particle_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).particle_count()));
    return 1;
  });
}

template <Vec3 (World::*Get)(std::int64_t) const>
int get_particle_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(particle_arg(L, 2, w)));
    return 1;
  });
}

template <double (World::*Get)(std::int64_t) const>
int get_particle_number(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushnumber(L, (w.*Get)(particle_arg(L, 2, w)));
    return 1;
  });
}

template <void (World::*Set)(std::int64_t, Vec3)>
int set_particle_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    (w.*Set)(id, check_vec(L, 3));
    return 0;
  });
}

int world_group_of(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = w.group_of(particle_arg(L, 2, w));
    if (g < 0) lua_pushnil(L);
    else lua_pushinteger(L, g + 1);
    return 1;
  });
}

int world_set_radius(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    w.set_radius(id, check_number(L, 3));
    return 0;
  });
}

int world_set_rotation_locked(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    w.set_rotation_locked(id, check_boolean(L, 3));
    return 0;
  });
}

int world_scale_radii(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.scale_radii(check_number(L, 2));
    return 0;
  });
}

template <std::vector<double> (World::*Get)() const, std::size_t Cols>
int get_bulk(lua_State* L) {
  return guarded(L, [&] {
    push_array(L, (world_arg(L).*Get)(), Cols);
    return 1;
  });
}

template <void (World::*Set)(std::int64_t, Vec3)>
int set_bulk_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::size_t cols = 1;
    std::vector<double> v = check_numbers(L, 2, &cols);
    std::size_t n = w.particle_count();
    if (v.size() != 3 * n || (cols != 3 && cols != 1))
      throw ArgError{2, "need " + std::to_string(n) + " x 3 values (one vector per particle), got " +
                            std::to_string(v.size()) + " values"};
    for (std::size_t i = 0; i < n; ++i)
      (w.*Set)(static_cast<std::int64_t>(i), {v[3 * i], v[3 * i + 1], v[3 * i + 2]});
    return 0;
  });
}

// ---------------------------------------------------------------------------------------------
// Walls

int world_add_plane(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:add_plane", 2);
    auto point = o.vec("point");
    auto normal = o.vec("normal");
    ContactMaterial m = material_field(L, o, "material", w.settings().contact);
    o.finish();
    if (!point || !normal) throw Error("world:add_plane: give point = {x, y, z} and normal = {x, y, z}");
    lua_pushinteger(L, w.add_plane(*point, *normal, m) + 1);
    return 1;
  });
}

int world_add_mesh(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:add_mesh", 2);
    ContactMaterial m = material_field(L, o, "material", w.settings().contact);
    if (o.push("vertices") == LUA_TNIL) throw Error("world:add_mesh: give vertices = {{x,y,z}, ...}");
    int vi = lua_gettop(L);
    if (o.push("triangles") == LUA_TNIL) throw Error("world:add_mesh: give triangles = {{i,j,k}, ...}");
    int ti = lua_gettop(L);
    o.finish();
    std::size_t vc = 1, tc = 1;
    std::vector<double> vflat = check_numbers(L, vi, &vc);
    std::vector<double> tflat = check_numbers(L, ti, &tc);
    if (vc != 3 || tc != 3)
      throw Error("world:add_mesh: vertices and triangles must be lists of 3 numbers each");
    std::vector<Vec3> vertices(vflat.size() / 3);
    for (std::size_t i = 0; i < vertices.size(); ++i)
      vertices[i] = {vflat[3 * i], vflat[3 * i + 1], vflat[3 * i + 2]};
    std::vector<std::array<int, 3>> triangles(tflat.size() / 3);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        double idx = tflat[3 * t + static_cast<std::size_t>(k)];
        if (idx != std::floor(idx) || idx < 1 || idx > static_cast<double>(vertices.size()))
          throw Error("world:add_mesh: triangle " + std::to_string(t + 1) +
                      " refers to vertex " + number_text(idx) + " (vertices are 1.." +
                      std::to_string(vertices.size()) + ")");
        triangles[t][static_cast<std::size_t>(k)] = static_cast<int>(idx) - 1;
      }
    lua_pushinteger(L, w.add_mesh(vertices, triangles, m) + 1);
    return 1;
  });
}

int world_set_wall_velocity(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int wall = wall_arg(L, 2, w);
    w.set_wall_velocity(wall, check_vec(L, 3));
    return 0;
  });
}

template <Vec3 (World::*Get)(int) const>
int get_wall_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(wall_arg(L, 2, w)));
    return 1;
  });
}

int world_remove_wall(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.remove_wall(wall_arg(L, 2, w));
    return 0;
  });
}

int world_wall_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).wall_count()));
    return 1;
  });
}

// ---------------------------------------------------------------------------------------------
// Groups

Dof dof_from_name(const std::string& name, const std::string& where) {
  if (name == "free") return Dof::free;
  if (name == "fixed") return Dof::fixed;
  if (name == "velocity") return Dof::velocity;
  if (name == "servo") return Dof::servo;
  throw Error(where + ": unknown motion '" + name + "' (valid: free, fixed, velocity, servo)");
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

Servo servo_fields(lua_State* L, int index, const std::string& context, Servo s) {
  Options o(L, index, context, 0);
  for_each_field(s, [&](const Field& f, double& v) { v = o.number(f.name, v); });
  o.finish();
  return s;
}

void push_servo(lua_State* L, const Servo& s) {
  lua_createtable(L, 0, 6);
  for_each_field(s, [&](const Field& f, double v) {
    lua_pushnumber(L, v);
    lua_setfield(L, -2, f.name);
  });
}

// motion = {translation = "free"|"fixed"|"velocity"|"servo" or one per axis, velocity = vec,
//           servo = {target_force=, stiffness=, gain=, relaxation=, max_velocity=, integral_time=} (for every
//           servo axis) or three such tables, rotation = "free"|"fixed"|"velocity",
//           angular_velocity = vec}
GroupMotion motion_arg(lua_State* L, int index, const std::string& context, int arg,
                       GroupMotion m) {
  Options o(L, index, context, arg);
  int t = o.push("translation");
  if (t == LUA_TSTRING) {
    Dof d = dof_from_name(lua_tostring(L, -1), context + " option 'translation'");
    m.translation = {d, d, d};
  } else if (t == LUA_TTABLE) {
    if (lua_rawlen(L, -1) != 3)
      throw Error(context + ": option 'translation' must be one name or three {x, y, z}");
    for (int k = 0; k < 3; ++k) {
      if (lua_rawgeti(L, -1, k + 1) != LUA_TSTRING)
        throw Error(context + ": option 'translation' must list names (free, fixed, velocity)");
      m.translation[static_cast<std::size_t>(k)] =
          dof_from_name(lua_tostring(L, -1), context + " option 'translation'");
      lua_pop(L, 1);
    }
  } else if (t != LUA_TNIL) {
    throw Error(context + ": option 'translation' must be a string or a table of three strings");
  }
  lua_pop(L, 1);
  if (auto v = o.vec("velocity")) {
    m.velocity = *v;
    if (t == LUA_TNIL) m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
  }
  int st = o.push_checked("servo", LUA_TTABLE, "a table {target_force=, ...} or three of them");
  if (st == LUA_TTABLE) {
    int si = lua_gettop(L);
    bool has_servo_axis = false;
    for (Dof d : m.translation) has_servo_axis = has_servo_axis || d == Dof::servo;
    if (!has_servo_axis)
      throw Error(context + ": option 'servo' needs a servo axis, e.g. translation = {\"fixed\", \"fixed\", \"servo\"}");
    if (lua_rawgeti(L, si, 1) == LUA_TTABLE) {
      lua_pop(L, 1);
      for (int k = 0; k < 3; ++k) {
        lua_rawgeti(L, si, k + 1);
        auto axis = static_cast<std::size_t>(k);
        m.servo[axis] = servo_fields(L, -1, context + " option 'servo'[" + std::to_string(k + 1) + "]", m.servo[axis]);
        lua_pop(L, 1);
      }
    } else {
      lua_pop(L, 1);
      for (std::size_t k = 0; k < 3; ++k)
        if (m.translation[k] == Dof::servo) m.servo[k] = servo_fields(L, si, context + " option 'servo'", m.servo[k]);
    }
  }
  lua_pop(L, 1);
  m.damping = o.number("damping", m.damping);
  std::string rotation = o.string("rotation", "");
  if (!rotation.empty()) m.rotation = dof_from_name(rotation, context + " option 'rotation'");
  if (auto w = o.vec("angular_velocity")) {
    m.angular_velocity = *w;
    if (rotation.empty()) m.rotation = Dof::velocity;
  }
  o.finish();
  return m;
}

void push_motion(lua_State* L, const GroupMotion& m) {
  lua_createtable(L, 0, 4);
  lua_createtable(L, 3, 0);
  for (int k = 0; k < 3; ++k) {
    lua_pushstring(L, dof_name(m.translation[static_cast<std::size_t>(k)]));
    lua_rawseti(L, -2, k + 1);
  }
  lua_setfield(L, -2, "translation");
  push_vec(L, m.velocity);
  lua_setfield(L, -2, "velocity");
  lua_createtable(L, 3, 0);
  for (int k = 0; k < 3; ++k) {
    push_servo(L, m.servo[static_cast<std::size_t>(k)]);
    lua_rawseti(L, -2, k + 1);
  }
  lua_setfield(L, -2, "servo");
  lua_pushstring(L, dof_name(m.rotation));
  lua_setfield(L, -2, "rotation");
  push_vec(L, m.angular_velocity);
  lua_setfield(L, -2, "angular_velocity");
  lua_pushnumber(L, m.damping);
  lua_setfield(L, -2, "damping");
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

int world_add_group(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:add_group");
    GroupMotion m = motion_arg(L, 3, "world:add_group", 3, GroupMotion{});
    lua_pushinteger(L, w.add_group(ids, m) + 1);
    return 1;
  });
}

int world_set_inert(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_inert");
    bool inert = lua_isnoneornil(L, 3) ? true : check_boolean(L, 3);
    w.set_inert(ids, inert);
    return 0;
  });
}

int world_inert_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).inert_count()));
    return 1;
  });
}

// ---------------------------------------------------------------------------------------------
// Tags and flags (labels for measurements, e.g. the two halves of a joint)

int world_set_tag(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_tag");
    w.set_tag(ids, int_in(check_integer(L, 3), "world:set_tag: tag", INT32_MIN, INT32_MAX));
    return 0;
  });
}

int world_tag(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushinteger(L, w.tag(particle_arg(L, 2, w)));
    return 1;
  });
}

int world_set_flags(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_flags");
    lua_Integer flags = check_integer(L, 3);
    if (flags < 0 || flags > 255) throw ArgError{3, "flags are 8 bits (0..255)"};
    w.set_flags(ids, static_cast<std::uint8_t>(flags));
    return 0;
  });
}

int world_flags(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushinteger(L, w.flags(particle_arg(L, 2, w)));
    return 1;
  });
}

int world_contact_summary(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int a = int_in(check_integer(L, 2), "world:contact_summary: tag_a", INT32_MIN, INT32_MAX);
    int b = int_in(check_integer(L, 3), "world:contact_summary: tag_b", INT32_MIN, INT32_MAX);
    lua_Integer mask = opt_integer(L, 4, 0);
    if (mask < 0 || mask > 255) throw ArgError{4, "a flag mask is 8 bits (0..255)"};
    ContactSummary c = w.contact_summary(a, b, static_cast<std::uint8_t>(mask));
    lua_createtable(L, 0, 5);
    lua_pushinteger(L, static_cast<lua_Integer>(c.count));
    lua_setfield(L, -2, "count");
    lua_pushnumber(L, c.area);
    lua_setfield(L, -2, "area");
    push_vec(L, c.force);
    lua_setfield(L, -2, "force");
    lua_pushinteger(L, static_cast<lua_Integer>(c.flagged_count));
    lua_setfield(L, -2, "flagged_count");
    push_vec(L, c.flagged_force);
    lua_setfield(L, -2, "flagged_force");
    return 1;
  });
}

int world_contact_stress(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int tag = static_cast<int>(check_integer(L, 2));
    double volume = luaL_checknumber(L, 3);
    const World::ContactStress c = w.contact_stress(tag, volume);
    lua_pushnumber(L, c.stress);
    lua_pushnumber(L, c.stiffness);
    lua_pushinteger(L, static_cast<lua_Integer>(c.contacts));
    return 3;
  });
}

// ---------------------------------------------------------------------------------------------
// Bonds

const char* break_mode_name(BreakEvent::Mode m) {
  switch (m) {
    case BreakEvent::Mode::tension: return "tension";
    case BreakEvent::Mode::compression: return "compression";
    case BreakEvent::Mode::shear: return "shear";
  }
  return "?";
}

int world_install_bonds(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string ctx = "world:install_bonds";
    Options o(L, 2, ctx, 2);
    BondMaterial m;
    // Defaults of the Lua layer: the beam as stiff as the world's contact springs (model.md 5:
    // kbn A = kn, kbs = kbn / 10), not the C++ struct's constants.
    m.beam_kn = o.number("beam_kn", w.settings().contact.kn);
    m.beam_ks = o.number("beam_ks", m.beam_kn / 10);
    m.radius_factor = o.number("radius_factor", m.radius_factor);
    m.breakable = o.boolean("breakable", true);
    auto st = o.number("tensile_strength");
    double tolerance = o.number("tolerance", -1);
    const bool stress_free = o.boolean("stress_free", false);
    std::vector<std::int64_t> ids;
    if (o.push("ids") != LUA_TNIL) ids = ids_arg(L, lua_gettop(L), w, ctx.c_str());
    lua_pop(L, 1);
    o.finish();
    if (m.breakable && !st)
      throw Error(ctx + ": give tensile_strength = (Pa), or breakable = false for elastic bonds");
    if (st) m.tensile_strength = *st;
    lua_pushinteger(L, static_cast<lua_Integer>(w.install_bonds(m, tolerance, ids, stress_free)));
    return 1;
  });
}

// Checkpoints: world:save(path), asperity.load(path [, {threads=, simd=}]).
int world_save(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string path = check_string(L, 2);
    w.save(path);
    return 0;
  });
}

int l_load(lua_State* L) {
  return guarded(L, [&] {
    const std::string path = check_string(L, 1);
    int threads = 0;
    std::string simd = "auto";
    if (!lua_isnoneornil(L, 2)) {
      Options o(L, 2, "asperity.load", 2);
      threads = int_in(o.integer("threads", threads), "asperity.load: threads", 0, kMaxThreads);
      simd = o.string("simd", simd);
      o.finish();
    }
    World loaded = World::load(path, threads, simd);
    void* mem = lua_newuserdatauv(L, sizeof(World), 0);
    new (mem) World(std::move(loaded));
    luaL_setmetatable(L, kWorldType);
    return 1;
  });
}

int world_set_bond_strength(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:set_bond_strength", 2);
    const bool breakable = o.boolean("breakable", true);
    const auto st = o.number("tensile_strength");
    o.finish();
    if (breakable && !st)
      throw Error("world:set_bond_strength: give tensile_strength = (Pa), or breakable = false");
    w.set_bond_strength(st ? *st : 0.0, breakable);
    return 0;
  });
}

int world_remove_bonds(lua_State* L) {
  return guarded(L, [&] {
    world_arg(L).remove_bonds();
    return 0;
  });
}

int world_bond_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).bond_count()));
    return 1;
  });
}

int world_bonds(lua_State* L) {
  return guarded(L, [&] {
    std::vector<BondInfo> bs = world_arg(L).bonds();
    lua_createtable(L, static_cast<int>(bs.size()), 0);
    for (std::size_t k = 0; k < bs.size(); ++k) {
      const BondInfo& b = bs[k];
      lua_createtable(L, 0, 12);
      auto num = [&](const char* f, double v) { lua_pushnumber(L, v); lua_setfield(L, -2, f); };
      auto vec = [&](const char* f, const Vec3& v) { push_vec(L, v); lua_setfield(L, -2, f); };
      lua_pushinteger(L, b.id_a + 1);
      lua_setfield(L, -2, "a");
      lua_pushinteger(L, b.id_b + 1);
      lua_setfield(L, -2, "b");
      vec("normal", b.normal);
      vec("point", b.point);
      num("gap", b.gap);
      num("beam_radius", b.beam_radius);
      num("normal_force", b.normal_force);
      vec("shear_force", b.shear_force);
      num("twisting_moment", b.twisting_moment);
      vec("bending_moment", b.bending_moment);
      num("sigma", b.sigma);
      num("tau", b.tau);
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

int world_break_events(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::vector<BreakEvent>& events = w.break_events();
    lua_Integer first = opt_integer(L, 2, 1);
    if (first < 1) throw ArgError{2, "events are numbered from 1"};
    lua_createtable(L, 0, 0);
    lua_Integer k = 0;
    for (std::size_t i = static_cast<std::size_t>(first - 1); i < events.size(); ++i) {
      const BreakEvent& e = events[i];
      lua_createtable(L, 0, 9);
      lua_pushinteger(L, static_cast<lua_Integer>(e.step));
      lua_setfield(L, -2, "step");
      lua_pushnumber(L, e.time);
      lua_setfield(L, -2, "time");
      push_vec(L, e.position);
      lua_setfield(L, -2, "position");
      lua_pushinteger(L, e.id_a + 1);
      lua_setfield(L, -2, "a");
      lua_pushinteger(L, e.id_b + 1);
      lua_setfield(L, -2, "b");
      lua_pushstring(L, break_mode_name(e.mode));
      lua_setfield(L, -2, "mode");
      lua_pushnumber(L, e.sigma);
      lua_setfield(L, -2, "sigma");
      lua_pushnumber(L, e.tau);
      lua_setfield(L, -2, "tau");
      lua_pushnumber(L, e.released_energy);
      lua_setfield(L, -2, "released_energy");
      lua_rawseti(L, -2, ++k);
    }
    return 1;
  });
}

int world_break_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).break_events().size()));
    return 1;
  });
}

int l_bond_criterion(lua_State* L) {
  return guarded(L, [&] {
    double sigma = check_number(L, 1), tau = check_number(L, 2), st = check_number(L, 3);
    lua_pushnumber(L, World::bond_criterion(sigma, tau, st));
    return 1;
  });
}

int world_set_group_motion(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    check_table(L, 3);
    // Fields not given keep their current setting.
    w.set_group_motion(g, motion_arg(L, 3, "world:set_group_motion", 3, w.group_motion(g)));
    return 0;
  });
}

int world_group_motion(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_motion(L, w.group_motion(group_arg(L, 2, w)));
    return 1;
  });
}

int world_set_group_velocity(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    GroupMotion m = w.group_motion(g);
    m.velocity = check_vec(L, 3);
    m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
    w.set_group_motion(g, m);
    return 0;
  });
}

int world_set_group_force(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    w.set_group_applied_force(g, check_vec(L, 3));
    return 0;
  });
}

template <Vec3 (World::*Get)(int) const>
int get_group_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(group_arg(L, 2, w)));
    return 1;
  });
}

int world_group_mass(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushnumber(L, w.group_mass(group_arg(L, 2, w)));
    return 1;
  });
}

int world_group_members(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = w.group_members(group_arg(L, 2, w));
    lua_createtable(L, static_cast<int>(ids.size()), 0);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      lua_pushinteger(L, ids[i] + 1);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}

int world_group_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).group_count()));
    return 1;
  });
}

// ---------------------------------------------------------------------------------------------
// Running

[[noreturn]] void throw_interrupted(const World& w) {
  throw Interrupted("interrupted at step " + std::to_string(w.step_count()) +
                    " (the world is intact: continue with world:cycle or world:run)");
}

std::uint64_t cycle_checked(World& w, std::uint64_t n) {
  std::uint64_t done;
  {
    RunningWorld running(w);
    done = w.cycle(n);
  }
  if (take_run_interrupt() || done < n) throw_interrupted(w);
  return done;
}

int world_cycle(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_Integer n = opt_integer(L, 2, 1);
    if (n < 0) throw ArgError{2, "the number of steps must be >= 0"};
    lua_pushinteger(L, static_cast<lua_Integer>(cycle_checked(w, static_cast<std::uint64_t>(n))));
    return 1;
  });
}

// Calls fn(world) with `nresults` results, re-raising its error unchanged.
void call_with_world(lua_State* L, int fn, int nresults) {
  lua_pushvalue(L, fn);
  lua_pushvalue(L, 1);
  if (lua_pcall(L, 1, nresults, 0) != LUA_OK) throw PendingLuaError{};
}

// The value shown in the progress line: a string, or a table of name = value.
std::string show_text(lua_State* L, int fn) {
  call_with_world(L, fn, 1);
  std::string out;
  if (lua_type(L, -1) == LUA_TSTRING) {
    out = lua_tostring(L, -1);
  } else if (lua_type(L, -1) == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, -2)) {
      if (lua_type(L, -2) == LUA_TSTRING) {
        char buf[48];
        if (lua_type(L, -1) == LUA_TNUMBER) std::snprintf(buf, sizeof buf, "%.4g", lua_tonumber(L, -1));
        else if (lua_type(L, -1) == LUA_TSTRING) std::snprintf(buf, sizeof buf, "%s", lua_tostring(L, -1));
        else std::snprintf(buf, sizeof buf, "%s", luaL_typename(L, -1));
        out += (out.empty() ? "" : "  ") + std::string(lua_tostring(L, -2)) + "=" + buf;
      }
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
  return out;
}

int world_run(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string ctx = "world:run";
    Options o(L, 2, ctx, 2);
    lua_Integer steps = o.integer("steps", 0);
    if (o.present("steps") && steps <= 0) throw Error(ctx + ": option 'steps' must be > 0");
    int stop_type = o.push("stop_when");
    int stop_fn = lua_gettop(L);
    bool equilibrium = false;
    if (stop_type == LUA_TSTRING) {
      std::string s = lua_tostring(L, -1);
      if (s != "equilibrium")
        throw Error(ctx + ": option 'stop_when' must be a function(world) or \"equilibrium\", got \"" + s + "\"");
      equilibrium = true;
    } else if (stop_type != LUA_TFUNCTION && stop_type != LUA_TNIL) {
      throw Error(ctx + ": option 'stop_when' must be a function(world) or \"equilibrium\", got " +
                  type_name(L, -1));
    }
    double ratio = o.number("ratio", 1e-4);
    if (o.present("ratio") && !equilibrium)
      throw Error(ctx + ": option 'ratio' applies only with stop_when = \"equilibrium\"");
    if (!(ratio > 0)) throw Error(ctx + ": option 'ratio' must be > 0");
    lua_Integer every = o.integer("every", 100);
    if (every < 1) throw Error(ctx + ": option 'every' must be >= 1");
    int callback_type = o.push_checked("callback", LUA_TFUNCTION, "a function(world)");
    int callback = lua_gettop(L);
    bool progress = o.boolean("progress", true);
    int show_type = o.push_checked("show", LUA_TFUNCTION, "a function(world) returning a string or table");
    int show = lua_gettop(L);
    int fraction_type = o.push_checked("fraction", LUA_TFUNCTION, "a function(world) returning 0..1");
    int fraction_fn = lua_gettop(L);
    o.finish();
    if (steps == 0 && stop_type == LUA_TNIL)
      throw Error(ctx + ": give steps = (how many) and/or stop_when = (a function or \"equilibrium\")");

    RunPlan plan;
    plan.steps = static_cast<std::uint64_t>(steps);
    plan.until_equilibrium = equilibrium;
    plan.ratio = ratio;
    plan.every = static_cast<std::uint64_t>(every);
    if (callback_type != LUA_TNIL) plan.callback = [&] { call_with_world(L, callback, 0); };
    if (stop_type == LUA_TFUNCTION)
      plan.stop_when = [&] {
        call_with_world(L, stop_fn, 1);
        const bool stop = lua_toboolean(L, -1);
        lua_pop(L, 1);
        return stop;
      };
    plan.interrupted = take_run_interrupt;
    Progress bar(progress, plan.steps);
    plan.on_chunk = [&](std::uint64_t done, double last_ratio) {
      if (!bar.due()) return;
      std::string extra;
      if (equilibrium && !std::isnan(last_ratio)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "ratio=%.3g (target %.3g)", last_ratio, ratio);
        extra = buf;
      }
      if (show_type != LUA_TNIL) {
        std::string text = show_text(L, show);
        if (!text.empty()) extra += (extra.empty() ? "" : "  ") + text;
      }
      double fraction = -1;
      if (fraction_type != LUA_TNIL) {
        call_with_world(L, fraction_fn, 1);
        fraction = lua_isnumber(L, -1) ? std::max(0.0, static_cast<double>(lua_tonumber(L, -1))) : -1;
        lua_pop(L, 1);
      }
      bar.draw(done, extra, fraction);
    };
    RunResult r;
    {
      RunningWorld running(w);  // a Ctrl-C stops the engine's step (interrupt.hpp)
      r = w.run(plan);
    }
    if (r.end == RunResult::End::interrupted) throw_interrupted(w);
    static const char* const reasons[] = {"steps", "equilibrium", "stop_when"};
    const char* reason = reasons[static_cast<int>(r.end)];
    bar.finish(r.steps, reason);
    lua_pushinteger(L, static_cast<lua_Integer>(r.steps));
    lua_pushstring(L, reason);
    return 2;
  });
}

int world_dt(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).dt()); return 1; });
}
// world:set_dt(x), world:set_dt_safety(x), world:set_skin(x): one number, checked by the World.
template <void (World::*Set)(double)>
int set_world_number(lua_State* L) {
  return guarded(L, [&] {
    (world_arg(L).*Set)(check_number(L, 2));
    return 0;
  });
}
int world_critical_dt(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).critical_dt()); return 1; });
}
int world_step(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).step_count()));
    return 1;
  });
}
int world_time(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).time()); return 1; });
}
int world_set_threads(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.set_threads(int_in(check_integer(L, 2), "world:set_threads: threads", 0, kMaxThreads));
    return 0;
  });
}
int world_simd(lua_State* L) {
  return guarded(L, [&] {
    std::string s = world_arg(L).simd_architecture();
    lua_pushstring(L, s.c_str());
    return 1;
  });
}
int world_stats(lua_State* L) {
  return guarded(L, [&] {
    StepStats s = world_arg(L).stats();
    lua_createtable(L, 0, 8);
    auto put = [&](const char* k, std::uint64_t v) {
      lua_pushinteger(L, static_cast<lua_Integer>(v));
      lua_setfield(L, -2, k);
    };
    put("rebuilds", s.rebuilds);
    put("reorders", s.reorders);
    put("pairs", s.pairs);
    put("contacts", s.contacts);
    put("wall_contacts", s.wall_contacts);
    put("frozen_bonds", s.frozen_bonds);
    put("threads", std::uint64_t(s.threads));
    if (s.busy_elsewhere >= 0) {  // nil where not measured
      lua_pushnumber(L, s.busy_elsewhere);
      lua_setfield(L, -2, "busy_elsewhere");
    }
    return 1;
  });
}
int world_rebuild_neighbors(lua_State* L) {
  return guarded(L, [&] {
    world_arg(L).rebuild_neighbors();
    return 0;
  });
}

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
    std::vector<ContactInfo> cs = world_arg(L).contacts();
    lua_createtable(L, static_cast<int>(cs.size()), 0);
    for (std::size_t k = 0; k < cs.size(); ++k) {
      const ContactInfo& c = cs[k];
      lua_createtable(L, 0, 7);
      lua_pushinteger(L, c.id_a + 1);
      lua_setfield(L, -2, "a");
      lua_pushinteger(L, c.id_b + 1);
      lua_setfield(L, -2, "b");
      push_vec(L, c.normal);
      lua_setfield(L, -2, "normal");
      push_vec(L, c.point);
      lua_setfield(L, -2, "point");
      lua_pushnumber(L, c.overlap);
      lua_setfield(L, -2, "overlap");
      lua_pushnumber(L, c.normal_force);
      lua_setfield(L, -2, "normal_force");
      push_vec(L, c.shear_force);
      lua_setfield(L, -2, "shear_force");
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

int world_max_overlap_ratio(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).max_overlap_ratio()); return 1; });
}

int world_contact_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).contact_count()));
    return 1;
  });
}

}  // namespace

void open_world(lua_State* L) {
  static const Function methods[] = {
      // particles
      {"add_particle", world_add_particle, "world:add_particle(pos, radius [, density]) -> id",
       "Adds a sphere at pos {x, y, z}; density defaults to the world's. Ids count from 1.\n"
       "Accepted: radius 1e-6..1e3 m, density 1e-6..1e9 kg/m^3, |x|, |y|, |z| <= 1e9 m."},
      {"add_particles", world_add_particles,
       "world:add_particles(positions, radii [, density]) -> first_id, last_id",
       "Adds many spheres at once: positions an n x 3 Array or {{x,y,z}, ...}; radii an Array,\n"
       "a table or one number for all."},
      {"particle_count", world_particle_count, "world:particle_count() -> n", "Number of particles."},
      {"position", get_particle_vec<&World::position>, "world:position(id) -> vec", "Centre (m)."},
      {"velocity", get_particle_vec<&World::velocity>, "world:velocity(id) -> vec",
       "Velocity (m/s), at the last half step (leapfrog)."},
      {"angular_velocity", get_particle_vec<&World::angular_velocity>,
       "world:angular_velocity(id) -> vec", "Angular velocity (rad/s)."},
      {"force", get_particle_vec<&World::force>, "world:force(id) -> vec",
       "Contact + applied force of the last step (N)."},
      {"torque", get_particle_vec<&World::torque>, "world:torque(id) -> vec", "Torque of the last step (N m)."},
      {"radius", get_particle_number<&World::radius>, "world:radius(id) -> r", "Radius (m)."},
      {"mass", get_particle_number<&World::mass>, "world:mass(id) -> m", "Mass (kg)."},
      {"group_of", world_group_of, "world:group_of(id) -> group or nil", "The particle's rigid group."},
      {"set_position", set_particle_vec<&World::set_position>, "world:set_position(id, pos)", "Moves a particle."},
      {"set_velocity", set_particle_vec<&World::set_velocity>, "world:set_velocity(id, v)", "Sets a particle's velocity."},
      {"set_angular_velocity", set_particle_vec<&World::set_angular_velocity>,
       "world:set_angular_velocity(id, w)", "Sets a particle's angular velocity."},
      {"set_force", set_particle_vec<&World::set_applied_force>, "world:set_force(id, f)",
       "A constant external force on the particle, until set again ({0,0,0} removes it)."},
      {"set_radius", world_set_radius, "world:set_radius(id, r)", "Changes a radius; mass follows (density kept)."},
      {"set_rotation_locked", world_set_rotation_locked, "world:set_rotation_locked(id, locked)",
       "Stops (true) or allows (false) the particle's rotation."},
      {"scale_radii", world_scale_radii, "world:scale_radii(factor)",
       "Multiplies every radius (radius expansion); masses follow."},
      {"positions", get_bulk<&World::positions, 3>, "world:positions() -> Array(n x 3)", "All centres, row id."},
      {"velocities", get_bulk<&World::velocities, 3>, "world:velocities() -> Array(n x 3)", "All velocities."},
      {"forces", get_bulk<&World::forces, 3>, "world:forces() -> Array(n x 3)", "All forces of the last step."},
      {"radii", get_bulk<&World::radii, 1>, "world:radii() -> Array(n)", "All radii."},
      {"set_positions", set_bulk_vec<&World::set_position>, "world:set_positions(positions)",
       "Moves every particle: an n x 3 Array or table."},
      {"set_velocities", set_bulk_vec<&World::set_velocity>, "world:set_velocities(velocities)",
       "Sets every particle's velocity: an n x 3 Array or table."},
      // walls
      {"add_plane", world_add_plane, "world:add_plane{point=, normal= [, material=]} -> wall",
       "An infinite plane through point; normal points to where the particles are.\n"
       "material = {kn=, ks=, friction=} defaults to the world's material."},
      {"add_mesh", world_add_mesh,
       "world:add_mesh{vertices=, triangles= [, material=]} -> wall",
       "A two-sided triangle mesh: vertices {{x,y,z},...} or an Array; triangles {{i,j,k},...}\n"
       "with vertex numbers from 1."},
      {"set_wall_velocity", world_set_wall_velocity, "world:set_wall_velocity(wall, v)", "Prescribed translation velocity."},
      {"wall_velocity", get_wall_vec<&World::wall_velocity>, "world:wall_velocity(wall) -> vec", "Its velocity."},
      {"wall_displacement", get_wall_vec<&World::wall_displacement>, "world:wall_displacement(wall) -> vec",
       "Displacement since creation (m)."},
      {"wall_force", get_wall_vec<&World::wall_force>, "world:wall_force(wall) -> vec",
       "Force of the particles on the wall, last step (N)."},
      {"remove_wall", world_remove_wall, "world:remove_wall(wall)", "Removes it (its number is not reused)."},
      {"wall_count", world_wall_count, "world:wall_count() -> n", "Walls created, removed ones included."},
      // groups
      {"add_group", world_add_group, "world:add_group(ids or predicate [, motion]) -> group",
       "A rigid group of particles: a list of ids, or function(id, pos, r) returning true for\n"
       "members. motion = {translation = \"free\"|\"fixed\"|\"velocity\"|\"servo\" (or one per\n"
       "axis), velocity = v, servo = {target_force=, stiffness=, gain=, relaxation=,\n"
       "max_velocity=, integral_time=}, rotation = \"fixed\"|\"free\"|\"velocity\", angular_velocity = w,\n"
       "damping = local damping of the free axes (default: the world's; 0 for a dead-load platen)}.\n"
       "Default: free translation, no rotation. Giving velocity alone prescribes it."},
      {"set_group_motion", world_set_group_motion, "world:set_group_motion(group, motion)",
       "Changes how the group moves (fields not given are kept); see add_group."},
      {"group_motion", world_group_motion, "world:group_motion(group) -> motion", "Its motion table."},
      {"set_group_velocity", world_set_group_velocity, "world:set_group_velocity(group, v)",
       "Prescribes the group's translation velocity on all three axes."},
      {"set_group_force", world_set_group_force, "world:set_group_force(group, f)",
       "A constant external force on the group."},
      {"group_force", get_group_vec<&World::group_force>, "world:group_force(group) -> vec",
       "Contact + applied force on the members, last step (N)."},
      {"group_impulse", get_group_vec<&World::group_impulse>, "world:group_impulse(group) -> vec",
       "Sum of group_force x dt since the world was made or loaded (N s): mean force over an "
       "interval = change of impulse / change of world:time()."},
      {"group_torque", get_group_vec<&World::group_torque>, "world:group_torque(group) -> vec",
       "Torque about the centre of mass (N m)."},
      {"group_position", get_group_vec<&World::group_position>, "world:group_position(group) -> vec", "Centre of mass."},
      {"group_velocity", get_group_vec<&World::group_velocity>, "world:group_velocity(group) -> vec", "Its velocity."},
      {"group_mass", world_group_mass, "world:group_mass(group) -> m", "Total mass (kg)."},
      {"group_members", world_group_members, "world:group_members(group) -> {ids}", "Its particles."},
      {"group_count", world_group_count, "world:group_count() -> n", "Number of groups."},
      {"set_inert", world_set_inert, "world:set_inert(ids or predicate [, inert=true])",
       "Members of a translating group that can never touch anything (the inside of a rigid\n"
       "block): left out of the contact search, so a rigid body costs what its surface costs."},
      {"inert_count", world_inert_count, "world:inert_count() -> n", "Inert particles."},
      // labels
      {"set_tag", world_set_tag, "world:set_tag(ids or predicate, tag)",
       "An integer label per particle (default 0), e.g. the two halves of a joint."},
      {"tag", world_tag, "world:tag(id) -> tag", "The particle's tag."},
      {"set_flags", world_set_flags, "world:set_flags(ids or predicate, flags)", "Flag bits (0..255) per particle."},
      {"flags", world_flags, "world:flags(id) -> flags", "The particle's flag bits."},
      {"contact_summary", world_contact_summary,
       "world:contact_summary(tag_a, tag_b [, flag_mask]) -> {count, area, force, flagged_count, flagged_force}",
       "Touching contacts between two tags: number, contact area (sum pi a^2, m^2, [4-1]), total\n"
       "force on the tag_b particles; flagged_*: those involving a particle with flag_mask bits."},
      {"contact_stress", world_contact_stress, "world:contact_stress(tag, volume) -> Pa, Pa, n",
       "Mean stress of the particles of a tag from their touching contacts (Love-Weber):\n"
       "sum Fn d / (3 volume), d the distance of the centres; compression positive. Then its affine\n"
       "stiffness against a common radius factor f, dp/df = sum kn (Ra + Rb) d / (3 volume), and\n"
       "the number of those contacts."},
      // bonds
      {"install_bonds", world_install_bonds,
       "world:install_bonds{tensile_strength= | breakable=false [, beam_kn=] [, beam_ks=]\n"
       "  [, radius_factor=] [, tolerance=] [, ids=] [, stress_free=false]} -> count",
       "Bonds (contact + parallel bond, model.md 5) between every pair closer than tolerance\n"
       "(default 1e-3 mean radius); beam_kn defaults to the world's kn, beam_ks to beam_kn/10;\n"
       "ids (a list or predicate) restricts them to pairs of those particles. Existing contact\n"
       "forces are kept; stress_free = true unloads each contact bond at its current overlap\n"
       "instead (a contact left by a break keeps that rest overlap until the pair separates)."},
      {"bond_count", world_bond_count, "world:bond_count() -> n", "Intact bonds."},
      {"set_bond_strength", world_set_bond_strength,
       "world:set_bond_strength{tensile_strength= | breakable=false}",
       "Changes the strength of every bond (stiffness and stored forces unchanged)."},
      {"remove_bonds", world_remove_bonds, "world:remove_bonds()",
       "Deletes every bond (no break events; bonded pairs become ordinary contacts)."},
      {"save", world_save, "world:save(path)",
       "Writes a checkpoint (the whole state, HDF5); asperity.load(path) continues bit for bit."},
      {"bonds", world_bonds, "world:bonds() -> {bond, ...}",
       "Intact bonds: {a, b, normal, point, gap, beam_radius, normal_force, shear_force,\n"
       "twisting_moment, bending_moment, sigma, tau}."},
      {"break_events", world_break_events, "world:break_events([first]) -> {event, ...}",
       "Bond breaks so far (from number `first`): {step, time, position, a, b, mode, sigma, tau,\n"
       "released_energy}; mode is \"tension\", \"compression\" or \"shear\"."},
      {"break_count", world_break_count, "world:break_count() -> n", "Bond breaks so far."},
      // running
      {"cycle", world_cycle, "world:cycle([n]) -> steps",
       "Advances n steps (1). Ctrl-C stops it at the next step with an 'interrupted' error."},
      {"run", world_run,
       "world:run{steps= [, stop_when=] [, ratio=] [, every=] [, callback=] [, progress=] [, show=]\n"
       "          [, fraction=]}\n"
       "  -> steps, reason",
       "Runs up to `steps` steps, or until stop_when: a function(world) returning true, or\n"
       "\"equilibrium\" (unbalanced-force ratio <= ratio, default 1e-4). stop_when and\n"
       "callback(world) are evaluated every `every` steps (100). A progress line appears on a\n"
       "terminal after 2 s (progress=false: never); show(world) returns a string or a table of\n"
       "values to add to it; fraction(world) returns the completion 0..1 for the percent and ETA\n"
       "when stop_when, not steps, ends the run. reason: \"steps\", \"equilibrium\" or \"stop_when\"."},
      {"dt", world_dt, "world:dt() -> s", "The time step in use."},
      {"set_dt", set_world_number<&World::set_dt>, "world:set_dt(dt)", "Fixes the time step (0: automatic again)."},
      {"set_dt_safety", set_world_number<&World::set_dt_safety>, "world:set_dt_safety(f)",
       "Automatic time step = f x the critical estimate (default 0.8; 0.001 <= f <= 2)."},
      {"set_skin", set_world_number<&World::set_skin>, "world:set_skin(m)", "Verlet skin in m (the list is rebuilt)."},
      {"set_overlap_limit", set_world_number<&World::set_overlap_limit>, "world:set_overlap_limit(r)",
       "The health check's deepest overlap, in radii of the smaller body (default 1; 0 < r < 2).\n"
       "Deeper, one centre is inside the other particle; a rigid block's contacts may go there."},
      {"set_friction", set_world_number<&World::set_friction>, "world:set_friction(mu)",
       "Ball-ball Coulomb coefficient from the next step on (walls keep theirs)."},
      {"critical_dt", world_critical_dt, "world:critical_dt() -> s",
       "Critical time step estimate now, without the safety factor."},
      {"step", world_step, "world:step() -> n", "Steps done so far."},
      {"time", world_time, "world:time() -> s", "Simulated time."},
      {"set_threads", world_set_threads, "world:set_threads(n)", "OpenMP threads (0: automatic, by the number of pairs and bonds, up to the cores that other processes leave free)."},
      {"simd", world_simd, "world:simd() -> name", "SIMD architecture of the kernels."},
      {"stats", world_stats, "world:stats() -> table", "Rebuilds, reorders, pairs, contacts, wall_contacts, frozen_bonds (bonds inside a rigid group that does not turn, which the step leaves out); threads (of the next step) and, with automatic threads, busy_elsewhere (cores other processes kept busy lately, which the count leaves to them)."},
      {"rebuild_neighbors", world_rebuild_neighbors, "world:rebuild_neighbors()", "Rebuilds the pair list now."},
      // measurements
      {"energies", world_energies, "world:energies() -> table",
       "kinetic, strain (now), friction, damping, boundary_work, gravity_work, released\n"
       "(cumulative), J."},
      {"energy_balance", world_energy_balance, "world:energy_balance(initial) -> J",
       "Input work minus stored and dissipated energy since `initial` (a world:energies() table)."},
      {"unbalanced_force_ratio", world_unbalanced_force_ratio, "world:unbalanced_force_ratio() -> r",
       "Mean unbalanced force of the particles outside rigid groups / mean normal force of the\n"
       "touching contacts, wall contacts and intact bonds (PFC's equilibrium ratio)."},
      {"contacts", world_contacts, "world:contacts() -> {contact, ...}",
       "Touching ball-ball pairs: {a, b, normal, point, overlap, normal_force, shear_force}."},
      {"contact_count", world_contact_count, "world:contact_count() -> n", "Touching ball-ball pairs."},
      {"max_overlap_ratio", world_max_overlap_ratio, "world:max_overlap_ratio() -> r",
       "Deepest overlap (touching pairs, wall contacts, bonds) / radius of the smaller body; 0 if none.\n"
       "A step past 1 stops with a health error; well before, the contacts are soft for the load."},
      {"settings", world_settings, "world:settings() -> table", "The settings the world was made with."},
  };
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
      {"load", l_load, "asperity.load(path [, {threads=, simd=}]) -> World",
       "A world from a checkpoint written by world:save(path)."},
      {"bond_criterion", l_bond_criterion, "asperity.bond_criterion(sigma, tau, tensile_strength) -> f",
       "The elliptic strength criterion [3-46..3-49]: >= 1 means the bond fails."},
  };
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
