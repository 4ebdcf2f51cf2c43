// Argument checks, options tables, vectors, documentation registry and the module table.
// See binding.hpp for the rules every bound function follows.
#include "lua/binding.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "lua/interrupt.hpp"

namespace asperity::lua {

namespace {
constexpr const char* kDocsKey = "asperity.docs";  // registry: value -> documentation string
constexpr const char* kVecType = "asperity.vec";
}  // namespace

// ---------------------------------------------------------------------------------------------
// Errors

void push_current_exception(lua_State* L) {
  try {
    throw;
  } catch (const PendingLuaError&) {
    // the error value is already on top of the stack
  } catch (const ArgError& e) {
    // Same wording as luaL_argerror, including its treatment of methods (self is not counted).
    lua_Debug ar;
    int arg = e.arg;
    const char* name = "?";
    if (lua_getstack(L, 0, &ar)) {
      lua_getinfo(L, "n", &ar);
      if (ar.namewhat && std::string(ar.namewhat) == "method") {
        --arg;
        if (arg == 0) {
          luaL_where(L, 1);
          lua_pushfstring(L, "calling '%s' on bad self (%s)", ar.name ? ar.name : "?",
                          e.message.c_str());
          lua_concat(L, 2);
          return;
        }
      }
      if (ar.name) name = ar.name;
    }
    luaL_where(L, 1);
    lua_pushfstring(L, "bad argument #%d to '%s' (%s)", arg, name, e.message.c_str());
    lua_concat(L, 2);
  } catch (const HealthError& e) {
    // The engine's message, then its fields with the particle in Lua's numbering (from 1): the
    // engine's own text may name the particle by its 0-based engine id.
    luaL_where(L, 1);
    std::string particle = e.particle_id >= 0 ? ", particle " + std::to_string(e.particle_id + 1) +
                                                    " (engine id " + std::to_string(e.particle_id) + ")"
                                              : std::string();
    char value[40];
    std::snprintf(value, sizeof value, "%.6g", e.value);
    lua_pushfstring(L, "simulation stopped: %s [step %s%s, %s = %s]", e.what(),
                    std::to_string(e.step).c_str(), particle.c_str(), e.quantity.c_str(), value);
    lua_concat(L, 2);
  } catch (const std::exception& e) {
    luaL_where(L, 1);
    lua_pushstring(L, e.what());
    lua_concat(L, 2);
    if (dynamic_cast<const Interrupted*>(&e)) make_interruption(L);
  } catch (...) {
    luaL_where(L, 1);
    lua_pushstring(L, "unknown C++ exception");
    lua_concat(L, 2);
  }
}

// ---------------------------------------------------------------------------------------------
// Checks

std::string type_name(lua_State* L, int index) {
  if (luaL_getmetafield(L, index, "__name") == LUA_TSTRING) {
    std::string name = lua_tostring(L, -1);
    lua_pop(L, 1);
    return name;
  }
  // luaL_getmetafield pushes nothing when the field is absent
  if (lua_type(L, index) == LUA_TLIGHTUSERDATA) return "light userdata";
  return luaL_typename(L, index);
}

void type_error(int arg, const char* expected, lua_State* L, int index) {
  std::string got = lua_isnone(L, index) ? "no value" : type_name(L, index);
  throw ArgError{arg, std::string(expected) + " expected, got " + got};
}

double check_number(lua_State* L, int arg) {
  int ok = 0;
  double v = lua_tonumberx(L, arg, &ok);
  if (!ok || lua_type(L, arg) != LUA_TNUMBER) type_error(arg, "number", L, arg);
  return v;
}

double opt_number(lua_State* L, int arg, double fallback) {
  return lua_isnoneornil(L, arg) ? fallback : check_number(L, arg);
}

lua_Integer check_integer(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TNUMBER) type_error(arg, "integer", L, arg);
  int ok = 0;
  lua_Integer v = lua_tointegerx(L, arg, &ok);
  if (!ok) throw ArgError{arg, "number has no integer representation"};
  return v;
}

lua_Integer opt_integer(lua_State* L, int arg, lua_Integer fallback) {
  return lua_isnoneornil(L, arg) ? fallback : check_integer(L, arg);
}

std::string check_string(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TSTRING) type_error(arg, "string", L, arg);
  std::size_t n = 0;
  const char* s = lua_tolstring(L, arg, &n);
  return std::string(s, n);
}

bool check_boolean(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TBOOLEAN) type_error(arg, "boolean", L, arg);
  return lua_toboolean(L, arg) != 0;
}

void check_function(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TFUNCTION) type_error(arg, "function", L, arg);
}

void check_table(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TTABLE) type_error(arg, "table", L, arg);
}

std::optional<Vec3> to_vec(lua_State* L, int index) {
  if (lua_type(L, index) != LUA_TTABLE) return std::nullopt;
  index = absolute(L, index);
  double c[3];
  // {x, y, z} first, then {x=, y=, z=}
  bool ok = true;
  for (int k = 0; k < 3 && ok; ++k) {
    ok = lua_rawgeti(L, index, k + 1) == LUA_TNUMBER;
    c[k] = lua_tonumber(L, -1);
    lua_pop(L, 1);
  }
  if (!ok) {
    ok = true;
    const char* names[3] = {"x", "y", "z"};
    for (int k = 0; k < 3 && ok; ++k) {
      lua_pushstring(L, names[k]);
      ok = lua_rawget(L, index) == LUA_TNUMBER;
      c[k] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
  }
  if (!ok) return std::nullopt;
  return Vec3{c[0], c[1], c[2]};
}

Vec3 check_vec(lua_State* L, int arg) {
  if (auto v = to_vec(L, arg)) return *v;
  if (lua_type(L, arg) == LUA_TTABLE)
    throw ArgError{arg, "vector expected ({x, y, z} of numbers), got a table without 3 numbers"};
  type_error(arg, "vector {x, y, z}", L, arg);
}

std::string number_text(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

int int_in(lua_Integer v, const std::string& what, lua_Integer lo, lua_Integer hi) {
  if (v < lo || v > hi)
    throw Error(what + " " + std::to_string(v) + " outside " + std::to_string(lo) + ".." + std::to_string(hi));
  return static_cast<int>(v);
}

std::int64_t check_id(lua_State* L, int arg, std::size_t count, const char* kind) {
  lua_Integer id = check_integer(L, arg);
  if (id < 1 || static_cast<std::size_t>(id) > count) {
    std::string range = count == 0 ? std::string("there are none yet")
                                   : "valid: 1.." + std::to_string(count);
    throw ArgError{arg, std::string("no ") + kind + " " + std::to_string(id) + " (" + range + ")"};
  }
  return id - 1;
}

void* check_udata(lua_State* L, int arg, const char* type) {
  void* p = luaL_testudata(L, arg, type);
  if (!p) type_error(arg, type, L, arg);
  return p;
}

int absolute(lua_State* L, int index) { return lua_absindex(L, index); }

// ---------------------------------------------------------------------------------------------
// Options

Options::Options(lua_State* L, int index, std::string context, int arg)
    : L_(L), index_(absolute(L, index)), empty_(lua_isnoneornil(L, index)),
      context_(std::move(context)) {
  if (!empty_ && lua_type(L, index_) != LUA_TTABLE)
    type_error(arg, "options table", L, index_);
}

int Options::push(const char* key) {
  known_.emplace_back(key);
  if (empty_) {
    lua_pushnil(L_);
    return LUA_TNIL;
  }
  lua_pushstring(L_, key);
  return lua_rawget(L_, index_);
}

bool Options::present(const char* key) {
  int t = push(key);
  lua_pop(L_, 1);
  return t != LUA_TNIL;
}

void Options::field_type_error(const char* key, const char* expected) {
  std::string got = type_name(L_, -1);
  lua_pop(L_, 1);
  throw Error(context_ + ": option '" + key + "' must be " + expected + ", got " + got);
}

int Options::push_checked(const char* key, int lua_type, const char* expected) {
  int t = push(key);
  if (t != LUA_TNIL && t != lua_type) field_type_error(key, expected);
  return t;
}

std::optional<double> Options::number(const char* key) {
  if (push_checked(key, LUA_TNUMBER, "a number") == LUA_TNIL) {
    lua_pop(L_, 1);
    return std::nullopt;
  }
  double v = lua_tonumber(L_, -1);
  lua_pop(L_, 1);
  return v;
}

double Options::number(const char* key, double fallback) { return number(key).value_or(fallback); }

lua_Integer Options::integer(const char* key, lua_Integer fallback) {
  if (push_checked(key, LUA_TNUMBER, "an integer") == LUA_TNIL) {
    lua_pop(L_, 1);
    return fallback;
  }
  int ok = 0;
  lua_Integer v = lua_tointegerx(L_, -1, &ok);
  if (!ok) field_type_error(key, "an integer");
  lua_pop(L_, 1);
  return v;
}

bool Options::boolean(const char* key, bool fallback) {
  if (push_checked(key, LUA_TBOOLEAN, "a boolean (true or false)") == LUA_TNIL) {
    lua_pop(L_, 1);
    return fallback;
  }
  bool v = lua_toboolean(L_, -1) != 0;
  lua_pop(L_, 1);
  return v;
}

std::string Options::string(const char* key, const std::string& fallback) {
  if (push_checked(key, LUA_TSTRING, "a string") == LUA_TNIL) {
    lua_pop(L_, 1);
    return fallback;
  }
  std::string v = lua_tostring(L_, -1);
  lua_pop(L_, 1);
  return v;
}

std::optional<Vec3> Options::vec(const char* key) {
  if (push(key) == LUA_TNIL) {
    lua_pop(L_, 1);
    return std::nullopt;
  }
  auto v = to_vec(L_, -1);
  if (!v) field_type_error(key, "a vector {x, y, z}");
  lua_pop(L_, 1);
  return v;
}

void Options::finish() {
  if (empty_) return;
  lua_pushnil(L_);
  while (lua_next(L_, index_)) {
    lua_pop(L_, 1);  // value
    std::string key;
    if (lua_type(L_, -1) == LUA_TSTRING) {
      key = lua_tostring(L_, -1);
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    } else if (lua_type(L_, -1) == LUA_TNUMBER) {
      key = "[" + std::to_string(lua_tointeger(L_, -1)) + "]";
    } else {
      key = "(a " + type_name(L_, -1) + " key)";
    }
    lua_pop(L_, 1);  // key
    std::vector<std::string> names = known_;
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    throw Error(context_ + ": unknown option '" + key + "' (known options: " + list + ")");
  }
}

// ---------------------------------------------------------------------------------------------
// Documentation

void set_doc(lua_State* L, int index, const std::string& text) {
  index = absolute(L, index);
  luaL_getsubtable(L, LUA_REGISTRYINDEX, kDocsKey);
  lua_pushvalue(L, index);
  lua_pushlstring(L, text.data(), text.size());
  lua_rawset(L, -3);
  lua_pop(L, 1);
}

void push_doc(lua_State* L, int index) {
  index = absolute(L, index);
  luaL_getsubtable(L, LUA_REGISTRYINDEX, kDocsKey);
  lua_pushvalue(L, index);
  lua_rawget(L, -2);
  lua_remove(L, -2);
}

void register_functions(lua_State* L, int table, std::span<const Function> functions) {
  table = absolute(L, table);
  for (const Function& f : functions) {
    lua_pushcfunction(L, f.fn);
    set_doc(L, -1, std::string(f.usage) + "\n" + f.summary);
    lua_setfield(L, table, f.name);
  }
}

void new_type(lua_State* L, const char* type, std::span<const Function> methods,
              std::span<const luaL_Reg> metamethods, const char* description) {
  luaL_newmetatable(L, type);
  for (const luaL_Reg& r : metamethods) {
    lua_pushcfunction(L, r.func);
    lua_setfield(L, -2, r.name);
  }
  lua_newtable(L);
  register_functions(L, -1, methods);
  set_doc(L, -1, description);
  // The metatable's __index may already be a function (Array: numeric indexing); keep the method
  // table reachable as `methods` either way, for help() and completion.
  lua_pushvalue(L, -1);
  lua_setfield(L, -3, "methods");
  if (lua_getfield(L, -2, "__index") == LUA_TNIL) {
    lua_pop(L, 1);
    lua_setfield(L, -2, "__index");
  } else {
    lua_pop(L, 2);
  }
}

// ---------------------------------------------------------------------------------------------
// Vectors

void push_vec(lua_State* L, const Vec3& v) {
  lua_createtable(L, 3, 0);
  lua_pushnumber(L, v.x);
  lua_rawseti(L, -2, 1);
  lua_pushnumber(L, v.y);
  lua_rawseti(L, -2, 2);
  lua_pushnumber(L, v.z);
  lua_rawseti(L, -2, 3);
  luaL_setmetatable(L, kVecType);
}

namespace {

int vec_index(lua_State* L) {
  // Only reached for absent keys: x/y/z alias 1/2/3, anything else looks in the methods.
  if (lua_type(L, 2) == LUA_TSTRING) {
    const char* k = lua_tostring(L, 2);
    if (k[0] && !k[1] && k[0] >= 'x' && k[0] <= 'z') {
      lua_rawgeti(L, 1, k[0] - 'x' + 1);
      return 1;
    }
    luaL_getmetatable(L, kVecType);
    lua_getfield(L, -1, "methods");
    lua_pushvalue(L, 2);
    lua_rawget(L, -2);
    return 1;
  }
  return 0;
}

Vec3 vec_arg(lua_State* L, int arg) { return check_vec(L, arg); }

int vec_new(lua_State* L) {
  return guarded(L, [&] {
    if (lua_type(L, 1) == LUA_TTABLE) {
      push_vec(L, check_vec(L, 1));
    } else {
      push_vec(L, {check_number(L, 1), check_number(L, 2), check_number(L, 3)});
    }
    return 1;
  });
}

int vec_add(lua_State* L) {
  return guarded(L, [&] { push_vec(L, vec_arg(L, 1) + vec_arg(L, 2)); return 1; });
}
int vec_sub(lua_State* L) {
  return guarded(L, [&] { push_vec(L, vec_arg(L, 1) - vec_arg(L, 2)); return 1; });
}
int vec_unm(lua_State* L) {
  return guarded(L, [&] { push_vec(L, -vec_arg(L, 1)); return 1; });
}
int vec_mul(lua_State* L) {
  return guarded(L, [&] {
    if (lua_type(L, 1) == LUA_TNUMBER) push_vec(L, vec_arg(L, 2) * lua_tonumber(L, 1));
    else push_vec(L, vec_arg(L, 1) * check_number(L, 2));
    return 1;
  });
}
int vec_div(lua_State* L) {
  return guarded(L, [&] { push_vec(L, vec_arg(L, 1) / check_number(L, 2)); return 1; });
}
int vec_eq(lua_State* L) {
  auto a = to_vec(L, 1), b = to_vec(L, 2);
  lua_pushboolean(L, a && b && *a == *b);
  return 1;
}
int vec_tostring(lua_State* L) {
  auto v = to_vec(L, 1);
  if (!v) return luaL_error(L, "not a vector");
  char buf[96];
  std::snprintf(buf, sizeof buf, "{%.6g, %.6g, %.6g}", v->x, v->y, v->z);
  lua_pushstring(L, buf);
  return 1;
}
int vec_norm(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, norm(vec_arg(L, 1))); return 1; });
}
int vec_dot(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, dot(vec_arg(L, 1), vec_arg(L, 2))); return 1; });
}
int vec_cross(lua_State* L) {
  return guarded(L, [&] { push_vec(L, cross(vec_arg(L, 1), vec_arg(L, 2))); return 1; });
}

}  // namespace

void open_vec(lua_State* L) {
  static const Function methods[] = {
      {"norm", vec_norm, "v:norm() -> number", "Euclidean length."},
      {"dot", vec_dot, "a:dot(b) -> number", "Scalar product."},
      {"cross", vec_cross, "a:cross(b) -> vec", "Vector product."},
  };
  static const luaL_Reg meta[] = {{"__index", vec_index}, {"__add", vec_add},
                                  {"__sub", vec_sub},     {"__unm", vec_unm},
                                  {"__mul", vec_mul},     {"__div", vec_div},
                                  {"__eq", vec_eq},       {"__tostring", vec_tostring}};
  new_type(L, kVecType, methods, meta,
           "vec: a 3-vector, a table {x, y, z} (also .x .y .z); + - * / with numbers,\n"
           "v:norm(), a:dot(b), a:cross(b). Any table {x, y, z} is accepted where a vector is "
           "expected.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"vec", vec_new, "asperity.vec(x, y, z) or asperity.vec{x, y, z} -> vec",
       "A vector with .x/.y/.z, arithmetic and printing."}};
  register_functions(L, -1, fns);
}

int open_asperity(lua_State* L) {
  lua_newtable(L);
  set_doc(L, -1,
          "asperity: discrete element engine for rock joints.\n"
          "  asperity.world{...} creates a world; help(world) lists its methods.\n"
          "  Ids of particles, walls and groups count from 1.\n"
          "  Outputs: asperity.series, asperity.snapshots, asperity.write_json.");
  open_vec(L);
  open_array(L);
  open_world(L);
  open_series(L);
  open_snapshots(L);
  open_io(L);
  open_surface(L);
  open_interrupt(L);
  return 1;
}

}  // namespace asperity::lua
