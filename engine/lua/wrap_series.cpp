// asperity.series: a time-series recorder (io::Series) for Lua.
//
//   local s = asperity.series{"time [s]", "kinetic [J]", {"ratio", ""}}
//   s:record{time = w:time(), kinetic = e.kinetic, ratio = r}   -- or s:record(t, ke, r)
//   s:write("out/energy")            -- out/energy.h5 and out/energy.csv
//   s:plot{file = "out/energy.png", y = {"kinetic"}}
//
// Columns are declared once, with units, and every row must give every column: a missing or
// misspelled name is an error at the record call, not a silent hole in the data.
#include <new>

#include "asperity/io.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {

constexpr const char* kSeriesType = "asperity.Series";

io::Series& series_arg(lua_State* L) {
  return *static_cast<io::Series*>(check_udata(L, 1, kSeriesType));
}

// "name [unit]" -> (name, unit); "name" -> (name, "").
std::pair<std::string, std::string> parse_column(const std::string& spec) {
  auto open = spec.rfind(" [");
  if (open != std::string::npos && spec.size() > open + 2 && spec.back() == ']')
    return {spec.substr(0, open), spec.substr(open + 2, spec.size() - open - 3)};
  return {spec, ""};
}

}  // namespace

io::Attributes attributes_from(lua_State* L, int index, const std::string& context) {
  io::Attributes out;
  if (lua_isnoneornil(L, index)) return out;
  if (lua_type(L, index) != LUA_TTABLE) throw Error(context + ": attributes must be a table");
  index = absolute(L, index);
  lua_pushnil(L);
  while (lua_next(L, index)) {
    if (lua_type(L, -2) != LUA_TSTRING) throw Error(context + ": attribute names must be strings");
    std::string key = lua_tostring(L, -2);
    switch (lua_type(L, -1)) {
      case LUA_TNUMBER:
        if (lua_isinteger(L, -1)) out.emplace_back(key, std::int64_t{lua_tointeger(L, -1)});
        else out.emplace_back(key, lua_tonumber(L, -1));
        break;
      case LUA_TSTRING: out.emplace_back(key, std::string(lua_tostring(L, -1))); break;
      case LUA_TBOOLEAN: out.emplace_back(key, std::int64_t{lua_toboolean(L, -1)}); break;
      default:
        throw Error(context + ": attribute '" + key + "' must be a number, string or boolean, got " +
                    type_name(L, -1));
    }
    lua_pop(L, 1);
  }
  return out;
}

namespace {

int series_new(lua_State* L) {
  return guarded(L, [&] {
    check_table(L, 1);
    std::vector<std::pair<std::string, std::string>> columns;
    auto n = static_cast<lua_Integer>(lua_rawlen(L, 1));
    for (lua_Integer i = 1; i <= n; ++i) {
      int t = lua_rawgeti(L, 1, i);
      if (t == LUA_TSTRING) {
        columns.push_back(parse_column(lua_tostring(L, -1)));
      } else if (t == LUA_TTABLE) {
        lua_rawgeti(L, -1, 1);
        lua_rawgeti(L, -2, 2);
        if (lua_type(L, -2) != LUA_TSTRING || !(lua_type(L, -1) == LUA_TSTRING || lua_isnil(L, -1)))
          throw ArgError{1, "column " + std::to_string(i) + ": {name, unit} must be strings"};
        columns.emplace_back(lua_tostring(L, -2), lua_isnil(L, -1) ? "" : lua_tostring(L, -1));
        lua_pop(L, 2);
      } else {
        throw ArgError{1, "column " + std::to_string(i) + " must be \"name [unit]\" or {name, unit}"};
      }
      lua_pop(L, 1);
    }
    // Named fields: only `attributes`.
    io::Attributes attributes;
    lua_pushnil(L);
    while (lua_next(L, 1)) {
      bool positional = lua_isinteger(L, -2) && lua_tointeger(L, -2) >= 1 && lua_tointeger(L, -2) <= n;
      if (!positional) {
        if (lua_type(L, -2) == LUA_TSTRING && std::string(lua_tostring(L, -2)) == "attributes") {
          attributes = attributes_from(L, -1, "asperity.series");
        } else {
          std::string key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : type_name(L, -2);
          throw Error("asperity.series: unknown option '" + key +
                      "' (give columns as a list, and optionally attributes = {...})");
        }
      }
      lua_pop(L, 1);
    }
    void* mem = lua_newuserdatauv(L, sizeof(io::Series), 0);
    auto* s = new (mem) io::Series(std::move(columns));
    s->attributes() = std::move(attributes);
    luaL_setmetatable(L, kSeriesType);
    return 1;
  });
}

int series_gc(lua_State* L) {
  if (void* p = luaL_testudata(L, 1, kSeriesType)) static_cast<io::Series*>(p)->~Series();
  return 0;
}

int series_tostring(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    std::string text = "Series(" + std::to_string(s.row_count()) + " rows:";
    for (const io::Column& c : s.columns()) text += " " + c.label();
    text += ")";
    lua_pushstring(L, text.c_str());
    return 1;
  });
}

int series_record(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    std::vector<double> row(s.column_count());
    if (lua_type(L, 2) == LUA_TTABLE) {
      for (std::size_t j = 0; j < row.size(); ++j) {
        const std::string& name = s.column(j).name;
        lua_pushstring(L, name.c_str());
        int t = lua_rawget(L, 2);
        if (t == LUA_TNIL) throw Error("series:record: no value for column '" + name + "'");
        if (t != LUA_TNUMBER)
          throw Error("series:record: column '" + name + "' must be a number, got " + type_name(L, -1));
        row[j] = lua_tonumber(L, -1);
        lua_pop(L, 1);
      }
      lua_pushnil(L);
      while (lua_next(L, 2)) {
        lua_pop(L, 1);
        if (lua_type(L, -1) != LUA_TSTRING || s.find(lua_tostring(L, -1)) < 0) {
          std::string key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "(" + type_name(L, -1) + ")";
          std::string names;
          for (const io::Column& c : s.columns()) names += (names.empty() ? "" : ", ") + c.name;
          throw Error("series:record: unknown column '" + key + "' (columns: " + names + ")");
        }
      }
    } else {
      int given = lua_gettop(L) - 1;
      if (given != static_cast<int>(row.size()))
        throw Error("series:record: " + std::to_string(row.size()) + " values expected (one per column), got " +
                    std::to_string(given));
      for (std::size_t j = 0; j < row.size(); ++j) row[j] = check_number(L, static_cast<int>(j) + 2);
    }
    s.append_row(row);
    return 0;
  });
}

std::size_t column_arg(lua_State* L, int arg, const io::Series& s) {
  if (lua_type(L, arg) == LUA_TNUMBER) {
    lua_Integer j = check_integer(L, arg);
    if (j < 1 || static_cast<std::size_t>(j) > s.column_count())
      throw ArgError{arg, "no column " + std::to_string(j)};
    return static_cast<std::size_t>(j - 1);
  }
  std::string name = check_string(L, arg);
  int j = s.find(name);
  if (j < 0) {
    std::string names;
    for (const io::Column& c : s.columns()) names += (names.empty() ? "" : ", ") + c.name;
    throw ArgError{arg, "no column '" + name + "' (columns: " + names + ")"};
  }
  return static_cast<std::size_t>(j);
}

int series_column(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    push_array(L, s.column(column_arg(L, 2, s)).values, 1);
    return 1;
  });
}

int series_last(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    const io::Column& c = s.column(column_arg(L, 2, s));
    if (c.values.empty()) lua_pushnil(L);
    else lua_pushnumber(L, c.values.back());
    return 1;
  });
}

int series_rows(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(series_arg(L).row_count()));
    return 1;
  });
}

int series_names(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    lua_createtable(L, static_cast<int>(s.column_count()), 0);
    lua_createtable(L, static_cast<int>(s.column_count()), 0);
    for (std::size_t j = 0; j < s.column_count(); ++j) {
      lua_pushstring(L, s.column(j).name.c_str());
      lua_rawseti(L, -3, static_cast<lua_Integer>(j + 1));
      lua_pushstring(L, s.column(j).unit.c_str());
      lua_rawseti(L, -2, static_cast<lua_Integer>(j + 1));
    }
    return 2;
  });
}

int series_set_attribute(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    lua_createtable(L, 0, 1);
    lua_pushvalue(L, 3);
    lua_setfield(L, -2, check_string(L, 2).c_str());
    for (auto& a : attributes_from(L, -1, "series:set_attribute")) {
      std::erase_if(s.attributes(), [&](const auto& b) { return b.first == a.first; });
      s.attributes().push_back(std::move(a));
    }
    return 0;
  });
}

int series_clear(lua_State* L) {
  return guarded(L, [&] {
    series_arg(L).clear();
    return 0;
  });
}

int series_write_h5(lua_State* L) {
  return guarded(L, [&] {
    series_arg(L).write_hdf5(check_string(L, 2));
    return 0;
  });
}

int series_write_csv(lua_State* L) {
  return guarded(L, [&] {
    series_arg(L).write_csv(check_string(L, 2));
    return 0;
  });
}

int series_write(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    std::string prefix = check_string(L, 2);
    s.write_hdf5(prefix + ".h5");
    s.write_csv(prefix + ".csv");
    lua_pushstring(L, (prefix + ".h5").c_str());
    lua_pushstring(L, (prefix + ".csv").c_str());
    return 2;
  });
}

int series_plot(lua_State* L) {
  return guarded(L, [&] {
    io::Series& s = series_arg(L);
    Options o(L, 2, "series:plot", 2);
    std::string file = o.string("file", "");
    if (file.empty()) throw Error("series:plot: give file = \"name.png\"");
    std::size_t x = 0;
    if (o.push("x") != LUA_TNIL) x = column_arg(L, lua_gettop(L), s);
    lua_pop(L, 1);
    std::vector<io::Column> ys;
    int t = o.push("y");
    int yi = lua_gettop(L);
    if (t == LUA_TSTRING || t == LUA_TNUMBER) {
      ys.push_back(s.column(column_arg(L, yi, s)));
    } else if (t == LUA_TTABLE) {
      auto n = static_cast<lua_Integer>(lua_rawlen(L, yi));
      for (lua_Integer i = 1; i <= n; ++i) {
        lua_rawgeti(L, yi, i);
        ys.push_back(s.column(column_arg(L, lua_gettop(L), s)));
        lua_pop(L, 1);
      }
    } else if (t == LUA_TNIL) {
      for (std::size_t j = 0; j < s.column_count(); ++j)
        if (j != x) ys.push_back(s.column(j));
    } else {
      throw Error("series:plot: option 'y' must be a column name or a list of them");
    }
    lua_pop(L, 1);
    io::PlotOptions p;
    p.title = o.string("title", "");
    p.xlabel = o.string("xlabel", "");
    p.ylabel = o.string("ylabel", "");
    p.logx = o.boolean("logx", false);
    p.logy = o.boolean("logy", false);
    p.points = o.boolean("points", false);
    p.width = static_cast<int>(o.integer("width", p.width));
    p.height = static_cast<int>(o.integer("height", p.height));
    o.finish();
    io::plot_png(file, s.column(x), ys, p);
    lua_pushstring(L, file.c_str());
    return 1;
  });
}

}  // namespace

void open_series(lua_State* L) {
  static const Function methods[] = {
      {"record", series_record, "s:record{name = value, ...} or s:record(v1, v2, ...)",
       "Appends a row: every column must be given, unknown names are errors."},
      {"column", series_column, "s:column(name or index) -> Array", "The recorded values."},
      {"last", series_last, "s:last(name) -> number or nil", "The last recorded value."},
      {"rows", series_rows, "s:rows() -> n", "Rows recorded."},
      {"names", series_names, "s:names() -> {names}, {units}", "Column names and units."},
      {"set_attribute", series_set_attribute, "s:set_attribute(name, value)",
       "A number or string stored with the HDF5 file (parameters of the run)."},
      {"clear", series_clear, "s:clear()", "Forgets the recorded rows."},
      {"write_h5", series_write_h5, "s:write_h5(path)",
       "HDF5: one dataset per column with a `units` attribute."},
      {"write_csv", series_write_csv, "s:write_csv(path)", "CSV with a `name [unit]` header."},
      {"write", series_write, "s:write(prefix) -> h5_path, csv_path", "Both, as prefix.h5 and prefix.csv."},
      {"plot", series_plot,
       "s:plot{file= [, x=] [, y=] [, title=] [, xlabel=] [, ylabel=] [, logx=] [, logy=]\n"
       "  [, points=] [, width=] [, height=]} -> file",
       "A PNG drawn by gnuplot: y (a name or a list; default all but x) against x (default the\n"
       "first column), axes labelled with names and units."},
  };
  static const luaL_Reg meta[] = {{"__gc", series_gc}, {"__tostring", series_tostring}};
  new_type(L, kSeriesType, methods, meta,
           "Series: named columns with units, recorded row by row, written to HDF5 and CSV.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"series", series_new, "asperity.series{\"name [unit]\", ... [, attributes = {...}]} -> Series",
       "A time-series recorder. Columns as \"name [unit]\" or {name, unit}."},
  };
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
