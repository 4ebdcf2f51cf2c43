// Lua states for scripts and the REPL: standard libraries, the `asperity` module (also as a
// global, it is the reason the program exists), `help`, the package path to scripts/lib, the
// `params` table, and calls with a traceback-adding message handler as lua.c does.
//
// help() and the REPL's value printer are written in Lua (embedded below): they format text and
// walk tables, which Lua does in a few lines, and any error they meet (a failing __tostring) is
// an ordinary Lua error caught by the pcall around them.
#include "lua/session.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/interrupt.hpp"

namespace asperity::lua {

namespace {

// help(x) and the REPL printer. Receives (asperity, doc, types) as the chunk's arguments.
const char* const kHelpSource = R"lua(
local asperity, doc, types = ...

local function first_line(s) return (s:match("^[^\n]*")) end

local function methods_of(v)
  local mt = getmetatable(v)
  if type(mt) == "table" and type(rawget(mt, "methods")) == "table" then return rawget(mt, "methods") end
end

local function listing(t, out)
  local names = {}
  for k, v in pairs(t) do
    if type(k) == "string" and doc(v) then names[#names + 1] = k end
  end
  table.sort(names)
  for _, k in ipairs(names) do out[#out + 1] = "  " .. first_line(doc(t[k])) end
end

local function help(v)
  local out = {}
  if v == nil then
    out[#out + 1] = doc(asperity)
    out[#out + 1] = "Functions:"
    listing(asperity, out)
    out[#out + 1] = "Types: " .. table.concat((function()
      local n = {} for k in pairs(types) do n[#n + 1] = k end table.sort(n) return n end)(), ", ")
    out[#out + 1] = "help(x) describes x (a function, a world, an Array, ...); help(\"word\") searches."
  elseif type(v) == "string" then
    local hits = {}
    local function search(t)
      for k, f in pairs(t) do
        local d = type(k) == "string" and doc(f)
        if d and (k:find(v, 1, true) or d:find(v, 1, true)) then hits[#hits + 1] = d end
      end
    end
    search(asperity)
    for _, m in pairs(types) do search(m) end
    table.sort(hits)
    if #hits == 0 then out[#out + 1] = "nothing found for '" .. v .. "'" end
    for _, d in ipairs(hits) do out[#out + 1] = d .. "\n" end
  elseif doc(v) and type(v) == "function" then
    out[#out + 1] = doc(v)
  elseif methods_of(v) then
    local m = methods_of(v)
    out[#out + 1] = doc(m) or tostring(v)
    out[#out + 1] = "Methods:"
    listing(m, out)
  elseif type(v) == "table" and doc(v) then
    out[#out + 1] = doc(v)
    listing(v, out)
  else
    out[#out + 1] = "no help for this " .. type(v) .. " (help() lists what there is)"
  end
  print(table.concat(out, "\n"))
end

-- Values as the REPL shows them: tables one level deep, everything else by tostring.
local function repr(v, depth)
  if type(v) == "string" then return depth > 0 and string.format("%q", v) or v end
  if type(v) ~= "table" then return tostring(v) end
  local mt = getmetatable(v)
  if mt and mt.__tostring then return tostring(v) end
  if depth > 1 then return "{...}" end
  local parts, n, shown = {}, #v, 0
  for i = 1, math.min(n, 20) do parts[#parts + 1] = repr(v[i], depth + 1) end
  if n > 20 then parts[#parts + 1] = "... (" .. n .. " items)" end
  local keys = {}
  for k in pairs(v) do
    if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
  end
  table.sort(keys, function(a, b) return tostring(a) < tostring(b) end)
  for _, k in ipairs(keys) do
    shown = shown + 1
    if shown > 20 then parts[#parts + 1] = "..." break end
    local key = (type(k) == "string" and k:match("^[%a_][%w_]*$")) and k or "[" .. repr(k, 1) .. "]"
    parts[#parts + 1] = key .. " = " .. repr(v[k], depth + 1)
  end
  return "{" .. table.concat(parts, ", ") .. "}"
end

local function show(...)
  local parts = {}
  for i = 1, select("#", ...) do parts[i] = repr((select(i, ...)), 0) end
  print(table.concat(parts, "\t"))
end

return help, show
)lua";

int l_doc(lua_State* L) {
  push_doc(L, 1);
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    if (luaL_getmetafield(L, 1, "methods") == LUA_TTABLE) {
      push_doc(L, -1);
      return 1;
    }
    lua_pushnil(L);
  }
  return 1;
}

// lua.c's message handler: add a traceback to string messages. An interruption stays the
// object it is, so that callers tell it by its type, and carries its traceback as a field.
int message_handler(lua_State* L) {
  if (is_interruption(L, 1)) {
    luaL_traceback(L, L, luaL_tolstring(L, 1, nullptr), 1);
    lua_setfield(L, 1, "traceback");
    lua_settop(L, 1);
    return 1;
  }
  const char* msg = lua_tostring(L, 1);
  if (!msg) {
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) return 1;
    msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  }
  luaL_traceback(L, L, msg, 1);
  return 1;
}

void set_package_path(lua_State* L, const std::string& script) {
  std::string dir = scripts_dir();
  std::string path = dir + "/lib/?.lua;" + dir + "/lib/?/init.lua;" + dir + "/?.lua;";
  if (!script.empty()) {
    std::string here = std::filesystem::path(script).parent_path().string();
    path += (here.empty() ? std::string(".") : here) + "/?.lua;";
  }
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "path");
  path += lua_tostring(L, -1);
  lua_pop(L, 1);
  lua_pushstring(L, path.c_str());
  lua_setfield(L, -2, "path");
  lua_pop(L, 1);
}

int open_all(lua_State* L) {
  luaL_openlibs(L);
  luaL_requiref(L, "asperity", open_asperity, 1);  // package.loaded.asperity and the global
  int module = lua_gettop(L);
  lua_pushstring(L, scripts_dir().c_str());
  lua_setfield(L, module, "scripts_dir");
  static const Function doc_fn[] = {
      {"doc", l_doc, "asperity.doc(value) -> string or nil", "The help text of a bound function or type."}};
  register_functions(L, module, doc_fn);

  // help and the printer
  if (luaL_loadbufferx(L, kHelpSource, std::strlen(kHelpSource), "=help", "t") != LUA_OK) return lua_error(L);
  lua_pushvalue(L, module);
  lua_getfield(L, module, "doc");
  lua_newtable(L);
  for (const char* type : {"asperity.World", "asperity.Array", "asperity.Series", "asperity.Snapshots", "asperity.vec", "asperity.HeightMap"}) {
    luaL_getmetatable(L, type);
    lua_getfield(L, -1, "methods");
    lua_setfield(L, -3, type + std::strlen("asperity."));
    lua_pop(L, 1);
  }
  lua_call(L, 3, 2);
  lua_setfield(L, LUA_REGISTRYINDEX, "asperity.show");
  lua_pushvalue(L, -1);
  set_doc(L, -1, "help([x]) -> prints what x is and how to use it; help() lists the API,\n"
                 "help(\"word\") searches it.");
  lua_pop(L, 1);
  lua_setglobal(L, "help");
  lua_pop(L, 1);  // module
  return 0;
}

int traceback_call(lua_State* L, int nargs, int nresults) {
  int base = lua_gettop(L) - nargs;
  lua_pushcfunction(L, message_handler);
  lua_insert(L, base);
  install_interrupt_handler(L);
  int status = lua_pcall(L, nargs, nresults, base);
  lua_remove(L, base);
  return status;
}

}  // namespace

std::string scripts_dir() {
  if (const char* env = std::getenv("ASPERITY_SCRIPTS_DIR"); env && *env) return env;
  return ASPERITY_SCRIPTS_DIR;
}

std::string version_text() {
  std::string simd;
  try {
    simd = World().simd_architecture();
  } catch (const std::exception& e) {
    simd = std::string("unknown (") + e.what() + ")";
  }
  std::string available;
  for (const std::string& a : available_simd_architectures()) available += (available.empty() ? "" : ", ") + a;
  return std::string("asperity ") + ASPERITY_VERSION + " (" + ASPERITY_BUILD_TYPE + " build)\n" +
         "SIMD: " + simd + " (this CPU: " + available + ")\n" + LUA_RELEASE + "\n";
}

Session::Session() : L_(luaL_newstate()) {
  if (!L_) throw Error("cannot create a Lua state (out of memory)");
  lua_pushcfunction(L_, open_all);
  if (lua_pcall(L_, 0, 0, 0) != LUA_OK) {
    std::string msg = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "?";
    lua_close(L_);
    throw Error("cannot load the asperity Lua API: " + msg);
  }
  set_package_path(L_, "");
}

Session::~Session() {
  remove_interrupt_handler();
  lua_close(L_);
}

void Session::set_params(const std::string& script,
                         const std::vector<std::pair<std::string, std::string>>& params) {
  lua_State* L = L_;
  lua_createtable(L, 0, static_cast<int>(params.size()));
  lua_createtable(L, static_cast<int>(params.size()), 1);  // arg
  lua_pushstring(L, script.c_str());
  lua_rawseti(L, -2, 0);
  int i = 0;
  for (const auto& [key, value] : params) {
    lua_pushstring(L, (key + "=" + value).c_str());
    lua_rawseti(L, -2, ++i);
    if (value == "true" || value == "false") lua_pushboolean(L, value == "true");
    else if (lua_stringtonumber(L, value.c_str()) == 0) lua_pushstring(L, value.c_str());
    lua_setfield(L, -3, key.c_str());
  }
  lua_setglobal(L, "arg");
  lua_setglobal(L, "params");
  if (!script.empty()) set_package_path(L, script);
}

bool Session::run_file(const std::string& path, std::string* error) {
  clear_interrupts();
  int status = luaL_loadfilex(L_, path.c_str(), "t");
  if (status == LUA_OK) status = traceback_call(L_, 0, 0);
  return finish(status, error);
}

bool Session::run_string(const std::string& code, const std::string& chunk_name, std::string* error) {
  clear_interrupts();
  int status = luaL_loadbufferx(L_, code.data(), code.size(), chunk_name.c_str(), "t");
  if (status == LUA_OK) status = traceback_call(L_, 0, 0);
  return finish(status, error);
}

bool Session::finish(int status, std::string* error) {
  interrupted_ = status != LUA_OK && is_interruption(L_, -1);
  if (status == LUA_OK) return true;
  int value = lua_gettop(L_);
  if (interrupted_ && lua_getfield(L_, value, "traceback") != LUA_TSTRING) {
    lua_pop(L_, 1);
    luaL_tolstring(L_, value, nullptr);
  }
  const char* msg = lua_tostring(L_, -1);
  if (error) *error = msg ? msg : "(error object without a message)";
  lua_settop(L_, value - 1);
  return false;
}

// Used by repl.cpp.
int call_with_traceback(lua_State* L, int nargs, int nresults) { return traceback_call(L, nargs, nresults); }

}  // namespace asperity::lua
