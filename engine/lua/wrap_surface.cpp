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

#include "lua/wrap_surface.hpp"

namespace asperity::lua {

namespace {

using namespace surface_wrap;

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
    set_roughness_common(L, r);
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
}  // namespace

void open_surface(lua_State* L) {
  surface_wrap::open_height_map(L);

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
  };
  register_functions(L, -1, fns);
  register_functions(L, -1, surface_wrap::dem_surface_functions());
  lua_setfield(L, -2, "surface");
}

}  // namespace asperity::lua
