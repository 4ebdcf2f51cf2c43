// world: particles (add, read, set, in bulk) and their labels (tags, flags) with the contact
// measurements made by them.
#include <cmath>
#include <cstdio>
#include <limits>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

namespace {

// ---------------------------------------------------------------------------------------------
// Particles

int world_add_particle(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    Vec3 x = check_vec(L, 2);
    double r = check_number(L, 3);
    double rho = opt_number(L, 4, 0.0);
    lua_pushinteger(L, w.add_particle(x, r, rho) + 1);
    return 1;
  });
}

int world_add_particles(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::size_t cols = 1;
    std::vector<double> xyz = check_numbers(L, 2, &cols);
    if (cols != 3 && !(cols == 1 && xyz.size() % 3 == 0))
      throw ArgError{2, "positions must be n x 3 (an Array, {{x,y,z},...} or a flat {x1,y1,z1,...})"};
    std::size_t n = xyz.size() / 3;
    std::vector<double> radii;
    if (lua_type(L, 3) == LUA_TNUMBER) {
      radii.assign(n, lua_tonumber(L, 3));
    } else {
      std::size_t rc = 1;
      radii = check_numbers(L, 3, &rc);
      if (rc != 1 || radii.size() != n)
        throw ArgError{3, "radii: one number per particle (" + std::to_string(n) + "), or a number"};
    }
    double rho = opt_number(L, 4, 0.0);
    if (n == 0) {
      lua_pushnil(L);
      lua_pushnil(L);
      return 2;
    }
    std::int64_t first = w.add_particles(xyz, radii, rho);
    lua_pushinteger(L, first + 1);
    lua_pushinteger(L, first + static_cast<std::int64_t>(n));
    return 2;
  });
}

int world_particle_count(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).particle_count()));
    return 1;
  });
}

template <Vec3 (World::*Get)(std::int64_t) const>
int get_particle_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    push_vec(L, (w.*Get)(particle_arg(L, 2, w)));
    return 1;
  });
}

template <double (World::*Get)(std::int64_t) const>
int get_particle_number(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushnumber(L, (w.*Get)(particle_arg(L, 2, w)));
    return 1;
  });
}

template <void (World::*Set)(std::int64_t, Vec3)>
int set_particle_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    (w.*Set)(id, check_vec(L, 3));
    return 0;
  });
}

int world_group_of(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int g = w.group_of(particle_arg(L, 2, w));
    if (g < 0) lua_pushnil(L);
    else lua_pushinteger(L, g + 1);
    return 1;
  });
}

// world:set_X(id, value) for a per-particle number (radius, density).
template <void (World::*Set)(std::int64_t, double)>
int set_particle_number(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    (w.*Set)(id, check_number(L, 3));
    return 0;
  });
}

int world_set_rotation_locked(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::int64_t id = particle_arg(L, 2, w);
    w.set_rotation_locked(id, check_boolean(L, 3));
    return 0;
  });
}

int world_scale_radii(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.scale_radii(check_number(L, 2));
    return 0;
  });
}

template <std::vector<double> (World::*Get)() const, std::size_t Cols>
int get_bulk(lua_State* L) {
  return guarded(L, [&] {
    push_array(L, (world_arg(L).*Get)(), Cols);
    return 1;
  });
}

template <void (World::*Set)(std::int64_t, Vec3)>
int set_bulk_vec(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::size_t cols = 1;
    std::vector<double> v = check_numbers(L, 2, &cols);
    std::size_t n = w.particle_count();
    if (v.size() != 3 * n || (cols != 3 && cols != 1))
      throw ArgError{2, "need " + std::to_string(n) + " x 3 values (one vector per particle), got " +
                            std::to_string(v.size()) + " values"};
    for (std::size_t i = 0; i < n; ++i)
      (w.*Set)(static_cast<std::int64_t>(i), {v[3 * i], v[3 * i + 1], v[3 * i + 2]});
    return 0;
  });
}

// ---------------------------------------------------------------------------------------------
// Tags and flags (labels for measurements, e.g. the two halves of a joint)

int world_set_tag(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_tag");
    w.set_tag(ids, int_in(check_integer(L, 3), "world:set_tag: tag", INT32_MIN, INT32_MAX));
    return 0;
  });
}

int world_tag(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushinteger(L, w.tag(particle_arg(L, 2, w)));
    return 1;
  });
}

int world_set_flags(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    std::vector<std::int64_t> ids = ids_arg(L, 2, w, "world:set_flags");
    lua_Integer flags = check_integer(L, 3);
    if (flags < 0 || flags > 255) throw ArgError{3, "flags are 8 bits (0..255)"};
    w.set_flags(ids, static_cast<std::uint8_t>(flags));
    return 0;
  });
}

int world_flags(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_pushinteger(L, w.flags(particle_arg(L, 2, w)));
    return 1;
  });
}

int world_contact_summary(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int a = int_in(check_integer(L, 2), "world:contact_summary: tag_a", INT32_MIN, INT32_MAX);
    int b = int_in(check_integer(L, 3), "world:contact_summary: tag_b", INT32_MIN, INT32_MAX);
    lua_Integer mask = opt_integer(L, 4, 0);
    if (mask < 0 || mask > 255) throw ArgError{4, "a flag mask is 8 bits (0..255)"};
    ContactSummary c = w.contact_summary(a, b, static_cast<std::uint8_t>(mask));
    lua_createtable(L, 0, 5);
    lua_pushinteger(L, static_cast<lua_Integer>(c.count));
    lua_setfield(L, -2, "count");
    lua_pushnumber(L, c.area);
    lua_setfield(L, -2, "area");
    push_vec(L, c.force);
    lua_setfield(L, -2, "force");
    lua_pushinteger(L, static_cast<lua_Integer>(c.flagged_count));
    lua_setfield(L, -2, "flagged_count");
    push_vec(L, c.flagged_force);
    lua_setfield(L, -2, "flagged_force");
    return 1;
  });
}

int world_contact_stress(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    int tag = static_cast<int>(check_integer(L, 2));
    double volume = luaL_checknumber(L, 3);
    const World::ContactStress c = w.contact_stress(tag, volume);
    lua_pushnumber(L, c.stress);
    lua_pushnumber(L, c.stiffness);
    lua_pushinteger(L, static_cast<lua_Integer>(c.contacts));
    return 3;
  });
}

}  // namespace

std::span<const Function> world_particle_methods() {
  static const Function methods[] = {
      {"add_particle", world_add_particle, "world:add_particle(pos, radius [, density]) -> id",
       "Adds a sphere at pos {x, y, z}; density defaults to the world's. Ids count from 1.\n"
       "Accepted: radius 1e-6..1e3 m, density 1e-6..1e9 kg/m^3, |x|, |y|, |z| <= 1e9 m."},
      {"add_particles", world_add_particles,
       "world:add_particles(positions, radii [, density]) -> first_id, last_id",
       "Adds many spheres at once: positions an n x 3 Array or {{x,y,z}, ...}; radii an Array,\n"
       "a table or one number for all."},
      {"particle_count", world_particle_count, "world:particle_count() -> n", "Number of particles."},
      {"position", get_particle_vec<&World::position>, "world:position(id) -> vec", "Centre (m)."},
      {"velocity", get_particle_vec<&World::velocity>, "world:velocity(id) -> vec",
       "Velocity (m/s), at the last half step (leapfrog)."},
      {"angular_velocity", get_particle_vec<&World::angular_velocity>,
       "world:angular_velocity(id) -> vec", "Angular velocity (rad/s)."},
      {"force", get_particle_vec<&World::force>, "world:force(id) -> vec",
       "Contact + applied force of the last step (N)."},
      {"torque", get_particle_vec<&World::torque>, "world:torque(id) -> vec", "Torque of the last step (N m)."},
      {"radius", get_particle_number<&World::radius>, "world:radius(id) -> r", "Radius (m)."},
      {"mass", get_particle_number<&World::mass>, "world:mass(id) -> m", "Mass (kg)."},
      {"density", get_particle_number<&World::density>, "world:density(id) -> rho", "Density (kg/m^3)."},
      {"group_of", world_group_of, "world:group_of(id) -> group or nil", "The particle's rigid group."},
      {"set_position", set_particle_vec<&World::set_position>, "world:set_position(id, pos)", "Moves a particle."},
      {"set_velocity", set_particle_vec<&World::set_velocity>, "world:set_velocity(id, v)", "Sets a particle's velocity."},
      {"set_angular_velocity", set_particle_vec<&World::set_angular_velocity>,
       "world:set_angular_velocity(id, w)", "Sets a particle's angular velocity."},
      {"set_force", set_particle_vec<&World::set_applied_force>, "world:set_force(id, f)",
       "A constant external force on the particle, until set again ({0,0,0} removes it)."},
      {"set_radius", set_particle_number<&World::set_radius>, "world:set_radius(id, r)", "Changes a radius; mass follows (density kept)."},
      {"set_density", set_particle_number<&World::set_density>, "world:set_density(id, rho)",
       "Changes a density (kg/m^3); mass and inertia follow, and its group's. A quasi-static process may weigh its lightest particles more: a larger critical time step."},
      {"set_rotation_locked", world_set_rotation_locked, "world:set_rotation_locked(id, locked)",
       "Stops (true) or allows (false) the particle's rotation."},
      {"scale_radii", world_scale_radii, "world:scale_radii(factor)",
       "Multiplies every radius (radius expansion); masses follow."},
      {"positions", get_bulk<&World::positions, 3>, "world:positions() -> Array(n x 3)", "All centres, row id."},
      {"velocities", get_bulk<&World::velocities, 3>, "world:velocities() -> Array(n x 3)", "All velocities."},
      {"forces", get_bulk<&World::forces, 3>, "world:forces() -> Array(n x 3)", "All forces of the last step."},
      {"radii", get_bulk<&World::radii, 1>, "world:radii() -> Array(n)", "All radii."},
      {"set_positions", set_bulk_vec<&World::set_position>, "world:set_positions(positions)",
       "Moves every particle: an n x 3 Array or table."},
      {"set_velocities", set_bulk_vec<&World::set_velocity>, "world:set_velocities(velocities)",
       "Sets every particle's velocity: an n x 3 Array or table."},
      {"set_tag", world_set_tag, "world:set_tag(ids or predicate, tag)",
       "An integer label per particle (default 0), e.g. the two halves of a joint."},
      {"tag", world_tag, "world:tag(id) -> tag", "The particle's tag."},
      {"set_flags", world_set_flags, "world:set_flags(ids or predicate, flags)", "Flag bits (0..255) per particle."},
      {"flags", world_flags, "world:flags(id) -> flags", "The particle's flag bits."},
      {"contact_summary", world_contact_summary,
       "world:contact_summary(tag_a, tag_b [, flag_mask]) -> {count, area, force, flagged_count, flagged_force}",
       "Touching contacts between two tags: number, contact area (sum pi a^2, m^2, [4-1]), total\n"
       "force on the tag_b particles; flagged_*: those involving a particle with flag_mask bits."},
      {"contact_stress", world_contact_stress, "world:contact_stress(tag, volume) -> Pa, Pa, n",
       "Mean stress of the particles of a tag from their touching contacts (Love-Weber):\n"
       "sum Fn d / (3 volume), d the distance of the centres; compression positive. Then its affine\n"
       "stiffness against a common radius factor f, dp/df = sum kn (Ra + Rb) d / (3 volume), and\n"
       "the number of those contacts."},
  };
  return methods;
}

}  // namespace asperity::lua
