// What the files of asperity.surface share (wrap_surface.cpp, wrap_surface_dem.cpp,
// wrap_height_map.cpp): the HeightMap userdata, how results are pushed and options read.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <numbers>

#include "asperity/surface.hpp"
#include "lua/binding.hpp"

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace asperity::lua::surface_wrap {

namespace sf = asperity::surface;


inline constexpr const char* kHeightMapType = "asperity.HeightMap";

inline sf::HeightMap& map_arg(lua_State* L, int arg) {
  return *static_cast<sf::HeightMap*>(check_udata(L, arg, kHeightMapType));
}

inline sf::HeightMap& push_map(lua_State* L, sf::HeightMap map) {
  void* mem = lua_newuserdatauv(L, sizeof(sf::HeightMap), 0);
  auto* m = new (mem) sf::HeightMap(std::move(map));
  luaL_setmetatable(L, kHeightMapType);
  return *m;
}

// --- pushing results ------------------------------------------------------------------------

inline void set_number(lua_State* L, const char* key, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, key);
}
inline void set_integer(lua_State* L, const char* key, lua_Integer v) {
  lua_pushinteger(L, v);
  lua_setfield(L, -2, key);
}
inline void set_string(lua_State* L, const char* key, const std::string& v) {
  lua_pushlstring(L, v.data(), v.size());
  lua_setfield(L, -2, key);
}
inline void set_array(lua_State* L, const char* key, std::vector<double> v) {
  push_array(L, std::move(v), 1);
  lua_setfield(L, -2, key);
}

inline void push_params(lua_State* L, const sf::SurfaceParams& p) {
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

inline void push_lag_series(lua_State* L, const sf::LagSeries& s) {
  lua_createtable(L, 0, 4);
  if (!std::isnan(s.angle)) set_number(L, "angle", s.angle);
  set_array(L, "lag", s.lag);
  set_array(L, "value", s.value);
  set_array(L, "pairs", s.pairs);
}

inline void push_spectrum(lua_State* L, const sf::Spectrum& s) {
  lua_createtable(L, 0, 3);
  set_array(L, "frequency", s.frequency);
  set_array(L, "psd", s.psd);
  set_array(L, "count", s.count);
}

inline void push_fit(lua_State* L, const sf::PowerLawFit& f) {
  lua_createtable(L, 0, 7);
  set_number(L, "hurst", f.hurst);
  set_number(L, "slope", f.slope);
  set_number(L, "intercept", f.intercept);
  set_number(L, "r2", f.r2);
  set_number(L, "x_min", f.x_min);
  set_number(L, "x_max", f.x_max);
  set_integer(L, "points", f.points);
}

inline void push_amplitude(lua_State* L, const sf::AmplitudeStats& a) {
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

// The fields a map's and a profile's roughness summaries share, into the table on top.
template <class Summary>
void set_roughness_common(lua_State* L, const Summary& r) {
  push_amplitude(L, r.amplitude);
  lua_setfield(L, -2, "amplitude");
  set_number(L, "correlation_length", r.correlation_length);
  set_number(L, "rolloff_length", r.rolloff_length);
  push_fit(L, r.hurst_structure);
  lua_setfield(L, -2, "hurst_structure");
  push_fit(L, r.hurst_psd);
  lua_setfield(L, -2, "hurst_psd");
}

inline void push_plane(lua_State* L, const sf::Plane& p) {
  lua_createtable(L, 0, 3);
  set_number(L, "a", p.a);
  set_number(L, "b", p.b);
  set_number(L, "c", p.c);
}

inline void push_abbott(lua_State* L, const sf::AbbottCurve& a) {
  lua_createtable(L, 0, 2);
  set_array(L, "height", a.height);
  set_array(L, "bearing_fraction", a.bearing_fraction);
}

inline void push_polar(lua_State* L, const std::vector<sf::DirectionalRoughness>& polar) {
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
inline void push_ids(lua_State* L, const std::vector<std::int64_t>& ids) {
  lua_createtable(L, static_cast<int>(ids.size()), 0);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    lua_pushinteger(L, ids[k] + 1);
    lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
  }
}

// --- reading options ------------------------------------------------------------------------

inline int integer_in(lua_Integer v, const char* what, lua_Integer lo, lua_Integer hi, const std::string& ctx) {
  if (v < lo || v > hi)
    throw Error(ctx + ": " + what + " " + std::to_string(v) + " outside " + std::to_string(lo) +
                ".." + std::to_string(hi));
  return static_cast<int>(v);
}

inline std::string g6(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A number argument that must be finite (angles, lengths, offsets): NaN or infinity would reach
// integer conversions and loop bounds in the analysis.
inline double finite_arg(lua_State* L, int arg, const char* what) {
  const double v = check_number(L, arg);
  if (!std::isfinite(v)) throw ArgError{arg, std::string(what) + " must be finite, got " + g6(v)};
  return v;
}
inline double opt_finite_arg(lua_State* L, int arg, const char* what, double fallback) {
  return lua_isnoneornil(L, arg) ? fallback : finite_arg(L, arg, what);
}
// A lag or step length: finite and >= 0 (0: the default).
inline double opt_length_arg(lua_State* L, int arg, const char* what) {
  const double v = opt_finite_arg(L, arg, what, 0.0);
  if (v < 0) throw ArgError{arg, std::string(what) + " must be >= 0 (m; 0: the default), got " + g6(v)};
  return v;
}
inline double finite_option(Options& o, const char* key, double fallback) {
  const double v = o.number(key, fallback);
  if (!std::isfinite(v)) throw Error(o.context() + ": option '" + key + "' must be finite, got " + g6(v));
  return v;
}
// A 1-based index into n items, checked before any arithmetic on it.
inline int index_arg(lua_State* L, int arg, lua_Integer n, const char* what) {
  const lua_Integer i = check_integer(L, arg);
  if (i < 1 || i > n)
    throw ArgError{arg, std::string(what) + " " + std::to_string(i) + " outside 1.." + std::to_string(n)};
  return static_cast<int>(i - 1);
}

inline sf::Window window_named(const std::string& name, const std::string& context) {
  if (name == "hann") return sf::Window::hann;
  if (name == "none") return sf::Window::none;
  throw Error(context + ": unknown window '" + name + "' (valid: hann, none)");
}

// Fields of AnalysisOptions, read from an Options table (finish() is the caller's).
inline sf::AnalysisOptions read_analysis_options(Options& o) {
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

inline sf::AnalysisOptions analysis_options(lua_State* L, int index, const std::string& context, int arg) {
  Options o(L, index, context, arg);
  sf::AnalysisOptions a = read_analysis_options(o);
  o.finish();
  return a;
}


// Generation parameters from a table: a reference surface by name, overridden field by field,
// or all of H (or Hx, Hy), Lc (or Lcx, Lcy) and variance.
inline sf::SurfaceParams read_surface_params(lua_State* L, int index, const std::string& context, int arg) {
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

// The HeightMap type (wrap_height_map.cpp) and the steps to a DEM surface (wrap_surface_dem.cpp).
void open_height_map(lua_State* L);
std::span<const Function> dem_surface_functions();

}  // namespace asperity::lua::surface_wrap
