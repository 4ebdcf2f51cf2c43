// asperity.surface: from a synthetic surface to the DEM surface of a packed half (surfaces.md 3):
// the profilometer, the mean plane, surface vs porosity particles, the noise study.
#include "lua/wrap_surface.hpp"

namespace asperity::lua::surface_wrap {

namespace {

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

}  // namespace

std::span<const Function> dem_surface_functions() {
  static const Function fns[] = {
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
  return fns;
}

}  // namespace asperity::lua::surface_wrap
