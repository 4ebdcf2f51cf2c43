// Shared vocabulary of the Lua binding (engine/lua/wrap_*.cpp). Private to engine/lua/.
//
// Design notes
// - Thin: a bound function checks its arguments, makes one engine call and pushes results.
// - Error path. Lua errors longjmp (Debian's liblua5.4 is built as C), which would skip the
//   destructors of any C++ object alive in the frames it crosses. So inside a bound function
//   nothing raises a Lua error directly: the argument checks below throw C++ exceptions
//   (ArgError, asperity::Error), and `guarded` catches everything at the boundary, pushes the
//   message while inside the catch block, and calls lua_error only after the catch block has
//   ended and every C++ object of the function is gone. Script callbacks are run with
//   lua_pcall; their error value is left on the stack and re-raised the same way
//   (PendingLuaError), so a callback's own "file:line: message" reaches the user unchanged.
//   Only raw table accesses (no metamethods, which could raise) are used inside guarded code.
// - Ids. Lua counts from 1, the engine from 0. Every particle, wall and group id crossing the
//   binding is shifted by one so that `world:positions()[id]` is the particle `id`, and ids are
//   checked against the current counts with a message naming the valid range.
// - Options are tables with named fields; unknown fields are errors that name the field and
//   list the known ones (Options::finish), and wrong types name the field and the expected type.
// - Vectors are tables {x, y, z} with a shared metatable (`asperity.vec`) giving .x/.y/.z,
//   arithmetic and a readable __tostring; any table {x, y, z} or {x=, y=, z=} is accepted.
// - Every bound function carries a usage line and a summary for help() and tab completion.
#pragma once

#include <lua.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "asperity/error.hpp"
#include "asperity/io.hpp"
#include "asperity/vec3.hpp"

namespace asperity::lua {

// A bad argument: becomes "bad argument #arg to 'name' (message)", as luaL_argerror would.
struct ArgError {
  int arg;
  std::string message;
};

// The error value of a failed lua_pcall is on top of the stack: re-raise it as it is.
struct PendingLuaError {};

// Raised by world:run/cycle when Ctrl-C stopped the run; reaches Lua as an interruption
// (interrupt.hpp), not a string.
struct Interrupted : Error {
  using Error::Error;
};

// Pushes the message for the exception being handled (call only inside a catch block).
void push_current_exception(lua_State* L);

template <class Body>
int guarded(lua_State* L, Body&& body) {
  try {
    return body();
  } catch (...) {
    push_current_exception(L);
  }
  return lua_error(L);  // outside the catch block: nothing of ours is left to destroy
}

// --- argument checks (throw ArgError) ------------------------------------------------------
std::string type_name(lua_State* L, int index);  // honours __name, like luaL_typeerror
[[noreturn]] void type_error(int arg, const char* expected, lua_State* L, int index);
double check_number(lua_State* L, int arg);
double opt_number(lua_State* L, int arg, double fallback);
lua_Integer check_integer(lua_State* L, int arg);
lua_Integer opt_integer(lua_State* L, int arg, lua_Integer fallback);
std::string check_string(lua_State* L, int arg);
bool check_boolean(lua_State* L, int arg);
void check_function(lua_State* L, int arg);
void check_table(lua_State* L, int arg);
Vec3 check_vec(lua_State* L, int arg);
// A number as a user wrote it: "6", "0.5", "1e+300", "nan" (std::to_string would give "6.000000").
std::string number_text(double v);
// v as an int, or an Error naming `what` when it lies outside [lo, hi] (a plain cast would wrap).
int int_in(lua_Integer v, const std::string& what, lua_Integer lo, lua_Integer hi);
// A 1-based Lua id -> 0-based engine index; `count` items exist. kind: "particle", "wall"...
std::int64_t check_id(lua_State* L, int arg, std::size_t count, const char* kind);

// Reads a vector from any index without raising; nullopt if it is not one.
std::optional<Vec3> to_vec(lua_State* L, int index);

void* check_udata(lua_State* L, int arg, const char* type);

// --- pushing -------------------------------------------------------------------------------
void push_vec(lua_State* L, const Vec3& v);
int absolute(lua_State* L, int index);

// --- options tables ------------------------------------------------------------------------
class Options {
 public:
  // index: where the table is (nil or none: every field absent). context: used in messages,
  // e.g. "world:run". arg: the argument number (for a "table expected" error).
  Options(lua_State* L, int index, std::string context, int arg);

  bool present(const char* key);  // non-nil; marks the key as known
  double number(const char* key, double fallback);
  std::optional<double> number(const char* key);
  lua_Integer integer(const char* key, lua_Integer fallback);
  bool boolean(const char* key, bool fallback);
  std::string string(const char* key, const std::string& fallback);
  std::optional<Vec3> vec(const char* key);
  // Pushes the field's value (nil if absent) and returns its Lua type; marks the key as known.
  int push(const char* key);
  // Field of the given Lua type or absent; otherwise an error naming the field.
  int push_checked(const char* key, int lua_type, const char* expected);
  // Errors on every field that was not asked for, naming it and listing the known ones.
  void finish();
  const std::string& context() const { return context_; }

 private:
  [[noreturn]] void field_type_error(const char* key, const char* expected);
  lua_State* L_;
  int index_;
  bool empty_;
  std::string context_;
  std::vector<std::string> known_;
};

// --- registration and documentation --------------------------------------------------------
struct Function {
  const char* name;
  lua_CFunction fn;
  const char* usage;    // e.g. "world:cycle(n) -> steps"
  const char* summary;  // one or a few lines
};

// Sets table[name] = fn for each, and records usage + summary for help().
void register_functions(lua_State* L, int table, std::span<const Function> functions);
// Attaches a description to the value at `index` (a type's method table, the module table).
void set_doc(lua_State* L, int index, const std::string& text);
// Pushes the documentation string of the value at `index`, or nil.
void push_doc(lua_State* L, int index);

// Creates the metatable `type` (luaL_newmetatable) with its methods as __index, the given
// metamethods, and the type's description. Leaves the metatable on the stack.
void new_type(lua_State* L, const char* type, std::span<const Function> methods,
              std::span<const luaL_Reg> metamethods, const char* description);

// --- the pieces of the module (each wrap_*.cpp fills its part of the table on top) ----------
void open_vec(lua_State* L);
void open_array(lua_State* L);
void open_world(lua_State* L);
void open_series(lua_State* L);
void open_snapshots(lua_State* L);
void open_io(lua_State* L);
void open_surface(lua_State* L);  // asperity.surface (wrap_surface.cpp)
void open_interrupt(lua_State* L);  // asperity.is_interrupted (interrupt.cpp)

// The `asperity` module table, complete (pushed).
int open_asperity(lua_State* L);

// Array handle (wrap_array.cpp): a rows x cols matrix of doubles owned by Lua.
struct Array {
  std::vector<double> data;
  std::size_t cols = 1;
  std::size_t rows() const { return cols ? data.size() / cols : 0; }
};
inline constexpr const char* kArrayType = "asperity.Array";
Array& push_array(lua_State* L, std::vector<double> data, std::size_t cols);
Array* to_array(lua_State* L, int index);
// Numbers from an Array, a flat table of numbers or a table of rows ({x,y,z} or vecs). Returns
// the values flat; cols_out receives the row width (1 for flat tables).
std::vector<double> check_numbers(lua_State* L, int arg, std::size_t* cols_out);

// A table of name = number|string|boolean (nil/none: empty) -> HDF5 attributes.
io::Attributes attributes_from(lua_State* L, int index, const std::string& context);

}  // namespace asperity::lua
