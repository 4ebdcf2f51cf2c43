// world: walls (planes, meshes) and rigid groups with their motions (free, fixed, velocity, servo).
#include <cmath>
#include <cstdio>
#include <limits>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

namespace {

// ---------------------------------------------------------------------------------------------
// Walls

int world_add_plane(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:add_plane", 2);
    auto point = o.vec("point");
    auto normal = o.vec("normal");
    ContactMaterial m = material_field(L, o, "material", w.settings().contact);
    o.finish();
    if (!point || !normal) throw Error("world:add_plane: give point = {x, y, z} and normal = {x, y, z}");
    lua_pushinteger(L, w.add_plane(*point, *normal, m) + 1);
    return 1;
  });
}

int world_add_mesh(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Options o(L, 2, "world:add_mesh", 2);
    ContactMaterial m = material_field(L, o, "material", w.settings().contact);
    if (o.push("vertices") == LUA_TNIL) throw Error("world:add_mesh: give vertices = {{x,y,z}, ...}");
    int vi = lua_gettop(L);
    if (o.push("triangles") == LUA_TNIL) throw Error("world:add_mesh: give triangles = {{i,j,k}, ...}");
    int ti = lua_gettop(L);
    o.finish();
    std::size_t vc = 1, tc = 1;
    std::vector<double> vflat = check_numbers(L, vi, &vc);
    std::vector<double> tflat = check_numbers(L, ti, &tc);
    if (vc != 3 || tc != 3)
      throw Error("world:add_mesh: vertices and triangles must be lists of 3 numbers each");
    std::vector<Vec3> vertices(vflat.size() / 3);
    for (std::size_t i = 0; i < vertices.size(); ++i)
      vertices[i] = {vflat[3 * i], vflat[3 * i + 1], vflat[3 * i + 2]};
    std::vector<std::array<int, 3>> triangles(tflat.size() / 3);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        double idx = tflat[3 * t + static_cast<std::size_t>(k)];
        if (idx != std::floor(idx) || idx < 1 || idx > static_cast<double>(vertices.size()))
          throw Error("world:add_mesh: triangle " + std::to_string(t + 1) +
                      " refers to vertex " + number_text(idx) + " (vertices are 1.." +
                      std::to_string(vertices.size()) + ")");
        triangles[t][static_cast<std::size_t>(k)] = static_cast<int>(idx) - 1;
      }
    lua_pushinteger(L, w.add_mesh(vertices, triangles, m) + 1);
    return 1;
  });
}

int world_set_wall_velocity(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int wall = wall_arg(L, 2, w);
    w.set_wall_velocity(wall, check_vec(L, 3));
    return 0;
  });
}

template <Vec3 (World::*Get)(int) const>
int get_wall_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(wall_arg(L, 2, w)));
    return 1;
  });
}

int world_remove_wall(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.remove_wall(wall_arg(L, 2, w));
    return 0;
  });
}

int world_wall_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).wall_count()));
    return 1;
  });
}

// ---------------------------------------------------------------------------------------------
// Groups

Dof dof_from_name(const std::string& name, const std::string& where) {
  if (name == "free") return Dof::free;
  if (name == "fixed") return Dof::fixed;
  if (name == "velocity") return Dof::velocity;
  if (name == "servo") return Dof::servo;
  throw Error(where + ": unknown motion '" + name + "' (valid: free, fixed, velocity, servo)");
}

Servo servo_fields(lua_State* L, int index, const std::string& context, Servo s) {
  Options o(L, index, context, 0);
  for_each_field(s, [&](const Field& f, double& v) { v = o.number(f.name, v); });
  o.finish();
  return s;
}


// A motion table (the fields of GroupMotion's table, world.hpp), read by the rules between its
// fields: translation one mode for all axes or three; a velocity alone prescribes the
// translation, an angular velocity alone the rotation; servo one table (servo_fields) for every
// servo axis, or three.
GroupMotion motion_arg(lua_State* L, int index, const std::string& context, int arg,
                       GroupMotion m) {
  Options o(L, index, context, arg);
  int t = o.push("translation");
  if (t == LUA_TSTRING) {
    Dof d = dof_from_name(lua_tostring(L, -1), context + " option 'translation'");
    m.translation = {d, d, d};
  } else if (t == LUA_TTABLE) {
    if (lua_rawlen(L, -1) != 3)
      throw Error(context + ": option 'translation' must be one name or three {x, y, z}");
    for (int k = 0; k < 3; ++k) {
      if (lua_rawgeti(L, -1, k + 1) != LUA_TSTRING)
        throw Error(context + ": option 'translation' must list names (free, fixed, velocity)");
      m.translation[static_cast<std::size_t>(k)] =
          dof_from_name(lua_tostring(L, -1), context + " option 'translation'");
      lua_pop(L, 1);
    }
  } else if (t != LUA_TNIL) {
    throw Error(context + ": option 'translation' must be a string or a table of three strings");
  }
  lua_pop(L, 1);
  if (auto v = o.vec("velocity")) {
    m.velocity = *v;
    if (t == LUA_TNIL) m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
  }
  int st = o.push_checked("servo", LUA_TTABLE, "a table {target_force=, ...} or three of them");
  if (st == LUA_TTABLE) {
    int si = lua_gettop(L);
    bool has_servo_axis = false;
    for (Dof d : m.translation) has_servo_axis = has_servo_axis || d == Dof::servo;
    if (!has_servo_axis)
      throw Error(context + ": option 'servo' needs a servo axis, e.g. translation = {\"fixed\", \"fixed\", \"servo\"}");
    if (lua_rawgeti(L, si, 1) == LUA_TTABLE) {
      lua_pop(L, 1);
      for (int k = 0; k < 3; ++k) {
        lua_rawgeti(L, si, k + 1);
        auto axis = static_cast<std::size_t>(k);
        m.servo[axis] = servo_fields(L, -1, context + " option 'servo'[" + std::to_string(k + 1) + "]", m.servo[axis]);
        lua_pop(L, 1);
      }
    } else {
      lua_pop(L, 1);
      for (std::size_t k = 0; k < 3; ++k)
        if (m.translation[k] == Dof::servo) m.servo[k] = servo_fields(L, si, context + " option 'servo'", m.servo[k]);
    }
  }
  lua_pop(L, 1);
  m.damping = o.number("damping", m.damping);
  std::string rotation = o.string("rotation", "");
  if (!rotation.empty()) m.rotation = dof_from_name(rotation, context + " option 'rotation'");
  if (auto w = o.vec("angular_velocity")) {
    m.angular_velocity = *w;
    if (rotation.empty()) m.rotation = Dof::velocity;
  }
  o.finish();
  return m;
}

// A motion's field as Lua shows it: modes by name, vectors {x, y, z}, servos as tables.
void push_field(lua_State* L, Dof d) { lua_pushstring(L, dof_name(d)); }
void push_field(lua_State* L, const std::array<Dof, 3>& modes) {
  lua_createtable(L, 3, 0);
  for (int k = 0; k < 3; ++k) {
    push_field(L, modes[static_cast<std::size_t>(k)]);
    lua_rawseti(L, -2, k + 1);
  }
}
void push_field(lua_State* L, const Vec3& v) { push_vec(L, v); }
void push_field(lua_State* L, double v) { lua_pushnumber(L, v); }
void push_field(lua_State* L, const std::array<Servo, 3>& servos) {
  lua_createtable(L, 3, 0);
  for (int k = 0; k < 3; ++k) {
    push_servo(L, servos[static_cast<std::size_t>(k)]);
    lua_rawseti(L, -2, k + 1);
  }
}
void push_motion(lua_State* L, const GroupMotion& m) {
  lua_createtable(L, 0, 6);
  for_each_field(m, [&](const Field& f, const auto& v) {
    push_field(L, v);
    lua_setfield(L, -2, f.name);
  });
}

int world_add_group(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:add_group");
    GroupMotion m = motion_arg(L, 3, "world:add_group", 3, GroupMotion{});
    lua_pushinteger(L, w.add_group(ids, m) + 1);
    return 1;
  });
}

int world_set_inert(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_inert");
    bool inert = lua_isnoneornil(L, 3) ? true : check_boolean(L, 3);
    w.set_inert(ids, inert);
    return 0;
  });
}

int world_inert_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).inert_count()));
    return 1;
  });
}

int world_set_group_motion(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    check_table(L, 3);
    // Fields not given keep their current setting.
    w.set_group_motion(g, motion_arg(L, 3, "world:set_group_motion", 3, w.group_motion(g)));
    return 0;
  });
}

int world_group_motion(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_motion(L, w.group_motion(group_arg(L, 2, w)));
    return 1;
  });
}

int world_set_group_velocity(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    GroupMotion m = w.group_motion(g);
    m.velocity = check_vec(L, 3);
    m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
    w.set_group_motion(g, m);
    return 0;
  });
}

int world_set_group_force(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = group_arg(L, 2, w);
    w.set_group_applied_force(g, check_vec(L, 3));
    return 0;
  });
}

template <Vec3 (World::*Get)(int) const>
int get_group_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(group_arg(L, 2, w)));
    return 1;
  });
}

int world_group_mass(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushnumber(L, w.group_mass(group_arg(L, 2, w)));
    return 1;
  });
}

int world_group_members(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = w.group_members(group_arg(L, 2, w));
    lua_createtable(L, static_cast<int>(ids.size()), 0);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      lua_pushinteger(L, ids[i] + 1);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}

int world_group_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).group_count()));
    return 1;
  });
}

// add_group's help: the motion table, and the servo's fields from their table (world.hpp).
const char* add_group_help() {
  static const std::string text =
      "A rigid group of particles: a list of ids, or function(id, pos, r) returning true for\n"
      "members, moving as `motion` says (fields not given keep their defaults; translation is one\n"
      "mode for all axes or three; a velocity alone prescribes it, an angular velocity alone the\n"
      "rotation; servo is one table for every servo axis or three). Its fields (default: meaning):" +
      motion_fields_help() +
      "\nA servo axis moves at clamp(G (F - F_target), max_velocity) with F the particles' force on\n"
      "the group along it; its fields:" + servo_fields_help();
  return text.c_str();
}

}  // namespace

void push_servo(lua_State* L, const Servo& s) {
  lua_createtable(L, 0, 6);
  for_each_field(s, [&](const Field& f, double v) {
    lua_pushnumber(L, v);
    lua_setfield(L, -2, f.name);
  });
}

std::span<const Function> world_body_methods() {
  static const Function methods[] = {
      {"add_plane", world_add_plane, "world:add_plane{point=, normal= [, material=]} -> wall",
       "An infinite plane through point; normal points to where the particles are.\n"
       "material = {kn=, ks=, friction=} defaults to the world's material."},
      {"add_mesh", world_add_mesh,
       "world:add_mesh{vertices=, triangles= [, material=]} -> wall",
       "A two-sided triangle mesh: vertices {{x,y,z},...} or an Array; triangles {{i,j,k},...}\n"
       "with vertex numbers from 1."},
      {"set_wall_velocity", world_set_wall_velocity, "world:set_wall_velocity(wall, v)", "Prescribed translation velocity."},
      {"wall_velocity", get_wall_vec<&World::wall_velocity>, "world:wall_velocity(wall) -> vec", "Its velocity."},
      {"wall_displacement", get_wall_vec<&World::wall_displacement>, "world:wall_displacement(wall) -> vec",
       "Displacement since creation (m)."},
      {"wall_force", get_wall_vec<&World::wall_force>, "world:wall_force(wall) -> vec",
       "Force of the particles on the wall, last step (N)."},
      {"remove_wall", world_remove_wall, "world:remove_wall(wall)", "Removes it (its number is not reused)."},
      {"wall_count", world_wall_count, "world:wall_count() -> n", "Walls created, removed ones included."},
      {"add_group", world_add_group, "world:add_group(ids or predicate [, motion]) -> group",
       add_group_help()},
      {"set_group_motion", world_set_group_motion, "world:set_group_motion(group, motion)",
       "Changes how the group moves (fields not given are kept); see add_group."},
      {"group_motion", world_group_motion, "world:group_motion(group) -> motion", "Its motion table."},
      {"set_group_velocity", world_set_group_velocity, "world:set_group_velocity(group, v)",
       "Prescribes the group's translation velocity on all three axes."},
      {"set_group_force", world_set_group_force, "world:set_group_force(group, f)",
       "A constant external force on the group."},
      {"group_force", get_group_vec<&World::group_force>, "world:group_force(group) -> vec",
       "Contact + applied force on the members, last step (N)."},
      {"group_impulse", get_group_vec<&World::group_impulse>, "world:group_impulse(group) -> vec",
       "Sum of group_force x dt since the world was made or loaded (N s): mean force over an "
       "interval = change of impulse / change of world:time()."},
      {"group_torque", get_group_vec<&World::group_torque>, "world:group_torque(group) -> vec",
       "Torque about the centre of mass (N m)."},
      {"group_position", get_group_vec<&World::group_position>, "world:group_position(group) -> vec", "Centre of mass."},
      {"group_velocity", get_group_vec<&World::group_velocity>, "world:group_velocity(group) -> vec", "Its velocity."},
      {"group_mass", world_group_mass, "world:group_mass(group) -> m", "Total mass (kg)."},
      {"group_members", world_group_members, "world:group_members(group) -> {ids}", "Its particles."},
      {"group_count", world_group_count, "world:group_count() -> n", "Number of groups."},
      {"set_inert", world_set_inert, "world:set_inert(ids or predicate [, inert=true])",
       "Members of a translating group that can never touch anything (the inside of a rigid\n"
       "block): left out of the contact search, so a rigid body costs what its surface costs."},
      {"inert_count", world_inert_count, "world:inert_count() -> n", "Inert particles."},
  };
  return methods;
}

}  // namespace asperity::lua
