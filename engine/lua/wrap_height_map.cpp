// asperity.HeightMap: the methods of a height map (heights, files, plots, the roughness analysis
// of surfaces.md 2, profiles).
#include "lua/wrap_surface.hpp"

namespace asperity::lua::surface_wrap {

namespace {

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
    set_roughness_common(L, r);
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

void open_height_map(lua_State* L) {
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
}

}  // namespace asperity::lua::surface_wrap
