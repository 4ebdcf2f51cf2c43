// Module-level functions of `asperity`: JSON, HDF5 read-back, directories, plots of arrays,
// clocks, version information.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "asperity/io.hpp"
#include "asperity/world.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {

// Lua value -> Json. Tables with keys 1..n are arrays, others objects with sorted keys (so the
// same table always gives the same file).
io::Json to_json(lua_State* L, int index, int depth, const std::string& where) {
  index = absolute(L, index);
  if (depth > 64) throw Error("asperity.write_json: nesting deeper than 64 at " + where + " (a cycle?)");
  // Each level holds a key and a value on the Lua stack, which a C function must reserve: past
  // LUA_MINSTACK slots the pushes would write beyond the stack.
  if (!lua_checkstack(L, 4)) throw Error("asperity.write_json: out of Lua stack at " + where);
  switch (lua_type(L, index)) {
    case LUA_TNIL: return nullptr;
    case LUA_TBOOLEAN: return lua_toboolean(L, index) != 0;
    case LUA_TNUMBER:
      if (lua_isinteger(L, index)) return static_cast<std::int64_t>(lua_tointeger(L, index));
      return lua_tonumber(L, index);
    case LUA_TSTRING: return std::string(lua_tostring(L, index));
    case LUA_TUSERDATA:
      if (Array* a = to_array(L, index)) {
        io::Json::Array out;
        for (std::size_t i = 0; i < a->rows(); ++i) {
          if (a->cols == 1) {
            out.emplace_back(a->data[i]);
          } else {
            io::Json::Array row;
            for (std::size_t j = 0; j < a->cols; ++j) row.emplace_back(a->data[i * a->cols + j]);
            out.emplace_back(std::move(row));
          }
        }
        return out;
      }
      break;
    case LUA_TTABLE: {
      auto n = static_cast<lua_Integer>(lua_rawlen(L, index));
      lua_Integer count = 0;
      bool sequence = true;
      lua_pushnil(L);
      while (lua_next(L, index)) {
        ++count;
        if (!lua_isinteger(L, -2) || lua_tointeger(L, -2) < 1 || lua_tointeger(L, -2) > n)
          sequence = false;
        lua_pop(L, 1);
      }
      if (sequence && count == n && n > 0) {
        io::Json::Array out;
        for (lua_Integer i = 1; i <= n; ++i) {
          lua_rawgeti(L, index, i);
          out.push_back(to_json(L, -1, depth + 1, where + "[" + std::to_string(i) + "]"));
          lua_pop(L, 1);
        }
        return out;
      }
      io::Json::Object out;
      lua_pushnil(L);
      while (lua_next(L, index)) {
        std::string key;
        if (lua_type(L, -2) == LUA_TSTRING) key = lua_tostring(L, -2);
        else if (lua_isinteger(L, -2)) key = std::to_string(lua_tointeger(L, -2));
        else throw Error("asperity.write_json: key of type " + type_name(L, -2) + " at " + where);
        out.emplace_back(key, to_json(L, -1, depth + 1, where + "." + key));
        lua_pop(L, 1);
      }
      std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      return out;
    }
    default: break;
  }
  throw Error("asperity.write_json: cannot write a " + type_name(L, index) + " (at " + where + ")");
}

int l_write_json(lua_State* L) {
  return guarded(L, [&] {
    std::string path = check_string(L, 1);
    if (lua_isnone(L, 2)) throw ArgError{2, "value expected"};
    io::write_json(path, to_json(L, 2, 0, "value"));
    return 0;
  });
}

int l_json(lua_State* L) {
  return guarded(L, [&] {
    if (lua_isnone(L, 1)) throw ArgError{1, "value expected"};
    // Bounded: an indent is repeated at every level, and 1e6 on a table 60 deep asks for gigabytes.
    const lua_Integer indent = opt_integer(L, 2, 2);
    if (indent < 0 || indent > 16) throw ArgError{2, "indent must be 0..16 spaces, got " + std::to_string(indent)};
    std::string text = io::to_json_text(to_json(L, 1, 0, "value"), static_cast<int>(indent));
    lua_pushlstring(L, text.data(), text.size());
    return 1;
  });
}

int l_read_h5(lua_State* L) {
  return guarded(L, [&] {
    std::string path = check_string(L, 1);
    std::string dataset = check_string(L, 2);
    std::vector<std::size_t> shape = io::hdf5_shape(path, dataset);
    std::vector<double> data = io::read_hdf5(path, dataset);
    // 2-D datasets keep their rows; higher ranks come back flat.
    std::size_t cols = shape.size() == 2 && shape[1] > 0 ? shape[1] : 1;
    push_array(L, std::move(data), cols);
    return 1;
  });
}

int l_h5_datasets(lua_State* L) {
  return guarded(L, [&] {
    std::vector<std::string> names = io::hdf5_datasets(check_string(L, 1));
    lua_createtable(L, static_cast<int>(names.size()), 0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      lua_pushstring(L, names[i].c_str());
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}

int l_h5_attribute(lua_State* L) {
  return guarded(L, [&] {
    std::string path = check_string(L, 1);
    std::string object = check_string(L, 2);
    std::string name = check_string(L, 3);
    auto a = io::read_hdf5_attribute(path, object, name);
    if (!a) lua_pushnil(L);
    else if (auto* d = std::get_if<double>(&*a)) lua_pushnumber(L, *d);
    else if (auto* i = std::get_if<std::int64_t>(&*a)) lua_pushinteger(L, *i);
    else lua_pushstring(L, std::get<std::string>(*a).c_str());
    return 1;
  });
}

int l_mkdir(lua_State* L) {
  return guarded(L, [&] {
    std::string path = check_string(L, 1);
    io::make_directories(path);
    lua_pushstring(L, path.c_str());
    return 1;
  });
}

int l_remove_all(lua_State* L) {
  return guarded(L, [&] {
    const std::string path = check_string(L, 1);
    if (path.empty() || path == "/" || path == "." || path == "..")
      throw ArgError{1, "refusing to remove '" + path + "'"};
    std::error_code ec;
    const auto n = std::filesystem::remove_all(path, ec);
    if (ec) throw Error("asperity.remove_all: cannot remove '" + path + "': " + ec.message());
    lua_pushinteger(L, static_cast<lua_Integer>(n));
    return 1;
  });
}

// A column for plotting from an Array or a table of numbers.
io::Column column_from(lua_State* L, int index, const std::string& label, const char* what) {
  std::size_t cols = 1;
  std::vector<double> v;
  if (to_array(L, index) || lua_type(L, index) == LUA_TTABLE) v = check_numbers(L, index, &cols);
  else throw Error(std::string("asperity.plot: ") + what + " must be an Array or a table of numbers");
  if (cols != 1) throw Error(std::string("asperity.plot: ") + what + " must have one column");
  io::Column c;
  auto open = label.rfind(" [");
  if (open != std::string::npos && label.back() == ']') {
    c.name = label.substr(0, open);
    c.unit = label.substr(open + 2, label.size() - open - 3);
  } else {
    c.name = label;
  }
  c.values = std::move(v);
  return c;
}

int l_plot(lua_State* L) {
  return guarded(L, [&] {
    Options o(L, 1, "asperity.plot", 1);
    std::string file = o.string("file", "");
    if (file.empty()) throw Error("asperity.plot: give file = \"name.png\"");
    io::PlotOptions p;
    p.title = o.string("title", "");
    std::string xlabel = o.string("xlabel", "x");
    p.ylabel = o.string("ylabel", "");
    p.logx = o.boolean("logx", false);
    p.logy = o.boolean("logy", false);
    p.points = o.boolean("points", false);
    p.width = static_cast<int>(o.integer("width", p.width));
    p.height = static_cast<int>(o.integer("height", p.height));
    std::vector<std::string> labels;
    if (o.push_checked("labels", LUA_TTABLE, "a list of strings") == LUA_TTABLE) {
      auto n = static_cast<lua_Integer>(lua_rawlen(L, -1));
      for (lua_Integer i = 1; i <= n; ++i) {
        lua_rawgeti(L, -1, i);
        labels.push_back(lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "y" + std::to_string(i));
        lua_pop(L, 1);
      }
    }
    lua_pop(L, 1);
    if (o.push("x") == LUA_TNIL) throw Error("asperity.plot: give x = Array or {numbers}");
    io::Column x = column_from(L, -1, xlabel, "x");
    lua_pop(L, 1);
    if (o.push("y") == LUA_TNIL) throw Error("asperity.plot: give y = Array, {numbers} or a list of them");
    int yi = lua_gettop(L);
    std::vector<io::Column> ys;
    auto label = [&](std::size_t k) { return k < labels.size() ? labels[k] : "y" + std::to_string(k + 1); };
    bool list = false;
    if (lua_type(L, yi) == LUA_TTABLE) {
      int t = lua_rawgeti(L, yi, 1);
      list = t == LUA_TTABLE || (t == LUA_TUSERDATA && to_array(L, -1));
      lua_pop(L, 1);
    }
    if (list) {
      auto n = static_cast<lua_Integer>(lua_rawlen(L, yi));
      for (lua_Integer i = 1; i <= n; ++i) {
        lua_rawgeti(L, yi, i);
        ys.push_back(column_from(L, -1, label(static_cast<std::size_t>(i - 1)), "each y"));
        lua_pop(L, 1);
      }
    } else {
      ys.push_back(column_from(L, yi, label(0), "y"));
    }
    lua_pop(L, 1);
    o.finish();
    io::plot_png(file, x, ys, p);
    lua_pushstring(L, file.c_str());
    return 1;
  });
}

int l_wall_time(lua_State* L) {
  using namespace std::chrono;
  lua_pushnumber(L, duration<double>(steady_clock::now().time_since_epoch()).count());
  return 1;
}

// The process's resident memory now (/proc/self/statm, resident pages) and its peak
// (getrusage: ru_maxrss, in KiB on Linux), in bytes; 0 where the system does not say.
int l_memory(lua_State* L) {
  double resident = 0, peak = 0;
  std::ifstream statm("/proc/self/statm");
  double total_pages = 0, resident_pages = 0;
  if (statm >> total_pages >> resident_pages) resident = resident_pages * double(sysconf(_SC_PAGESIZE));
  rusage ru{};
  if (getrusage(RUSAGE_SELF, &ru) == 0) peak = 1024.0 * double(ru.ru_maxrss);
  lua_createtable(L, 0, 2);
  lua_pushnumber(L, resident);
  lua_setfield(L, -2, "resident");
  lua_pushnumber(L, std::max(peak, resident));
  lua_setfield(L, -2, "peak");
  return 1;
}

int l_simd_architectures(lua_State* L) {
  return guarded(L, [&] {
    std::vector<std::string> names = available_simd_architectures();
    lua_createtable(L, static_cast<int>(names.size()), 0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      lua_pushstring(L, names[i].c_str());
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}

}  // namespace

void open_io(lua_State* L) {
  static const Function fns[] = {
      {"write_json", l_write_json, "asperity.write_json(path, value)",
       "Writes a Lua value (tables, numbers, strings, booleans, Arrays) as JSON."},
      {"json", l_json, "asperity.json(value [, indent]) -> string", "The JSON text of a value."},
      {"read_h5", l_read_h5, "asperity.read_h5(path, dataset) -> Array",
       "Reads a numeric HDF5 dataset (e.g. \"/particles/position\") back."},
      {"h5_datasets", l_h5_datasets, "asperity.h5_datasets(path) -> {names}", "Datasets in an HDF5 file."},
      {"h5_attribute", l_h5_attribute, "asperity.h5_attribute(path, object, name) -> value or nil",
       "An attribute (\"/\" for the file's own), e.g. h5_attribute(f, \"/time\", \"units\")."},
      {"mkdir", l_mkdir, "asperity.mkdir(path) -> path", "Creates a directory and its parents if needed."},
      {"remove_all", l_remove_all, "asperity.remove_all(path) -> n",
       "Removes a file, or a directory and everything in it (n: entries removed; 0 if there was\n"
       "nothing)."},
      {"plot", l_plot,
       "asperity.plot{file=, x=, y= [, labels=] [, xlabel=] [, ylabel=] [, title=] [, logx=]\n"
       "  [, logy=] [, points=]} -> file",
       "A PNG drawn by gnuplot from Arrays or tables. Labels as \"name [unit]\"."},
      {"wall_time", l_wall_time, "asperity.wall_time() -> s", "A monotonic clock, for timing."},
      {"memory", l_memory, "asperity.memory() -> {resident=, peak=}",
       "This process's resident memory now and at its peak, in bytes (0 where the system does not\n"
       "say): what a run needs, e.g. to plan a larger one."},
      {"simd_architectures", l_simd_architectures, "asperity.simd_architectures() -> {names}",
       "What this CPU supports, best first."},
  };
  register_functions(L, -1, fns);
  lua_pushstring(L, ASPERITY_VERSION);
  lua_setfield(L, -2, "version");
  lua_pushstring(L, ASPERITY_BUILD_TYPE);
  lua_setfield(L, -2, "build_type");
}

}  // namespace asperity::lua
