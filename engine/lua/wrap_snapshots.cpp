// asperity.snapshots: particle snapshots to HDF5 with an XDMF index (io::SnapshotSeries).
//
//   local snaps = asperity.snapshots{dir = "out/demo", name = "particles"}
//   snaps:write(world)     -- out/demo/particles_000000.h5, particles.xdmf (+ _contacts.xdmf)
//
// Ids and group numbers in the files are Lua's (from 1), so what a script prints and what
// ParaView shows agree.
#include <new>

#include "asperity/io.hpp"
#include "asperity/world.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {

constexpr const char* kSnapshotsType = "asperity.Snapshots";

struct Snapshots {
  io::SnapshotSeries series;
  bool contacts;
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
    o.finish();
    if (dir.empty()) throw Error("asperity.snapshots: give dir = \"output directory\"");
    io::SnapshotSeries series(dir, name);  // creates the directory; may throw
    void* mem = lua_newuserdatauv(L, sizeof(Snapshots), 0);
    new (mem) Snapshots{std::move(series), contacts};
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
    io::Snapshot snap = io::take_snapshot(*world, s.contacts, 1);
    snap.attributes = std::move(attributes);
    std::string path = s.series.write(snap).string();
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
      {"write", snapshots_write, "snaps:write(world [, attributes]) -> path",
       "Writes the next snapshot (particles: id, position, velocity, radius, group; contacts;\n"
       "bonds when there are any)\n"
       "and rewrites the XDMF index. attributes: {name = number|string} stored in the file."},
      {"count", snapshots_count, "snaps:count() -> n", "Snapshots written."},
      {"xdmf", snapshots_xdmf, "snaps:xdmf() -> path", "The XDMF file to open in ParaView."},
  };
  static const luaL_Reg meta[] = {{"__gc", snapshots_gc}};
  new_type(L, kSnapshotsType, methods, meta,
           "Snapshots: a series of HDF5 particle snapshots with an XDMF index for ParaView.");
  lua_pop(L, 1);
  static const Function fns[] = {
      {"snapshots", snapshots_new, "asperity.snapshots{dir= [, name=\"particles\"] [, contacts=true]}",
       "A snapshot writer into dir (created if needed): NAME_000000.h5, ... and NAME.xdmf;\n"
       "with contacts, also NAME_contacts.xdmf (contacts as lines, for force chains), and\n"
       "NAME_bonds.xdmf when the world has bonds."},
  };
  register_functions(L, -1, fns);
}

}  // namespace asperity::lua
