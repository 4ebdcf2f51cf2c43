// asperity.snapshots: particle snapshots to HDF5 with an XDMF index (io::SnapshotSeries).
//
//   local snaps = asperity.snapshots{dir = "out/demo", name = "particles"}
//   snaps:write(world)     -- out/demo/particles_000000.h5, particles.xdmf (+ _contacts.xdmf)
//
//   -- indexed by shear displacement, legends for the integer keys, one tag left out:
//   local snaps = asperity.snapshots{dir = out, name = "joint", time = "shear displacement (mm)",
//                                    keys = {tag = "1: lower half, 2: upper half"}, exclude_tag = 3}
//   snaps:write(world, {stage = "shear"}, 2.5)
//
// Ids and group numbers in the files are Lua's (from 1), so what a script prints and what
// ParaView shows agree.
#include <algorithm>
#include <cmath>
#include <new>
#include <optional>

#include "asperity/io.hpp"
#include "asperity/world.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {

constexpr const char* kSnapshotsType = "asperity.Snapshots";

struct Snapshots {
  io::SnapshotSeries series;
  bool contacts;
  std::optional<lua_Integer> exclude_tag;
};

Snapshots& snapshots_arg(lua_State* L) {
  return *static_cast<Snapshots*>(check_udata(L, 1, kSnapshotsType));
}

int snapshots_new(lua_State* L) {
  return guarded(L, [&] {
    Options o(L, 1, "asperity.snapshots", 1);
    std::string dir = o.string("dir", "");
    std::string name = o.string("name", "particles");
    bool contacts = o.boolean("contacts", true);
    io::SnapshotSeriesOptions options;
    options.time_label = o.string("time", "");
    lua_Integer keep = o.integer("keep", 0);
    if (keep < 0) throw Error("asperity.snapshots: option 'keep' must be >= 0 (snapshots already written)");
    options.keep = static_cast<std::size_t>(keep);
    std::optional<lua_Integer> exclude;
    if (o.present("exclude_tag")) exclude = o.integer("exclude_tag", 0);
    if (o.push_checked("keys", LUA_TTABLE, "a table {group = \"1: ...\", tag = \"...\"}") == LUA_TTABLE) {
      lua_pushnil(L);
      while (lua_next(L, -2) != 0) {
        if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TSTRING)
          throw Error("asperity.snapshots: keys must map a particle field name to its legend (strings)");
        options.keys.emplace_back(std::string(lua_tostring(L, -2)) + "_key", std::string(lua_tostring(L, -1)));
        lua_pop(L, 1);
      }
    }
    lua_pop(L, 1);
    std::sort(options.keys.begin(), options.keys.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    o.finish();
    if (dir.empty()) throw Error("asperity.snapshots: give dir = \"output directory\"");
    io::SnapshotSeries series(dir, name, std::move(options));  // creates the directory; may throw
    void* mem = lua_newuserdatauv(L, sizeof(Snapshots), 0);
    new (mem) Snapshots{std::move(series), contacts, exclude};
    luaL_setmetatable(L, kSnapshotsType);
    return 1;
  });
}

int snapshots_gc(lua_State* L) {
  if (void* p = luaL_testudata(L, 1, kSnapshotsType)) static_cast<Snapshots*>(p)->~Snapshots();
  return 0;
}

int snapshots_write(lua_State* L) {
  return guarded(L, [&] {
    Snapshots& s = snapshots_arg(L);
    auto* world = static_cast<World*>(check_udata(L, 2, "asperity.World"));
    io::Attributes attributes = attributes_from(L, 3, "snapshots:write");
    std::optional<double> index_time;
    if (!lua_isnoneornil(L, 4)) {
      index_time = luaL_checknumber(L, 4);
      if (!std::isfinite(*index_time)) throw Error("snaps:write: the time (argument #3) must be finite");
    }
    io::Snapshot snap = io::take_snapshot(*world, s.contacts, 1);
    snap.attributes = std::move(attributes);
    snap.index_time = index_time;
    if (s.exclude_tag) {
      std::vector<bool> keep(snap.tag.size());
      for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = snap.tag[i] != *s.exclude_tag;
      io::drop_particles(snap, keep);
    }
    std::string path = s.series.write(std::move(snap)).string();
    lua_pushstring(L, path.c_str());
    return 1;
  });
}

int snapshots_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(snapshots_arg(L).series.count()));
    return 1;
  });
}

int snapshots_xdmf(lua_State* L) {
  return guarded(L, [&] {
    lua_pushstring(L, snapshots_arg(L).series.xdmf_path().c_str());
    return 1;
  });
}

}  // namespace

void open_snapshots(lua_State* L) {
  static const Function methods[] = {
      {"write", snapshots_write, "snaps:write(world [, attributes [, time]]) -> path",
       "Writes the next snapshot (particles: id, position, velocity, radius, group, tag, force,\n"
       "angular_velocity, displacement since the series' first snapshot; contacts; bonds when\n"
       "there are any) and rewrites the XDMF index. attributes: {name = number|string} stored in\n"
       "the file; time: the XDMF time of this snapshot (default: the simulated time)."},
      {"count", snapshots_count, "snaps:count() -> n", "Snapshots written."},
      {"xdmf", snapshots_xdmf, "snaps:xdmf() -> path", "The XDMF file to open in ParaView."},
  };
  static const luaL_Reg meta[] = {{"__gc", snapshots_gc}};
  new_type(L, kSnapshotsType, methods, meta,
           "Snapshots: a series of HDF5 particle snapshots with an XDMF index for ParaView.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"snapshots", snapshots_new,
       "asperity.snapshots{dir= [, name=\"particles\"] [, contacts=true] [, time=label] [, keys={field=legend}]\n"
       "                   [, exclude_tag=n] [, keep=n]}",
       "A snapshot writer into dir (created if needed): NAME_000000.h5, ... and NAME.xdmf;\n"
       "with contacts, also NAME_contacts.xdmf (contacts as lines, for force chains), and\n"
       "NAME_bonds.xdmf when the world has bonds. Files of an earlier series NAME in dir are\n"
       "removed first (but see keep). time: what the times given to write() are (e.g. \"shear displacement (mm)\");\n"
       "keys: legends of integer fields, stored as /particles attributes FIELD_key and in the\n"
       "XDMF; exclude_tag: particles with this tag are left out of the files. keep: continue a\n"
       "series whose first n snapshots an interrupted run wrote (a resumed run): they are kept\n"
       "and read back, later ones removed; the next write is snapshot n + 1."},
  };
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
