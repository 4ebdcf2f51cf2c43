// Particle store: structure of arrays (model.md 1). Hot columns (positions, velocities, radius,
// inverse mass) are what the kernels stream; cold ones (ids, density) are touched by the API.
//
// Capacity is padded to a multiple of kMaxLanes with at least two null particles beyond the real
// ones: radius 0, zero inverse mass, parked far apart on the x axis. Padding pairs of the pair
// list point at two of them, so their overlap is negative and every force is zero.
#pragma once
#include <bit>
#include <cstdint>
#include <vector>

#include "core/aligned.hpp"
#include "store/columns.hpp"

namespace asperity::detail {

struct ParticleStore {
  std::size_t n = 0;         // real particles
  std::size_t capacity = 0;  // >= n + 2, multiple of kMaxLanes

  AVec<double> x, y, z;        // centre, m
  AVec<double> vx, vy, vz;     // velocity at t - dt/2 (after a step: t + dt/2)
  AVec<double> wx, wy, wz;     // angular velocity
  AVec<double> radius;
  AVec<double> mass, inv_mass, inertia, inv_inertia;
  AVec<double> fx, fy, fz;     // contact + applied force of the last step
  AVec<double> tx, ty, tz;     // torque of the last step
  AVec<double> x0, y0, z0;     // centre at the last neighbour build (rebuild criterion)
  AVec<double> ax, ay, az;     // applied external force (allocated on first use)
  std::vector<std::uint8_t> rotation_locked;  // the lock in force (API, bonds, settings)
  std::vector<std::int32_t> group;  // -1: none
  std::vector<std::int32_t> tag;    // user label
  std::vector<std::uint8_t> flags;  // user bits
  std::vector<std::uint8_t> inert;  // never searched, moved lazily with its group
  std::vector<std::int64_t> id;     // stable id of the particle at this index
  // Per real particle (n long, no null ones):
  std::vector<double> density;
  std::vector<std::uint8_t> user_rotation_locked;  // set by the API; bonds add their own lock
  // How many of its bonds have broken: a particle keeps its rotation lock while it holds
  // min(rotation_lock_bonds, installed) bonds, installed = intact + broken
  // (refresh_bond_topology).
  std::vector<std::int32_t> bonds_broken;
  std::vector<std::int64_t> index_of_id;  // stable id -> current index

  bool has_applied = false;

  // Every column of `capacity` slots once: f(info, column of p). The pad is a null particle's value
  // (x aside: null particles are parked apart, see resize).
  template <class F, class Store>
  static void slot_columns(F&& f, Store& p) {
    f(ColumnInfo{"x"}, p.x);
    f(ColumnInfo{"y"}, p.y);
    f(ColumnInfo{"z"}, p.z);
    f(ColumnInfo{"vx"}, p.vx);
    f(ColumnInfo{"vy"}, p.vy);
    f(ColumnInfo{"vz"}, p.vz);
    f(ColumnInfo{"wx"}, p.wx);
    f(ColumnInfo{"wy"}, p.wy);
    f(ColumnInfo{"wz"}, p.wz);
    f(ColumnInfo{"radius"}, p.radius);
    f(ColumnInfo{"mass"}, p.mass);
    f(ColumnInfo{"inv_mass"}, p.inv_mass);
    f(ColumnInfo{"inertia"}, p.inertia);
    f(ColumnInfo{"inv_inertia"}, p.inv_inertia);
    f(ColumnInfo{"fx"}, p.fx);
    f(ColumnInfo{"fy"}, p.fy);
    f(ColumnInfo{"fz"}, p.fz);
    f(ColumnInfo{"tx"}, p.tx);
    f(ColumnInfo{"ty"}, p.ty);
    f(ColumnInfo{"tz"}, p.tz);
    f(ColumnInfo{"x0"}, p.x0);
    f(ColumnInfo{"y0"}, p.y0);
    f(ColumnInfo{"z0"}, p.z0);
    f(ColumnInfo{"ax", 0, false, 1, true}, p.ax);
    f(ColumnInfo{"ay", 0, false, 1, true}, p.ay);
    f(ColumnInfo{"az", 0, false, 1, true}, p.az);
    f(ColumnInfo{"rotation_locked", 1}, p.rotation_locked);
    f(ColumnInfo{"group", -1}, p.group);
    f(ColumnInfo{"tag"}, p.tag);
    f(ColumnInfo{"flags"}, p.flags);
    f(ColumnInfo{"inert"}, p.inert);
    f(ColumnInfo{"id", -1}, p.id);
  }
  // Every column of `n` entries (real particles only) once, index_of_id aside (it is by id,
  // not by index).
  template <class F, class Store>
  static void particle_columns(F&& f, Store& p) {
    f(ColumnInfo{"density"}, p.density);
    f(ColumnInfo{"user_rotation_locked"}, p.user_rotation_locked);
    f(ColumnInfo{"bonds_broken", 0, false, 7}, p.bonds_broken);
  }

  std::int32_t null_a() const { return static_cast<std::int32_t>(n); }
  std::int32_t null_b() const { return static_cast<std::int32_t>(n + 1); }

  void resize(std::size_t new_n);
  // Reorder every column by `order` (new index i holds old index order[i]).
  void permute(const std::vector<std::int32_t>& order);
  // Nonzero unless particle i's angular velocity is exactly +0 on every axis (a -0 counts as
  // turning: its sign could reach a result). The kernels without spin terms are exact only for
  // +0 (kernels/contact_law.hpp); the pair and bond stages test this to choose them.
  std::uint64_t spin_bits(std::size_t i) const {
    return std::bit_cast<std::uint64_t>(wx[i]) | std::bit_cast<std::uint64_t>(wy[i]) |
           std::bit_cast<std::uint64_t>(wz[i]);
  }
};

}  // namespace asperity::detail
