// asperity.surface: rough surfaces (include/asperity/surface.hpp) from Lua - the spectral
// generator, the reference surfaces S1..S8, height-map files, the roughness analysis, and the
// steps from a synthetic surface to a DEM surface (profilometer, mean plane, surface vs porosity
// particles, noise study). Spec: docs/surfaces.md.
//
//   local s = asperity.surface.generate{name = "S5", n = 365, seed = 1}   -- a HeightMap
//   local r = s:analyze()            -- r.hurst_psd.hurst, r.amplitude.variance, r.psd_radial...
//   s:heights()                      -- Array(ny x nx), row = y index
//   s:save("surface.h5"); s:plot("elevation.png")
//
// Design notes
// - A height map is a userdata (asperity.HeightMap) owning the C++ HeightMap: 365^2 heights stay
//   in one block, and analysis methods run on it without copying through Lua. Bulk data crossing
//   the boundary (heights, lags, spectra, curves) are Arrays, never per-number tables; scalars
//   and small records are plain tables of numbers, ready for asperity.write_json.
// - Parameter names follow the spec and scripts/surface.lua: H, Lc, variance and the anisotropic
//   Hx, Hy, Lcx, Lcy, variance_x, variance_y, in SI units (m, m^2); n, side (m), seed, name.
// - Indices are Lua's: rows and columns of a map from 1, particle ids from 1 (the rows of the
//   positions Array, i.e. world ids), 0 for "no particle".
// - Results of fits that could not be made are NaN, which write_json writes as null.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <numbers>

#include "asperity/surface.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {

namespace sf = asperity::surface;

constexpr const char* kHeightMapType = "asperity.HeightMap";

sf::HeightMap& map_arg(lua_State* L, int arg) {
  return *static_cast<sf::HeightMap*>(check_udata(L, arg, kHeightMapType));
}

sf::HeightMap& push_map(lua_State* L, sf::HeightMap map) {
  void* mem = lua_newuserdatauv(L, sizeof(sf::HeightMap), 0);
  auto* m = new (mem) sf::HeightMap(std::move(map));
  luaL_setmetatable(L, kHeightMapType);
  return *m;
}

// --- pushing results ------------------------------------------------------------------------

void set_number(lua_State* L, const char* key, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, key);
}
void set_integer(lua_State* L, const char* key, lua_Integer v) {
  lua_pushinteger(L, v);
  lua_setfield(L, -2, key);
}
void set_string(lua_State* L, const char* key, const std::string& v) {
  lua_pushlstring(L, v.data(), v.size());
  lua_setfield(L, -2, key);
}
void set_array(lua_State* L, const char* key, std::vector<double> v) {
  push_array(L, std::move(v), 1);
  lua_setfield(L, -2, key);
}

void push_params(lua_State* L, const sf::SurfaceParams& p) {
  lua_createtable(L, 0, 16);
  set_string(L, "name", p.name);
  set_integer(L, "n", p.n);
  set_number(L, "side", p.side);
  set_integer(L, "seed", static_cast<lua_Integer>(p.seed));
  set_number(L, "spacing", p.spacing());
  set_number(L, "Hx", p.hurst_x);
  set_number(L, "Hy", p.hurst_y);
  set_number(L, "Lcx", p.corr_length_x);
  set_number(L, "Lcy", p.corr_length_y);
  set_number(L, "variance", p.variance);
  set_number(L, "variance_x", p.variance_x > 0 ? p.variance_x : p.variance);
  set_number(L, "variance_y", p.variance_y > 0 ? p.variance_y : p.variance);
  if (p.hurst_x == p.hurst_y) set_number(L, "H", p.hurst_x);
  if (p.corr_length_x == p.corr_length_y) set_number(L, "Lc", p.corr_length_x);
  lua_pushboolean(L, p.is_isotropic());
  lua_setfield(L, -2, "isotropic");
}

void push_lag_series(lua_State* L, const sf::LagSeries& s) {
  lua_createtable(L, 0, 4);
  if (!std::isnan(s.angle)) set_number(L, "angle", s.angle);
  set_array(L, "lag", s.lag);
  set_array(L, "value", s.value);
  set_array(L, "pairs", s.pairs);
}

void push_spectrum(lua_State* L, const sf::Spectrum& s) {
  lua_createtable(L, 0, 3);
  set_array(L, "frequency", s.frequency);
  set_array(L, "psd", s.psd);
  set_array(L, "count", s.count);
}

void push_fit(lua_State* L, const sf::PowerLawFit& f) {
  lua_createtable(L, 0, 7);
  set_number(L, "hurst", f.hurst);
  set_number(L, "slope", f.slope);
  set_number(L, "intercept", f.intercept);
  set_number(L, "r2", f.r2);
  set_number(L, "x_min", f.x_min);
  set_number(L, "x_max", f.x_max);
  set_integer(L, "points", f.points);
}

void push_amplitude(lua_State* L, const sf::AmplitudeStats& a) {
  lua_createtable(L, 0, 9);
  set_number(L, "mean", a.mean);
  set_number(L, "ra", a.ra);
  set_number(L, "rms", a.rms);
  set_number(L, "variance", a.variance);
  set_number(L, "skewness", a.skewness);
  set_number(L, "kurtosis", a.kurtosis);
  set_number(L, "min", a.min);
  set_number(L, "max", a.max);
  set_integer(L, "count", static_cast<lua_Integer>(a.count));
}

void push_plane(lua_State* L, const sf::Plane& p) {
  lua_createtable(L, 0, 3);
  set_number(L, "a", p.a);
  set_number(L, "b", p.b);
  set_number(L, "c", p.c);
}

void push_abbott(lua_State* L, const sf::AbbottCurve& a) {
  lua_createtable(L, 0, 2);
  set_array(L, "height", a.height);
  set_array(L, "bearing_fraction", a.bearing_fraction);
}

void push_polar(lua_State* L, const std::vector<sf::DirectionalRoughness>& polar) {
  lua_createtable(L, static_cast<int>(polar.size()), 0);
  for (std::size_t k = 0; k < polar.size(); ++k) {
    const auto& d = polar[k];
    lua_createtable(L, 0, 6);
    set_number(L, "angle", d.angle);
    set_number(L, "hurst_structure", d.hurst_structure);
    set_number(L, "hurst_psd", d.hurst_psd);
    set_number(L, "variance", d.variance);
    set_number(L, "correlation_length", d.correlation_length);
    set_number(L, "rolloff_length", d.rolloff_length);
    lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
  }
}

// 0-based particle numbers -> a Lua list of ids from 1.
void push_ids(lua_State* L, const std::vector<std::int64_t>& ids) {
  lua_createtable(L, static_cast<int>(ids.size()), 0);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    lua_pushinteger(L, ids[k] + 1);
    lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
  }
}

// --- reading options ------------------------------------------------------------------------

int integer_in(lua_Integer v, const char* what, lua_Integer lo, lua_Integer hi, const std::string& ctx) {
  if (v < lo || v > hi)
    throw Error(ctx + ": " + what + " " + std::to_string(v) + " outside " + std::to_string(lo) +
                ".." + std::to_string(hi));
  return static_cast<int>(v);
}

std::string g6(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A number argument that must be finite (angles, lengths, offsets): NaN or infinity would reach
// integer conversions and loop bounds in the analysis.
double finite_arg(lua_State* L, int arg, const char* what) {
  const double v = check_number(L, arg);
  if (!std::isfinite(v)) throw ArgError{arg, std::string(what) + " must be finite, got " + g6(v)};
  return v;
}
double opt_finite_arg(lua_State* L, int arg, const char* what, double fallback) {
  return lua_isnoneornil(L, arg) ? fallback : finite_arg(L, arg, what);
}
// A lag or step length: finite and >= 0 (0: the default).
double opt_length_arg(lua_State* L, int arg, const char* what) {
  const double v = opt_finite_arg(L, arg, what, 0.0);
  if (v < 0) throw ArgError{arg, std::string(what) + " must be >= 0 (m; 0: the default), got " + g6(v)};
  return v;
}
double finite_option(Options& o, const char* key, double fallback) {
  const double v = o.number(key, fallback);
  if (!std::isfinite(v)) throw Error(o.context() + ": option '" + key + "' must be finite, got " + g6(v));
  return v;
}
// A 1-based index into n items, checked before any arithmetic on it.
int index_arg(lua_State* L, int arg, lua_Integer n, const char* what) {
  const lua_Integer i = check_integer(L, arg);
  if (i < 1 || i > n)
    throw ArgError{arg, std::string(what) + " " + std::to_string(i) + " outside 1.." + std::to_string(n)};
  return static_cast<int>(i - 1);
}

sf::Window window_named(const std::string& name, const std::string& context) {
  if (name == "hann") return sf::Window::hann;
  if (name == "none") return sf::Window::none;
  throw Error(context + ": unknown window '" + name + "' (valid: hann, none)");
}

// Fields of AnalysisOptions, read from an Options table (finish() is the caller's).
sf::AnalysisOptions read_analysis_options(Options& o) {
  sf::AnalysisOptions a;
  const std::string& ctx = o.context();
  // Lengths and frequencies finite (NaN or inf would reach integer conversions); counts bounded
  // (each is a loop count: a billion directions is a hang, not an analysis).
  auto length = [&](const char* key, double fallback) {
    const double v = finite_option(o, key, fallback);
    if (v < 0) throw Error(ctx + ": option '" + key + "' must be >= 0, got " + g6(v));
    return v;
  };
  a.remove_mean_plane = o.boolean("remove_mean_plane", a.remove_mean_plane);
  a.window = window_named(o.string("window", "hann"), o.context());
  a.max_lag = length("max_lag", a.max_lag);
  a.structure_fit_min_lag = length("structure_fit_min_lag", a.structure_fit_min_lag);
  a.structure_fit_max_lag = length("structure_fit_max_lag", a.structure_fit_max_lag);
  a.psd_fit_min_frequency = length("psd_fit_min_frequency", a.psd_fit_min_frequency);
  a.psd_fit_max_frequency = length("psd_fit_max_frequency", a.psd_fit_max_frequency);
  a.directions = integer_in(o.integer("directions", a.directions), "directions", 1, 3600, ctx);
  a.sector_half_width = finite_option(o, "sector_half_width", a.sector_half_width);
  a.abbott_levels = integer_in(o.integer("abbott_levels", a.abbott_levels), "abbott_levels", 2, 1 << 20, ctx);
  a.colatitude_bins = integer_in(o.integer("colatitude_bins", a.colatitude_bins), "colatitude_bins", 1, 1 << 20, ctx);
  a.slope_max_steps = integer_in(o.integer("slope_max_steps", a.slope_max_steps), "slope_max_steps", 1, 1 << 20, ctx);
  return a;
}

sf::AnalysisOptions analysis_options(lua_State* L, int index, const std::string& context, int arg) {
  Options o(L, index, context, arg);
  sf::AnalysisOptions a = read_analysis_options(o);
  o.finish();
  return a;
}


// Generation parameters from a table: a reference surface by name, overridden field by field,
// or all of H (or Hx, Hy), Lc (or Lcx, Lcy) and variance.
sf::SurfaceParams read_surface_params(lua_State* L, int index, const std::string& context, int arg) {
  Options o(L, index, context, arg);
  const std::string name = o.string("name", "");
  const lua_Integer seed = o.integer("seed", 1);
  if (seed < 0) throw Error(context + ": seed must be >= 0");
  const int n = integer_in(o.integer("n", 365), "n", 3, 1 << 15, context);
  const double side = o.number("side", 0.10);
  auto H = o.number("H"), Hx = o.number("Hx"), Hy = o.number("Hy");
  auto Lc = o.number("Lc"), Lcx = o.number("Lcx"), Lcy = o.number("Lcy");
  auto s2 = o.number("variance"), s2x = o.number("variance_x"), s2y = o.number("variance_y");
  o.finish();
  sf::SurfaceParams p;
  if (!name.empty()) {
    try {
      p = sf::reference_surface(name, static_cast<std::uint64_t>(seed), n, side);
    } catch (const Error& e) {
      throw Error(context + ": " + e.what());
    }
  } else {
    std::string missing;
    if (!H && !(Hx && Hy)) missing += " H (or Hx and Hy)";
    if (!Lc && !(Lcx && Lcy)) missing += " Lc (or Lcx and Lcy)";
    if (!s2) missing += " variance";
    if (!missing.empty())
      throw Error(context + ": give name = \"S1\"..\"S8\", or the parameters; missing:" + missing);
    p.n = n;
    p.side = side;
    p.seed = static_cast<std::uint64_t>(seed);
  }
  if (H) p.hurst_x = p.hurst_y = *H;
  if (Hx) p.hurst_x = *Hx;
  if (Hy) p.hurst_y = *Hy;
  if (Lc) p.corr_length_x = p.corr_length_y = *Lc;
  if (Lcx) p.corr_length_x = *Lcx;
  if (Lcy) p.corr_length_y = *Lcy;
  if (s2) p.variance = *s2;
  if (s2x) p.variance_x = *s2x;
  if (s2y) p.variance_y = *s2y;
  if (!name.empty() && (H || Hx || Hy || Lc || Lcx || Lcy || s2 || s2x || s2y))
    p.name = name + "*";  // a reference surface with changed statistics is no longer it
  try {
    sf::validate(p);
  } catch (const Error& e) {
    throw Error(context + ": " + e.what());
  }
  return p;
}

// --- module functions -----------------------------------------------------------------------

int l_generate(lua_State* L) {
  return guarded(L, [&] {
    check_table(L, 1);
    const sf::SurfaceParams p = read_surface_params(L, 1, "asperity.surface.generate", 1);
    push_map(L, sf::generate_surface(p));
    return 1;
  });
}

int l_reference(lua_State* L) {
  return guarded(L, [&] {
    const std::string name = check_string(L, 1);
    Options o(L, 2, "asperity.surface.reference", 2);
    const lua_Integer seed = o.integer("seed", 1);
    const int n = integer_in(o.integer("n", 365), "n", 3, 1 << 15, o.context());
    const double side = o.number("side", 0.10);
    o.finish();
    if (seed < 0) throw Error("asperity.surface.reference: seed must be >= 0");
    push_params(L, sf::reference_surface(name, static_cast<std::uint64_t>(seed), n, side));
    return 1;
  });
}

int l_names(lua_State* L) {
  return guarded(L, [&] {
    const auto names = sf::reference_surface_names();
    lua_createtable(L, static_cast<int>(names.size()), 0);
    for (std::size_t k = 0; k < names.size(); ++k) {
      lua_pushstring(L, names[k].c_str());
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

int l_load(lua_State* L) {
  return guarded(L, [&] {
    const std::string path = check_string(L, 1);
    Options o(L, 2, "asperity.surface.load", 2);
    const double spacing = finite_option(o, "spacing", 0.0);
    o.finish();
    push_map(L, sf::load_hdf5(path, spacing));
    return 1;
  });
}

int l_load_grid(lua_State* L) {
  return guarded(L, [&] {
    const std::string path = check_string(L, 1);
    Options o(L, 2, "asperity.surface.load_grid", 2);
    sf::GridImportOptions g;
    g.spacing = finite_option(o, "spacing", g.spacing);
    g.height_scale = finite_option(o, "height_scale", g.height_scale);
    o.finish();
    push_map(L, sf::load_grid(path, g));
    return 1;
  });
}

int l_height_map(lua_State* L) {
  return guarded(L, [&] {
    Options o(L, 1, "asperity.surface.height_map", 1);
    check_table(L, 1);
    const double spacing = o.number("spacing", 0.0);
    const lua_Integer nx_given = o.integer("nx", 0);
    if (o.push("heights") == LUA_TNIL)
      throw Error("asperity.surface.height_map: give heights = Array(ny x nx) or a flat table with nx");
    std::size_t cols = 1;
    std::vector<double> h = check_numbers(L, lua_gettop(L), &cols);
    lua_pop(L, 1);
    o.finish();
    if (!(spacing > 0) || !std::isfinite(spacing))
      throw Error("asperity.surface.height_map: give spacing = grid step (m), finite and > 0, got " + g6(spacing));
    const std::size_t nx = cols > 1 ? cols : static_cast<std::size_t>(nx_given);
    if (nx < 1 || h.empty() || h.size() % nx != 0)
      throw Error("asperity.surface.height_map: " + std::to_string(h.size()) +
                  " heights do not make rows of nx = " + std::to_string(nx) +
                  " (give an Array with nx columns, or nx =)");
    sf::HeightMap m(static_cast<int>(nx), static_cast<int>(h.size() / nx), spacing);
    m.height = std::move(h);
    push_map(L, std::move(m));
    return 1;
  });
}

int l_analyze_profile(lua_State* L) {
  return guarded(L, [&] {
    std::size_t cols = 1;
    sf::Profile p;
    p.height = check_numbers(L, 1, &cols);
    if (cols != 1) throw ArgError{1, "a profile is one column of heights"};
    p.spacing = check_number(L, 2);
    const sf::AnalysisOptions a = analysis_options(L, 3, "asperity.surface.analyze_profile", 3);
    const sf::ProfileSummary r = sf::analyze(p, a);
    lua_createtable(L, 0, 8);
    lua_createtable(L, 0, 2);
    set_number(L, "a", r.mean_line.a);
    set_number(L, "c", r.mean_line.c);
    lua_setfield(L, -2, "mean_line");
    push_amplitude(L, r.amplitude);
    lua_setfield(L, -2, "amplitude");
    set_number(L, "correlation_length", r.correlation_length);
    set_number(L, "rolloff_length", r.rolloff_length);
    push_fit(L, r.hurst_structure);
    lua_setfield(L, -2, "hurst_structure");
    push_fit(L, r.hurst_psd);
    lua_setfield(L, -2, "hurst_psd");
    push_lag_series(L, r.structure);
    lua_setfield(L, -2, "structure");
    push_spectrum(L, r.psd);
    lua_setfield(L, -2, "psd");
    return 1;
  });
}

int l_fit_power_law(lua_State* L) {
  return guarded(L, [&] {
    std::size_t cx = 1, cy = 1;
    const std::vector<double> x = check_numbers(L, 1, &cx);
    const std::vector<double> y = check_numbers(L, 2, &cy);
    if (cx != 1 || cy != 1) throw Error("asperity.surface.fit_power_law: x and y must be one column");
    if (x.size() != y.size())
      throw Error("asperity.surface.fit_power_law: " + std::to_string(x.size()) + " x values but " +
                  std::to_string(y.size()) + " y values");
    const double lo = opt_number(L, 3, 0.0);
    const double hi = opt_number(L, 4, std::numeric_limits<double>::infinity());
    push_fit(L, sf::fit_power_law(x, y, lo, hi));
    return 1;
  });
}

// profilometer{positions=, radii=, grid=, origin=, side=, ids=}
int l_profilometer(lua_State* L) {
  return guarded(L, [&] {
    const std::string ctx = "asperity.surface.profilometer";
    check_table(L, 1);
    Options o(L, 1, ctx, 1);
    std::size_t cols = 1;
    if (o.push("positions") == LUA_TNIL) throw Error(ctx + ": give positions = Array(n x 3)");
    const std::vector<double> pos = check_numbers(L, lua_gettop(L), &cols);
    lua_pop(L, 1);
    if (cols != 3 && !pos.empty()) throw Error(ctx + ": positions must have 3 columns (x, y, z)");
    if (o.push("radii") == LUA_TNIL) throw Error(ctx + ": give radii = Array(n)");
    const std::vector<double> radii = check_numbers(L, lua_gettop(L), &cols);
    lua_pop(L, 1);
    if (cols != 1) throw Error(ctx + ": radii must be one column");
    sf::ProfilometerGrid grid;
    const int gt = o.push("grid");
    if (sf::HeightMap* m = static_cast<sf::HeightMap*>(luaL_testudata(L, -1, kHeightMapType))) {
      grid.nx = m->nx;
      grid.ny = m->ny;
      grid.spacing = m->spacing;
    } else if (gt == LUA_TTABLE) {
      Options g(L, -1, ctx + " option 'grid'", 0);
      grid.nx = integer_in(g.integer("nx", 0), "grid.nx", 1, 1 << 16, ctx);
      grid.ny = integer_in(g.integer("ny", grid.nx), "grid.ny", 1, 1 << 16, ctx);
      grid.spacing = g.number("spacing", 0.0);
      g.finish();
      if (!(grid.spacing > 0) || !std::isfinite(grid.spacing))
        throw Error(ctx + ": grid.spacing must be a finite length > 0 (m), got " + g6(grid.spacing));
      if (std::int64_t(grid.nx) * grid.ny > (std::int64_t(1) << 26))
        throw Error(ctx + ": grid of " + std::to_string(grid.nx) + " x " + std::to_string(grid.ny) +
                    " nodes, more than 2^26");
    } else {
      throw Error(ctx + ": give grid = a HeightMap (its grid) or {nx=, ny=, spacing=}");
    }
    lua_pop(L, 1);
    if (o.push_checked("origin", LUA_TTABLE, "a table {x0, y0} (m)") == LUA_TTABLE) {
      lua_rawgeti(L, -1, 1);
      lua_rawgeti(L, -2, 2);
      if (lua_type(L, -2) != LUA_TNUMBER || lua_type(L, -1) != LUA_TNUMBER ||
          !std::isfinite(lua_tonumber(L, -2)) || !std::isfinite(lua_tonumber(L, -1)))
        throw Error(ctx + ": origin must be {x0, y0} of finite numbers (m)");
      grid.x0 = lua_tonumber(L, -2);
      grid.y0 = lua_tonumber(L, -1);
      lua_pop(L, 2);
    }
    lua_pop(L, 1);
    const std::string side_name = o.string("side", "lower");
    sf::HalfSide side;
    if (side_name == "lower") side = sf::HalfSide::lower;
    else if (side_name == "upper") side = sf::HalfSide::upper;
    else throw Error(ctx + ": unknown side '" + side_name + "' (valid: lower, upper)");
    std::vector<std::int64_t> subset;
    if (o.push("ids") != LUA_TNIL) {
      std::size_t c = 1;
      for (double v : check_numbers(L, lua_gettop(L), &c)) {
        if (v != std::floor(v) || v < 1 || v > static_cast<double>(radii.size()))
          throw Error(ctx + ": no particle " + number_text(v) + " in ids (valid: 1.." +
                      std::to_string(radii.size()) + ")");
        subset.push_back(static_cast<std::int64_t>(v) - 1);
      }
      if (c != 1) throw Error(ctx + ": ids must be a list of particle ids");
      if (subset.empty()) throw Error(ctx + ": ids is empty");
    }
    lua_pop(L, 1);
    o.finish();
    sf::ProfilometerResult r = sf::profilometer(pos, radii, grid, side, subset);
    // Mean radius of the particles the profilometer saw: the default band of classify().
    std::vector<std::int64_t> seen;
    for (auto p : r.particle)
      if (p >= 0) seen.push_back(p);
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    double mean_radius = 0.0;
    for (auto p : seen) mean_radius += radii[static_cast<std::size_t>(p)];
    mean_radius = seen.empty() ? std::nan("") : mean_radius / static_cast<double>(seen.size());

    std::vector<double> ids(r.particle.size());
    for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<double>(r.particle[k] + 1);
    lua_createtable(L, 0, 7);
    push_map(L, std::move(r.surface));
    lua_setfield(L, -2, "surface");
    push_array(L, std::move(ids), static_cast<std::size_t>(grid.nx));
    lua_setfield(L, -2, "particle");
    set_integer(L, "covered", static_cast<lua_Integer>(r.covered));
    set_integer(L, "particles", static_cast<lua_Integer>(r.particles));
    set_number(L, "mean_radius", mean_radius);
    set_string(L, "side", side_name);
    lua_createtable(L, 2, 0);
    lua_pushnumber(L, grid.x0);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, grid.y0);
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "origin");
    return 1;
  });
}

// Pushes t[key] of the table at `index` without metamethods (see binding.hpp: nothing in
// guarded code may raise a Lua error).
int raw_field(lua_State* L, int index, const char* key) {
  index = absolute(L, index);
  lua_pushstring(L, key);
  return lua_rawget(L, index);
}

// The DEM map of argument `arg`: a HeightMap, or a profilometer result {surface = HeightMap}.
sf::HeightMap& dem_arg(lua_State* L, int arg) {
  if (lua_type(L, arg) == LUA_TTABLE) {
    raw_field(L, arg, "surface");
    auto* m = static_cast<sf::HeightMap*>(luaL_testudata(L, -1, kHeightMapType));
    lua_pop(L, 1);  // the table keeps it alive
    if (m) return *m;
    throw ArgError{arg, "a HeightMap or a profilometer result expected"};
  }
  return map_arg(L, arg);
}

sf::DemMeanPlane mean_plane_of(lua_State* L, const sf::HeightMap& dem, const sf::HeightMap& syn,
                               int options_index, const std::string& context, int arg) {
  Options o(L, options_index, context, arg);
  sf::DemMeanPlaneOptions m;
  m.levels = integer_in(o.integer("levels", m.levels), "levels", 2, 1 << 20, context);
  m.bandwidth = finite_option(o, "bandwidth", m.bandwidth);
  m.tolerance = finite_option(o, "tolerance", m.tolerance);
  o.finish();
  return sf::dem_mean_plane(dem, syn, m);
}

int l_mean_plane(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& dem = dem_arg(L, 1);
    const sf::HeightMap& syn = map_arg(L, 2);
    const sf::DemMeanPlane r = mean_plane_of(L, dem, syn, 3, "asperity.surface.mean_plane", 3);
    lua_createtable(L, 0, 9);
    set_number(L, "shift", r.shift);
    set_number(L, "coinciding_fraction", r.coinciding_fraction);
    set_number(L, "tolerance", r.tolerance);
    set_number(L, "bandwidth", r.bandwidth);
    set_number(L, "mean_difference", r.mean_difference);
    set_integer(L, "points", static_cast<lua_Integer>(r.points));
    set_array(L, "dv", r.dv);
    set_array(L, "cumulative", r.cumulative);
    set_array(L, "density", r.density);
    return 1;
  });
}

int l_classify(lua_State* L) {
  return guarded(L, [&] {
    const std::string ctx = "asperity.surface.classify";
    check_table(L, 1);
    const sf::HeightMap& dem = dem_arg(L, 1);
    raw_field(L, 1, "particle");
    Array* ids = to_array(L, -1);
    raw_field(L, 1, "mean_radius");
    const double mean_radius = lua_type(L, -1) == LUA_TNUMBER ? lua_tonumber(L, -1) : std::nan("");
    lua_pop(L, 2);  // the table keeps the Array alive
    if (!ids) throw ArgError{1, "a profilometer result ({surface=, particle=}) expected"};
    const sf::HeightMap& syn = map_arg(L, 2);
    Options o(L, 3, ctx, 3);
    auto shift = o.number("shift");
    double band = o.number("band", mean_radius);
    o.finish();
    if (std::isnan(band)) throw Error(ctx + ": give band = (m)");
    if (!shift) shift = sf::dem_mean_plane(dem, syn).shift;
    std::vector<std::int64_t> node(ids->data.size());
    // The array may have been edited (or built by hand): each entry is a particle id from 1 or 0
    // (no particle), checked before the conversion to an integer.
    for (std::size_t k = 0; k < node.size(); ++k) {
      const double v = ids->data[k];
      if (!(v >= 0 && v <= 9007199254740992.0) || v != std::floor(v))
        throw ArgError{1, "particle[" + std::to_string(k + 1) + "] = " + g6(v) +
                              " is not a particle id (an integer >= 1, or 0 for none)"};
      node[k] = static_cast<std::int64_t>(v) - 1;
    }
    const sf::SurfaceParticles r = sf::classify_surface_particles(dem, node, syn, *shift, band);
    lua_createtable(L, 0, 6);
    push_ids(L, r.surface);
    lua_setfield(L, -2, "surface");
    push_ids(L, r.porosity);
    lua_setfield(L, -2, "porosity");
    set_number(L, "retained_fraction", r.retained_fraction);
    set_number(L, "node_fraction", r.node_fraction);
    set_number(L, "band", r.band);
    set_number(L, "shift", r.shift);
    return 1;
  });
}

int l_noise_study(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    Options o(L, 2, "asperity.surface.noise_study", 2);
    std::vector<double> levels;
    if (o.push("levels") != LUA_TNIL) {
      std::size_t c = 1;
      levels = check_numbers(L, lua_gettop(L), &c);
      if (levels.size() > 1000) throw Error("asperity.surface.noise_study: " + std::to_string(levels.size()) + " levels, at most 1000");
    } else {
      for (int k = 0; k <= 10; ++k) levels.push_back(0.1 * k);
    }
    lua_pop(L, 1);
    const lua_Integer seed = o.integer("seed", 1);
    if (seed < 0) throw Error("asperity.surface.noise_study: seed must be >= 0, got " + std::to_string(seed));
    const sf::AnalysisOptions a = read_analysis_options(o);
    o.finish();
    const auto study = sf::noise_study(m, levels, static_cast<std::uint64_t>(seed), a);
    lua_createtable(L, static_cast<int>(study.size()), 0);
    for (std::size_t k = 0; k < study.size(); ++k) {
      const auto& l = study[k];
      lua_createtable(L, 0, 8);
      set_number(L, "level", l.level);
      set_number(L, "noise_rms", l.noise_rms);
      set_number(L, "variance", l.variance);
      set_number(L, "hurst_psd", l.hurst_psd);
      set_number(L, "hurst_structure", l.hurst_structure);
      set_number(L, "psd_fit_r2", l.psd_fit_r2);
      set_number(L, "structure_fit_r2", l.structure_fit_r2);
      set_number(L, "correlation_length", l.correlation_length);
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

// --- HeightMap methods ----------------------------------------------------------------------

int map_gc(lua_State* L) {
  if (void* p = luaL_testudata(L, 1, kHeightMapType)) static_cast<sf::HeightMap*>(p)->~HeightMap();
  return 0;
}

int map_tostring(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    char buf[160];
    std::snprintf(buf, sizeof buf, "HeightMap(%d x %d, spacing %.6g m%s%s)", m.nx, m.ny, m.spacing,
                  m.params && !m.params->name.empty() ? ", " : "",
                  m.params ? m.params->name.c_str() : "");
    lua_pushstring(L, buf);
    return 1;
  });
}

int map_size(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    lua_pushinteger(L, m.nx);
    lua_pushinteger(L, m.ny);
    return 2;
  });
}

int map_spacing(lua_State* L) {
  return guarded(L, [&] {
    lua_pushnumber(L, map_arg(L, 1).spacing);
    return 1;
  });
}

int map_heights(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    push_array(L, m.height, static_cast<std::size_t>(m.nx));
    return 1;
  });
}

int map_at(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const lua_Integer i = check_integer(L, 2), j = check_integer(L, 3);
    if (i < 1 || i > m.nx) throw ArgError{2, "column " + std::to_string(i) + " outside 1.." + std::to_string(m.nx)};
    if (j < 1 || j > m.ny) throw ArgError{3, "row " + std::to_string(j) + " outside 1.." + std::to_string(m.ny)};
    lua_pushnumber(L, m.at(static_cast<int>(i - 1), static_cast<int>(j - 1)));
    return 1;
  });
}

int map_params(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    if (m.params) push_params(L, *m.params);
    else lua_pushnil(L);
    return 1;
  });
}

int map_save(lua_State* L) {
  return guarded(L, [&] {
    sf::save_hdf5(map_arg(L, 1), check_string(L, 2));
    return 0;
  });
}

int map_save_csv(lua_State* L) {
  return guarded(L, [&] {
    sf::save_csv(map_arg(L, 1), check_string(L, 2));
    return 0;
  });
}

int map_plot(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const std::string file = check_string(L, 2);
    Options o(L, 3, "map:plot", 3);
    sf::MapPlotOptions p;
    p.title = o.string("title", "");
    p.width = static_cast<int>(o.integer("width", p.width));
    p.height = static_cast<int>(o.integer("height", p.height));
    o.finish();
    sf::plot_height_map_png(m, file, p);
    lua_pushstring(L, file.c_str());
    return 1;
  });
}

int map_analyze(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const sf::AnalysisOptions a = analysis_options(L, 2, "map:analyze", 2);
    const sf::RoughnessSummary r = sf::analyze(m, a);
    lua_createtable(L, 0, 12);
    push_plane(L, r.mean_plane);
    lua_setfield(L, -2, "mean_plane");
    push_amplitude(L, r.amplitude);
    lua_setfield(L, -2, "amplitude");
    set_number(L, "correlation_length", r.correlation_length);
    set_number(L, "rolloff_length", r.rolloff_length);
    push_fit(L, r.hurst_structure);
    lua_setfield(L, -2, "hurst_structure");
    push_fit(L, r.hurst_psd);
    lua_setfield(L, -2, "hurst_psd");
    push_lag_series(L, r.structure_radial);
    lua_setfield(L, -2, "structure_radial");
    push_lag_series(L, r.structure_x);
    lua_setfield(L, -2, "structure_x");
    push_lag_series(L, r.structure_y);
    lua_setfield(L, -2, "structure_y");
    push_spectrum(L, r.psd_radial);
    lua_setfield(L, -2, "psd_radial");
    push_abbott(L, r.abbott);
    lua_setfield(L, -2, "abbott");
    push_polar(L, r.polar);
    lua_setfield(L, -2, "polar");
    return 1;
  });
}

int map_amplitude(lua_State* L) {
  return guarded(L, [&] {
    push_amplitude(L, sf::amplitude_stats(map_arg(L, 1)));
    return 1;
  });
}

int map_mean_plane(lua_State* L) {
  return guarded(L, [&] {
    push_plane(L, sf::fit_mean_plane(map_arg(L, 1)));
    return 1;
  });
}

int map_remove_mean_plane(lua_State* L) {
  return guarded(L, [&] {
    push_map(L, sf::remove_mean_plane(map_arg(L, 1)));
    return 1;
  });
}

// Direction argument: an angle (rad), "x", "y" or "radial" (default).
std::optional<double> direction_arg(lua_State* L, int arg) {
  if (lua_isnoneornil(L, arg)) return std::nullopt;
  if (lua_type(L, arg) == LUA_TNUMBER) return finite_arg(L, arg, "angle (rad)");
  if (lua_type(L, arg) == LUA_TSTRING) {
    const std::string s = lua_tostring(L, arg);
    if (s == "radial") return std::nullopt;
    if (s == "x") return 0.0;
    if (s == "y") return 0.5 * std::numbers::pi;
    throw ArgError{arg, "unknown direction '" + s + "' (an angle in rad, \"x\", \"y\" or \"radial\")"};
  }
  type_error(arg, "angle (rad) or \"x\", \"y\", \"radial\"", L, arg);
}

template <bool Structure, bool Halve>
int map_lags(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const auto angle = direction_arg(L, 2);
    const double max_lag = opt_length_arg(L, 3, "max_lag");
    const sf::LagMap lags(m);
    sf::LagSeries s = Structure ? (angle ? lags.structure_function(*angle, max_lag)
                                         : lags.structure_function_radial(max_lag))
                                : (angle ? lags.autocovariance(*angle, max_lag)
                                         : lags.autocovariance_radial(max_lag));
    if (Halve) s = sf::variogram(s);
    push_lag_series(L, s);
    return 1;
  });
}

int map_psd(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    Options o(L, 2, "map:psd", 2);
    auto angle = o.number("angle");
    if (angle && !std::isfinite(*angle)) throw Error("map:psd: option 'angle' must be finite");
    const double half_width = finite_option(o, "half_width", std::numbers::pi / 8);
    const sf::Window w = window_named(o.string("window", "hann"), "map:psd");
    o.finish();
    push_spectrum(L, angle ? sf::sector_psd(m, *angle, half_width, w) : sf::radial_psd(m, w));
    return 1;
  });
}

int map_slopes(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const double angle = direction_arg(L, 2).value_or(0.0);
    const lua_Integer max_steps = opt_integer(L, 3, 20);
    if (max_steps < 1 || max_steps > 1 << 20)
      throw ArgError{3, "max_steps " + std::to_string(max_steps) + " outside 1.." + std::to_string(1 << 20)};
    const int steps = static_cast<int>(max_steps);
    const sf::SlopeSeries s = sf::slope_statistics(m, angle, steps);
    lua_createtable(L, 0, 4);
    set_number(L, "angle", s.angle);
    set_array(L, "step", s.step);
    set_array(L, "z2", s.z2);
    set_array(L, "z3", s.z3);
    return 1;
  });
}

int map_colatitude(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const double angle = direction_arg(L, 2).value_or(0.0);
    Options o(L, 3, "map:colatitude", 3);
    const double step = finite_option(o, "step", 0.0);
    const int bins = integer_in(o.integer("bins", 90), "bins", 1, 1 << 20, "map:colatitude");
    o.finish();
    const sf::ColatitudeDistribution c = sf::colatitude_distribution(m, angle, step, bins);
    lua_createtable(L, 0, 11);
    set_number(L, "angle", c.angle);
    set_number(L, "step", c.step);
    set_array(L, "bin_edges", c.bin_edges);
    set_array(L, "positive", c.positive);
    set_array(L, "negative", c.negative);
    set_number(L, "fraction_positive", c.fraction_positive);
    set_number(L, "mean_positive", c.mean_positive);
    set_number(L, "mean_negative", c.mean_negative);
    set_number(L, "max_positive", c.max_positive);
    set_number(L, "max_negative", c.max_negative);
    set_integer(L, "samples", static_cast<lua_Integer>(c.samples));
    return 1;
  });
}

int map_abbott(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    const lua_Integer levels = opt_integer(L, 2, 201);
    if (levels < 2 || levels > 1 << 20)
      throw ArgError{2, "levels " + std::to_string(levels) + " outside 2.." + std::to_string(1 << 20)};
    push_abbott(L, sf::abbott_curve(m, static_cast<int>(levels)));
    return 1;
  });
}

int map_polar(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    push_polar(L, sf::polar_roughness(m, analysis_options(L, 2, "map:polar", 2)));
    return 1;
  });
}

void push_profile(lua_State* L, sf::Profile p) {
  const double h = p.spacing;
  push_array(L, std::move(p.height), 1);
  lua_pushnumber(L, h);
}

int map_row(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    push_profile(L, sf::row_profile(m, index_arg(L, 2, m.ny, "row")));
    return 2;
  });
}

int map_column(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    push_profile(L, sf::column_profile(m, index_arg(L, 2, m.nx, "column")));
    return 2;
  });
}

int map_profile(lua_State* L) {
  return guarded(L, [&] {
    const sf::HeightMap& m = map_arg(L, 1);
    push_profile(L, sf::line_profile(m, finite_arg(L, 2, "x0 (m)"), finite_arg(L, 3, "y0 (m)"),
                                     finite_arg(L, 4, "angle (rad)"), opt_length_arg(L, 5, "step")));
    return 2;
  });
}

int map_shifted(lua_State* L) {
  return guarded(L, [&] {
    sf::HeightMap m = map_arg(L, 1);
    const double dz = finite_arg(L, 2, "dz (m)");
    for (double& z : m.height) z += dz;
    push_map(L, std::move(m));
    return 1;
  });
}

}  // namespace

void open_surface(lua_State* L) {
  static const Function methods[] = {
      {"size", map_size, "map:size() -> nx, ny", "Grid points along x (columns) and y (rows)."},
      {"spacing", map_spacing, "map:spacing() -> h", "Grid step (m), the same along x and y."},
      {"heights", map_heights, "map:heights() -> Array(ny x nx)",
       "The heights (m): row j is y = (j - 1) h, column i is x = (i - 1) h."},
      {"at", map_at, "map:at(i, j) -> z", "Height at column i, row j (from 1)."},
      {"params", map_params, "map:params() -> table or nil",
       "Generation parameters (name, n, side, seed, H/Hx/Hy, Lc/Lcx/Lcy, variance...), nil for\n"
       "measured or imported maps."},
      {"save", map_save, "map:save(path)",
       "HDF5: dataset `height` (ny x nx, m), attributes spacing, units and the parameters."},
      {"save_csv", map_save_csv, "map:save_csv(path)", "A CSV grid, one row of heights per y."},
      {"plot", map_plot, "map:plot(file [, {title=, width=, height=}]) -> file",
       "Elevation map as a PNG heat map (gnuplot), axes and heights in mm."},
      {"analyze", map_analyze, "map:analyze([options]) -> table",
       "Everything of spec section 2 after removing the mean plane: mean_plane {a,b,c}, amplitude\n"
       "{mean, ra, rms, variance, skewness, kurtosis, min, max}, correlation_length (S reaches\n"
       "(1-1/e) 2 s2), rolloff_length (PSD corner, the generator's Lc), hurst_psd and\n"
       "hurst_structure {hurst, slope, intercept, r2, x_min, x_max, points}, structure_radial,\n"
       "structure_x, structure_y {lag, value, pairs: Arrays}, psd_radial {frequency, psd, count},\n"
       "abbott {height, bearing_fraction}, polar {{angle, hurst_psd, hurst_structure, variance,\n"
       "correlation_length, rolloff_length}, ...}. options: remove_mean_plane, window (\"hann\"|\n"
       "\"none\"), max_lag, structure_fit_min_lag, structure_fit_max_lag, psd_fit_min_frequency,\n"
       "psd_fit_max_frequency, directions, sector_half_width, abbott_levels, colatitude_bins,\n"
       "slope_max_steps."},
      {"amplitude", map_amplitude, "map:amplitude() -> table",
       "Ra, rms, variance, skewness, kurtosis [2-2..2-5] of the heights as they are."},
      {"mean_plane", map_mean_plane, "map:mean_plane() -> {a, b, c}", "Least-squares plane z = a x + b y + c [2-1]."},
      {"remove_mean_plane", map_remove_mean_plane, "map:remove_mean_plane() -> HeightMap",
       "A new map of the residuals about the mean plane."},
      {"structure_function", map_lags<true, false>,
       "map:structure_function([direction [, max_lag]]) -> {lag, value, pairs}",
       "S(tau) [2-9] along an angle (rad), \"x\", \"y\", or \"radial\" (default). Arrays, m and m^2."},
      {"variogram", map_lags<true, true>, "map:variogram([direction [, max_lag]]) -> {lag, value, pairs}",
       "gamma = S / 2."},
      {"autocovariance", map_lags<false, false>,
       "map:autocovariance([direction [, max_lag]]) -> {lag, value, pairs}", "R(tau) [2-6] about the mean."},
      {"psd", map_psd, "map:psd([{angle=, half_width=, window=}]) -> {frequency, psd, count}",
       "Ring-averaged 2-D PSD (m^4, per (cycle/m)^2), or a sector around `angle` (+-half_width)."},
      {"slopes", map_slopes, "map:slopes([direction [, max_steps]]) -> {step, z2, z3}",
       "Z2 and Z3 against the step [2-13, 2-14]."},
      {"colatitude", map_colatitude, "map:colatitude([direction [, {step=, bins=}]]) -> table",
       "Colatitude distribution [2-17], positive and negative slopes separately."},
      {"abbott", map_abbott, "map:abbott([levels]) -> {height, bearing_fraction}",
       "Abbott-Firestone curve: share of the heights >= each level."},
      {"polar", map_polar, "map:polar([options]) -> {{angle, hurst_psd, ...}, ...}",
       "H, s2, Lc per direction over [0, pi) (options as for analyze)."},
      {"row", map_row, "map:row(j) -> Array, spacing", "Profile along x at row j."},
      {"column", map_column, "map:column(i) -> Array, spacing", "Profile along y at column i."},
      {"profile", map_profile, "map:profile(x0, y0, angle [, step]) -> Array, spacing",
       "Profile through (x0, y0) (m) along angle (rad), bilinear between nodes."},
      {"shifted", map_shifted, "map:shifted(dz) -> HeightMap", "A copy with dz (m) added to every height."},
  };
  static const luaL_Reg meta[] = {{"__gc", map_gc}, {"__tostring", map_tostring}};
  new_type(L, kHeightMapType, methods, meta,
           "HeightMap: heights on a square grid (m), from asperity.surface.generate, load,\n"
           "load_grid, height_map or profilometer. map:heights() gives them as an Array.");
  lua_pop(L, 1);

  lua_newtable(L);
  set_doc(L, -1,
          "asperity.surface: self-affine rough surfaces (spec surfaces.md).\n"
          "  generate{name=\"S5\"} or generate{H=, Lc=, variance=} -> HeightMap; map:analyze().\n"
          "  From a synthetic surface to a DEM surface: profilometer, mean_plane, classify;\n"
          "  noise_study. Lengths in m, variances in m^2. help(map) lists the HeightMap methods.");
  static const Function fns[] = {
      {"generate", l_generate,
       "asperity.surface.generate{name= | H=, Lc=, variance= [, Hx=, Hy=, Lcx=, Lcy=, variance_x=,\n"
       "  variance_y=] [, n=365] [, side=0.1] [, seed=1]} -> HeightMap",
       "A self-affine surface by the spectral method [2-41..2-57]: n x n (n odd), period side\n"
       "(m), zero mean, variance exact. name = \"S1\"..\"S8\" takes spec table 4 (other fields\n"
       "given override it). One seed gives the same hills and holes for any parameters."},
      {"reference", l_reference, "asperity.surface.reference(name [, {seed=, n=, side=}]) -> table",
       "The parameters of a reference surface S1..S8 in SI units."},
      {"names", l_names, "asperity.surface.names() -> {\"S1\", ...}", "The reference surfaces."},
      {"load", l_load, "asperity.surface.load(path [, {spacing=}]) -> HeightMap",
       "A height map from HDF5 (dataset `height`, attribute `spacing`), e.g. one map:save wrote."},
      {"load_grid", l_load_grid, "asperity.surface.load_grid(path [, {spacing=, height_scale=}]) -> HeightMap",
       "A CSV/whitespace grid (one row per y; \"# spacing = h\") or an ESRI ASCII grid;\n"
       "height_scale converts units (1e-6 for micrometres)."},
      {"height_map", l_height_map, "asperity.surface.height_map{heights=, spacing= [, nx=]} -> HeightMap",
       "A map from an Array(ny x nx) (or a flat table with nx) of heights (m)."},
      {"analyze_profile", l_analyze_profile,
       "asperity.surface.analyze_profile(heights, spacing [, options]) -> table",
       "Section 2 for one profile: mean_line, amplitude, correlation_length, rolloff_length,\n"
       "hurst_structure, hurst_psd (1-D: slope -(1 + 2H)), structure, psd."},
      {"fit_power_law", l_fit_power_law, "asperity.surface.fit_power_law(x, y [, x_min, x_max]) -> fit",
       "Least-squares line through (log x, log y) in the window: {slope, intercept, r2, points}."},
      {"profilometer", l_profilometer,
       "asperity.surface.profilometer{positions=, radii=, grid= [, origin={x0, y0}] [, side=\"lower\"]\n"
       "  [, ids=]} -> {surface, particle, covered, particles, mean_radius}",
       "Numerical profilometer (spec 3): per grid node the highest point of the spheres\n"
       "(side=\"upper\": the lowest) whose disc covers it. grid: a HeightMap (its nx, ny, spacing)\n"
       "or {nx=, ny=, spacing=}; origin: where node (1, 1) is. surface: HeightMap (NaN where no\n"
       "sphere covers a node); particle: Array(ny x nx) of particle ids (rows of positions, from\n"
       "1; 0 for none). ids restricts the particles (e.g. one half of a joint)."},
      {"mean_plane", l_mean_plane,
       "asperity.surface.mean_plane(dem, synthetic [, {levels=, bandwidth=, tolerance=}]) -> table",
       "Modified Abbott curve: the cumulative distribution F(dv) of z_dem - z_syn, and its mode\n"
       "`shift` (dv_mp), where the shifted synthetic surface meets most of the DEM surface.\n"
       "Also coinciding_fraction (|d - shift| <= tolerance, default 1 % of the synthetic rms\n"
       "height), mean_difference, dv, cumulative, density (Arrays). dem: a HeightMap or a\n"
       "profilometer result; both in the same frame (a mold placed at z0 shifts dv_mp by z0)."},
      {"classify", l_classify,
       "asperity.surface.classify(profile, synthetic [, {shift=, band=}]) -> table",
       "Surface vs porosity particles [3-52..3-54]: a profilometer particle is \"surface\" when\n"
       "one of its nodes lies within band of z_syn + shift. Defaults: shift from mean_plane,\n"
       "band = the mean radius of the profilometer particles. Returns surface, porosity (ids),\n"
       "retained_fraction, node_fraction, band, shift."},
      {"noise_study", l_noise_study,
       "asperity.surface.noise_study(map [, {levels=, seed=, ...analysis options}]) -> {row, ...}",
       "Adds white Gaussian noise of rms level * rms height (levels default 0, 0.1, ..., 1) and\n"
       "re-measures with the clean map's fit windows: {level, noise_rms, variance, hurst_psd,\n"
       "hurst_structure, psd_fit_r2, structure_fit_r2, correlation_length} per level."},
  };
  register_functions(L, -1, fns);
  lua_setfield(L, -2, "surface");
}

}  // namespace asperity::lua
