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
  std::vector<double> density;
  std::vector<std::uint8_t> rotation_locked;
  std::vector<std::int32_t> group;  // -1: none
  std::vector<std::int32_t> tag;    // user label
  std::vector<std::uint8_t> flags;  // user bits
  std::vector<std::uint8_t> inert;  // never searched, moved lazily with its group
  std::vector<std::int64_t> id;     // stable id of the particle at this index
  std::vector<std::int64_t> index_of_id;  // stable id -> current index

  bool has_applied = false;

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
