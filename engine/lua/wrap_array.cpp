// asperity.Array: a rows x cols matrix of doubles owned by Lua, the form of every bulk read
// (world:positions(), series:column(), asperity.read_h5) and accepted by every bulk write.
//
// Why a handle rather than Lua tables: a table of 10^5 {x, y, z} rows costs 10^5 allocations
// and garbage; the handle is one allocation, and its methods (sum, min, max, norms, col) work on
// the whole array in C. a[i] still reads like a table: a number for one column, a vec row
// otherwise; a:row(i) returns the row as separate numbers without allocating.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>

#include "lua/binding.hpp"

namespace asperity::lua {

Array& push_array(lua_State* L, std::vector<double> data, std::size_t cols) {
  void* mem = lua_newuserdatauv(L, sizeof(Array), 0);
  Array* a = new (mem) Array{std::move(data), cols ? cols : 1};
  luaL_setmetatable(L, kArrayType);
  return *a;
}

Array* to_array(lua_State* L, int index) {
  return static_cast<Array*>(luaL_testudata(L, index, kArrayType));
}

std::vector<double> check_numbers(lua_State* L, int arg, std::size_t* cols_out) {
  if (Array* a = to_array(L, arg)) {
    *cols_out = a->cols;
    return a->data;
  }
  if (lua_type(L, arg) != LUA_TTABLE) type_error(arg, "Array or table of numbers", L, arg);
  int t = absolute(L, arg);
  lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, t));
  std::vector<double> out;
  if (n == 0) {
    *cols_out = 1;
    return out;
  }
  if (lua_rawgeti(L, t, 1) == LUA_TTABLE) {
    lua_pop(L, 1);
    // rows: {x, y, z} / vec tables (3 wide), or general rows of equal length
    lua_rawgeti(L, t, 1);
    std::size_t cols = lua_rawlen(L, -1);
    lua_pop(L, 1);
    if (cols == 0) cols = 3;  // {x=, y=, z=} rows
    out.reserve(static_cast<std::size_t>(n) * cols);
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_rawgeti(L, t, i);
      if (cols == 3) {
        auto v = to_vec(L, -1);
        if (!v)
          throw ArgError{arg, "row " + std::to_string(i) + " is not a vector {x, y, z}"};
        out.insert(out.end(), {v->x, v->y, v->z});
      } else {
        if (lua_type(L, -1) != LUA_TTABLE || lua_rawlen(L, -1) != cols)
          throw ArgError{arg, "row " + std::to_string(i) + " does not have " +
                                  std::to_string(cols) + " numbers like row 1"};
        for (std::size_t j = 1; j <= cols; ++j) {
          if (lua_rawgeti(L, -1, static_cast<lua_Integer>(j)) != LUA_TNUMBER)
            throw ArgError{arg, "row " + std::to_string(i) + " has a non-number"};
          out.push_back(lua_tonumber(L, -1));
          lua_pop(L, 1);
        }
      }
      lua_pop(L, 1);
    }
    *cols_out = cols;
    return out;
  }
  lua_pop(L, 1);
  out.reserve(static_cast<std::size_t>(n));
  for (lua_Integer i = 1; i <= n; ++i) {
    if (lua_rawgeti(L, t, i) != LUA_TNUMBER)
      throw ArgError{arg, "element " + std::to_string(i) + " is a " +
                              std::string(luaL_typename(L, -1)) + ", not a number"};
    out.push_back(lua_tonumber(L, -1));
    lua_pop(L, 1);
  }
  *cols_out = 1;
  return out;
}

namespace {

Array& self(lua_State* L) { return *static_cast<Array*>(check_udata(L, 1, kArrayType)); }

std::size_t check_row(lua_State* L, int arg, const Array& a) {
  lua_Integer i = check_integer(L, arg);
  if (i < 1 || static_cast<std::size_t>(i) > a.rows())
    throw ArgError{arg, "row " + std::to_string(i) + " out of range 1.." + std::to_string(a.rows())};
  return static_cast<std::size_t>(i - 1);
}

std::size_t check_col(lua_State* L, int arg, const Array& a) {
  lua_Integer j = check_integer(L, arg);
  if (j < 1 || static_cast<std::size_t>(j) > a.cols)
    throw ArgError{arg, "column " + std::to_string(j) + " out of range 1.." + std::to_string(a.cols)};
  return static_cast<std::size_t>(j - 1);
}

void push_row(lua_State* L, const Array& a, std::size_t i) {
  const double* r = a.data.data() + i * a.cols;
  if (a.cols == 1) {
    lua_pushnumber(L, r[0]);
  } else if (a.cols == 3) {
    push_vec(L, {r[0], r[1], r[2]});
  } else {
    lua_createtable(L, static_cast<int>(a.cols), 0);
    for (std::size_t j = 0; j < a.cols; ++j) {
      lua_pushnumber(L, r[j]);
      lua_rawseti(L, -2, static_cast<lua_Integer>(j + 1));
    }
  }
}

int array_index(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    if (lua_type(L, 2) == LUA_TNUMBER) {
      push_row(L, a, check_row(L, 2, a));
      return 1;
    }
    luaL_getmetatable(L, kArrayType);
    lua_getfield(L, -1, "methods");
    lua_pushvalue(L, 2);
    lua_rawget(L, -2);
    return 1;
  });
}

int array_newindex(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::size_t i = check_row(L, 2, a);
    double* r = a.data.data() + i * a.cols;
    if (a.cols == 1) {
      r[0] = check_number(L, 3);
    } else if (a.cols == 3) {
      Vec3 v = check_vec(L, 3);
      r[0] = v.x, r[1] = v.y, r[2] = v.z;
    } else {
      throw Error("Array: assign rows of wide arrays with a:set(i, j, value)");
    }
    return 0;
  });
}

int array_len(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(self(L).rows()));
    return 1;
  });
}

int array_tostring(lua_State* L) {
  Array* a = to_array(L, 1);
  if (!a) return 0;
  std::string s = "Array(" + std::to_string(a->rows()) + " x " + std::to_string(a->cols) + ")";
  // a short preview helps in the REPL
  std::size_t show = std::min<std::size_t>(a->rows(), 4);
  char buf[64];
  for (std::size_t i = 0; i < show; ++i) {
    s += i ? ", " : ": ";
    if (a->cols > 1) s += "{";
    for (std::size_t j = 0; j < a->cols && j < 4; ++j) {
      std::snprintf(buf, sizeof buf, "%s%.6g", j ? ", " : "", a->data[i * a->cols + j]);
      s += buf;
    }
    if (a->cols > 4) s += ", ...";
    if (a->cols > 1) s += "}";
  }
  if (a->rows() > show) s += ", ...";
  lua_pushlstring(L, s.data(), s.size());
  return 1;
}

int array_gc(lua_State* L) {
  if (Array* a = to_array(L, 1)) a->~Array();
  return 0;
}

int array_new(lua_State* L) {
  return guarded(L, [&] {
    if (lua_type(L, 1) == LUA_TNUMBER) {
      lua_Integer rows = check_integer(L, 1);
      lua_Integer cols = opt_integer(L, 2, 1);
      // Bounded so that rows * cols neither overflows nor asks for more memory than a machine has.
      constexpr lua_Integer kMaxElements = lua_Integer(1) << 28;  // 2 GiB of doubles
      if (rows < 0 || rows > kMaxElements)
        throw ArgError{1, "rows " + std::to_string(rows) + " outside 0.." + std::to_string(kMaxElements)};
      if (cols < 1 || cols > kMaxElements)
        throw ArgError{2, "cols " + std::to_string(cols) + " outside 1.." + std::to_string(kMaxElements)};
      if (rows * cols > kMaxElements)
        throw ArgError{1, std::to_string(rows) + " x " + std::to_string(cols) + " elements, more than " +
                              std::to_string(kMaxElements)};
      double fill = opt_number(L, 3, 0.0);
      push_array(L, std::vector<double>(static_cast<std::size_t>(rows * cols), fill),
                 static_cast<std::size_t>(cols));
      return 1;
    }
    std::size_t cols = 1;
    std::vector<double> v = check_numbers(L, 1, &cols);
    push_array(L, std::move(v), cols);
    return 1;
  });
}

int array_size(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    lua_pushinteger(L, static_cast<lua_Integer>(a.rows()));
    lua_pushinteger(L, static_cast<lua_Integer>(a.cols));
    return 2;
  });
}

int array_row(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::size_t i = check_row(L, 2, a);
    if (a.cols > 100000 || !lua_checkstack(L, static_cast<int>(a.cols)))
      throw Error("a:row: " + std::to_string(a.cols) + " columns are too many to return as values (use a:get)");
    for (std::size_t j = 0; j < a.cols; ++j) lua_pushnumber(L, a.data[i * a.cols + j]);
    return static_cast<int>(a.cols);
  });
}

int array_get(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::size_t i = check_row(L, 2, a);
    std::size_t j = lua_isnoneornil(L, 3) ? 0 : check_col(L, 3, a);
    lua_pushnumber(L, a.data[i * a.cols + j]);
    return 1;
  });
}

int array_set(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::size_t i = check_row(L, 2, a);
    std::size_t j = check_col(L, 3, a);
    a.data[i * a.cols + j] = check_number(L, 4);
    return 0;
  });
}

int array_col(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::size_t j = check_col(L, 2, a);
    std::vector<double> c(a.rows());
    for (std::size_t i = 0; i < c.size(); ++i) c[i] = a.data[i * a.cols + j];
    push_array(L, std::move(c), 1);
    return 1;
  });
}

int array_totable(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    lua_createtable(L, static_cast<int>(a.rows()), 0);
    for (std::size_t i = 0; i < a.rows(); ++i) {
      push_row(L, a, i);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}

int array_flat(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    lua_createtable(L, static_cast<int>(a.data.size()), 0);
    for (std::size_t k = 0; k < a.data.size(); ++k) {
      lua_pushnumber(L, a.data[k]);
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

// Column-wise reductions: one result per column.
template <class Init, class Step, class Finish>
int reduce(lua_State* L, Init init, Step step, Finish finish) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::vector<double> acc(a.cols, init(a));
    for (std::size_t i = 0; i < a.rows(); ++i)
      for (std::size_t j = 0; j < a.cols; ++j) acc[j] = step(acc[j], a.data[i * a.cols + j]);
    if (a.cols > 100000 || !lua_checkstack(L, static_cast<int>(a.cols)))
      throw Error("Array: " + std::to_string(a.cols) + " columns are too many to return as values");
    for (double v : acc) lua_pushnumber(L, finish(v, a));
    return static_cast<int>(a.cols);
  });
}

int array_sum(lua_State* L) {
  return reduce(L, [](const Array&) { return 0.0; }, [](double s, double x) { return s + x; },
                [](double s, const Array&) { return s; });
}
int array_mean(lua_State* L) {
  return reduce(L, [](const Array&) { return 0.0; }, [](double s, double x) { return s + x; },
                [](double s, const Array& a) { return a.rows() ? s / double(a.rows()) : NAN; });
}
int array_min(lua_State* L) {
  return reduce(L, [](const Array&) { return INFINITY; },
                [](double s, double x) { return std::min(s, x); },
                [](double s, const Array&) { return s; });
}
int array_max(lua_State* L) {
  return reduce(L, [](const Array&) { return -INFINITY; },
                [](double s, double x) { return std::max(s, x); },
                [](double s, const Array&) { return s; });
}

int array_norms(lua_State* L) {
  return guarded(L, [&] {
    Array& a = self(L);
    std::vector<double> n(a.rows());
    for (std::size_t i = 0; i < n.size(); ++i) {
      double s = 0;
      for (std::size_t j = 0; j < a.cols; ++j) s += a.data[i * a.cols + j] * a.data[i * a.cols + j];
      n[i] = std::sqrt(s);
    }
    push_array(L, std::move(n), 1);
    return 1;
  });
}

}  // namespace

void open_array(lua_State* L) {
  static const Function methods[] = {
      {"size", array_size, "a:size() -> rows, cols", "Shape of the array (#a is the rows)."},
      {"row", array_row, "a:row(i) -> v1, v2, ...", "Row i as separate numbers (no table)."},
      {"get", array_get, "a:get(i [, j]) -> number", "Element (i, j); j defaults to 1."},
      {"set", array_set, "a:set(i, j, value)", "Sets element (i, j)."},
      {"col", array_col, "a:col(j) -> Array", "Column j as a one-column Array."},
      {"totable", array_totable, "a:totable() -> table",
       "A Lua table: numbers for one column, vec rows for three, tables otherwise."},
      {"flat", array_flat, "a:flat() -> table", "All values row after row, in a flat table."},
      {"sum", array_sum, "a:sum() -> s1, s2, ...", "Sum of each column."},
      {"mean", array_mean, "a:mean() -> m1, m2, ...", "Mean of each column."},
      {"min", array_min, "a:min() -> m1, m2, ...", "Minimum of each column."},
      {"max", array_max, "a:max() -> m1, m2, ...", "Maximum of each column."},
      {"norms", array_norms, "a:norms() -> Array", "Euclidean norm of each row."},
  };
  static const luaL_Reg meta[] = {{"__index", array_index},   {"__newindex", array_newindex},
                                  {"__len", array_len},       {"__tostring", array_tostring},
                                  {"__gc", array_gc}};
  new_type(L, kArrayType, methods, meta,
           "Array: a rows x cols block of numbers (bulk reads and writes).\n"
           "  a[i] is row i (a number for one column, a vec for three); #a rows; a:row(i)\n"
           "  returns the row as numbers. Reductions work per column.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"array", array_new,
       "asperity.array(rows [, cols [, fill]]) or asperity.array(table) -> Array",
       "A new Array, filled with `fill` (0), or from a flat table or a table of rows."}};
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
