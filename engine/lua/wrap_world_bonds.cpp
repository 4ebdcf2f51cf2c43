// world: bonds (install, strength, list, break events) and checkpoints (save, asperity.load).
#include <cmath>
#include <cstdio>
#include <limits>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

namespace {

// ---------------------------------------------------------------------------------------------
// Bonds

int world_install_bonds(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string ctx = "world:install_bonds";
    Options o(L, 2, ctx, 2);
    // The material's defaults and its checks are the World's (materials.hpp, field_problems.hpp).
    BondMaterial m;
    for_each_field(m, [&](const Field& f, auto& v) { read_option(L, o, f, v); });
    double tolerance = o.number("tolerance", -1);
    const bool stress_free = o.boolean("stress_free", false);
    std::vector<std::int64_t> ids;
    if (o.push("ids") != LUA_TNIL) ids = ids_arg(L, lua_gettop(L), w, ctx.c_str());
    lua_pop(L, 1);
    o.finish();
    lua_pushinteger(L, static_cast<lua_Integer>(w.install_bonds(m, tolerance, ids, stress_free)));
    return 1;
  });
}

// Checkpoints: world:save(path), asperity.load(path [, {threads=, simd=}]).
int world_save(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string path = check_string(L, 2);
    w.save(path);
    return 0;
  });
}

int world_set_bond_strength(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:set_bond_strength", 2);
    const bool breakable = o.boolean("breakable", true);
    const auto st = o.number("tensile_strength");
    const auto c = o.number("contact_strength");
    const auto cs = o.number("contact_shear_strength");
    const auto mub = o.number("contact_bond_friction");
    o.finish();
    w.set_bond_strength(st ? *st : 0.0, breakable, c, cs, mub);
    return 0;
  });
}

int world_remove_bonds(lua_State* L) {
  return guarded(L, [&] {
    world_arg(L).remove_bonds();
    return 0;
  });
}

int world_bond_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).bond_count()));
    return 1;
  });
}

int world_bonds(lua_State* L) {
  return guarded(L, [&] {
    const std::vector<bool> fields = row_field_mask<BondInfo>(L, 2, "world:bonds");
    std::vector<BondInfo> bs = world_arg(L).bonds();
    lua_createtable(L, static_cast<int>(bs.size()), 0);
    for (std::size_t k = 0; k < bs.size(); ++k) {
      push_row(L, bs[k], &fields);
      lua_rawseti(L, -2, static_cast<lua_Integer>(k + 1));
    }
    return 1;
  });
}

int world_break_events(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::vector<BreakEvent>& events = w.break_events();
    lua_Integer first = opt_integer(L, 2, 1);
    if (first < 1) throw ArgError{2, "events are numbered from 1"};
    lua_createtable(L, 0, 0);
    lua_Integer k = 0;
    for (std::size_t i = static_cast<std::size_t>(first - 1); i < events.size(); ++i) {
      push_row(L, events[i]);
      lua_rawseti(L, -2, ++k);
    }
    return 1;
  });
}

// world:break_count([kind]): "beam" (the default: the thesis's broken bonds), "contact_bond",
// or "all" (every event: the numbering of world:break_events).
int world_break_count(lua_State* L) {
  return guarded(L, [&] {
    const std::vector<BreakEvent>& events = world_arg(L).break_events();
    const std::string kind = lua_isnoneornil(L, 2) ? "beam" : check_string(L, 2);
    if (kind != "beam" && kind != "contact_bond" && kind != "all")
      throw ArgError{2, "kind must be \"beam\", \"contact_bond\" or \"all\", got \"" + kind + "\""};
    std::size_t n = events.size();
    if (kind != "all") {
      n = 0;
      for (const BreakEvent& e : events) n += kind == name_of(e.kind);
    }
    lua_pushinteger(L, static_cast<lua_Integer>(n));
    return 1;
  });
}

// install_bonds' help, with the bond material's fields from their table (materials.hpp).
const char* install_bonds_help() {
  static const std::string text =
      "Bonds (contact + parallel bond, model.md 5) between every pair closer than tolerance\n"
      "(default 1e-3 mean radius); ids (a list or predicate) restricts them to pairs of those\n"
      "particles. Existing contact forces are kept; stress_free = true unloads each contact bond\n"
      "at its current overlap instead (a contact left by a break keeps that rest overlap until the\n"
      "pair separates). A breakable bond needs tensile_strength.\n"
      "The material's fields (default: meaning):" + bond_material_fields_help();
  return text.c_str();
}

}  // namespace

int load_world(lua_State* L) {
  return guarded(L, [&] {
    const std::string path = check_string(L, 1);
    int threads = 0;
    std::string simd = "auto";
    if (!lua_isnoneornil(L, 2)) {
      Options o(L, 2, "asperity.load", 2);
      threads = int_in(o.integer("threads", threads), "asperity.load: threads", 0, kMaxThreads);
      simd = o.string("simd", simd);
      o.finish();
    }
    World loaded = World::load(path, threads, simd);
    void* mem = lua_newuserdatauv(L, sizeof(World), 0);
    new (mem) World(std::move(loaded));
    luaL_setmetatable(L, kWorldType);
    return 1;
  });
}

int bond_criterion(lua_State* L) {
  return guarded(L, [&] {
    double sigma = check_number(L, 1), tau = check_number(L, 2), st = check_number(L, 3);
    lua_pushnumber(L, World::bond_criterion(sigma, tau, st));
    return 1;
  });
}

std::span<const Function> world_bond_methods() {
  static const std::string bonds_help = "Bonds of which a part holds: " + row_fields<BondInfo>() +
                                        ";\nbeam and contact_bond say which part holds (model.md 5: they break separately);\n"
                                        "fields: only those (a row of every field is about 1 kB of Lua memory).";
  static const std::string breaks_help =
      "Bond breaks so far (from number `first`): " + row_fields<BreakEvent>() +
      ";\nkind is \"beam\" (the parallel bond) or \"contact_bond\", mode \"tension\", \"compression\" or \"shear\".";
  static const Function methods[] = {
      {"install_bonds", world_install_bonds,
       "world:install_bonds{tensile_strength= | breakable=false [, beam_kn=] [, beam_ks=]\n"
       "  [, radius_factor=] [, tolerance=] [, ids=] [, stress_free=false]} -> count",
       install_bonds_help()},
      {"bond_count", world_bond_count, "world:bond_count() -> n",
       "Parallel bonds that hold (a pair held by its contact bond alone is not counted)."},
      {"set_bond_strength", world_set_bond_strength,
       "world:set_bond_strength{tensile_strength= | breakable=false [, contact_strength=]\n"
       "  [, contact_shear_strength=] [, contact_bond_friction=]}",
       "Changes the strength of every bond (stiffness and stored forces unchanged); contact_strength\n"
       "(c: the contact bond breaks at c st A; 0 with the beam, math.huge never) and\n"
       "contact_shear_strength (cs: in shear at cs st A; 0 as c) and contact_bond_friction (mu_b:\n"
       "+ mu_b Fn under compression) stay as they are unless given."},
      {"remove_bonds", world_remove_bonds, "world:remove_bonds()",
       "Deletes every bond (no break events; bonded pairs become ordinary contacts)."},
      {"save", world_save, "world:save(path)",
       "Writes a checkpoint (the whole state, HDF5); asperity.load(path) continues bit for bit."},
      {"bonds", world_bonds, "world:bonds([{fields = {name, ...}}]) -> {bond, ...}", bonds_help.c_str()},
      {"break_events", world_break_events, "world:break_events([first]) -> {event, ...}", breaks_help.c_str()},
      {"break_count", world_break_count, "world:break_count([kind]) -> n",
       "Breaks so far of kind \"beam\" (the default: parallel bonds, the thesis's broken bonds),\n"
       "\"contact_bond\", or \"all\" (the numbering of world:break_events)."},
  };
  return methods;
}

}  // namespace asperity::lua
