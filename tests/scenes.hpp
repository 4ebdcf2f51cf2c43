// Small scenes and helpers shared by the engine's tests.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "asperity/world.hpp"

namespace asperity::test {

// The message of the Error that `call` throws; "(no error)" when it throws none.
inline std::string error_of(auto&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The same length and the same bits (a NaN equals itself, +0 differs from -0).
inline bool same_bits(const std::vector<double>& u, const std::vector<double>& v) {
  return u.size() == v.size() && std::memcmp(u.data(), v.data(), u.size() * sizeof(double)) == 0;
}

// Particles (a, b) of pair k of `pairs` in the random inputs of the SIMD-vs-scalar kernel tests.
// Separate: every pair has its own two particles, 2k and 2k + 1 (the a-side is gathered). Shared:
// three pairs per a, a sorted like the engine's lists, so most batches load their a-side as a
// window (engine/kernels/a_side.hpp); every fifth batch of 8 has scattered a and gathers. Shared
// uses a_particles(pairs) + pairs particles, separate 2 pairs.
inline std::size_t a_particles(std::size_t pairs) { return (pairs + 2) / 3; }
inline std::pair<std::int64_t, std::int64_t> kernel_test_pair(std::size_t k, std::size_t pairs,
                                                               bool shared) {
  if (!shared) return {std::int64_t(2 * k), std::int64_t(2 * k + 1)};
  const std::size_t m = a_particles(pairs);
  return {std::int64_t((k / 8) % 5 == 4 ? (7 * k) % m : k / 3), std::int64_t(m + k)};
}

// `n` spheres of random radius on a jittered grid (no overlaps) in a box of six planes, falling
// with random velocities, friction and rotation: a busy scene with rebuilds, slips and wall
// contacts. Gravity is scaled to the soft model (kn = 0.1 N/m) so overlaps stay small. `lift`
// raises the spheres and the lid (room for a mesh on the floor).
inline World random_box(int n, WorldSettings ws = {}, unsigned seed = 1, double lift = 0) {
  ws.gravity = {0, 0, -0.02};
  World w(ws);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const int side = 12;  // cells per row and column; layers as needed
  const double cell = 1e-3, L = side * cell;
  for (int i = 0; i < n; ++i) {
    const int cx = i % side, cy = (i / side) % side, cz = i / (side * side);
    const double r = 3e-4 + 1.5e-4 * u(rng);
    const double slack = cell / 2 - r;
    const auto id = w.add_particle({(cx + 0.5) * cell + slack * (2 * u(rng) - 1),
                                    (cy + 0.5) * cell + slack * (2 * u(rng) - 1),
                                    lift + (cz + 0.5) * cell + slack * (2 * u(rng) - 1)}, r);
    w.set_velocity(id, {2e-3 * (u(rng) - 0.5), 2e-3 * (u(rng) - 0.5), 2e-3 * (u(rng) - 0.5)});
  }
  w.add_plane({0, 0, 0}, {0, 0, 1});
  w.add_plane({0, 0, 0}, {1, 0, 0});
  w.add_plane({L, 0, 0}, {-1, 0, 0});
  w.add_plane({0, 0, 0}, {0, 1, 0});
  w.add_plane({0, L, 0}, {0, -1, 0});
  w.add_plane({0, 0, lift + 2 * L + double(n / (side * side)) * cell}, {0, 0, -1});
  return w;
}

// A still, bumpy mesh over random_box's 12 mm floor (a mould: heights 0 to 1 mm, cells x cells
// squares of two triangles each); its wall index.
inline int add_bumpy_mould(World& w, int cells) {
  const double h = 12e-3 / cells;
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      v.push_back({i * h, j * h, 0.5e-3 * (1 + std::sin(0.9 * i) * std::cos(0.7 * j))});
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const int a = j * (cells + 1) + i;
      t.push_back({a, a + 1, a + cells + 2});
      t.push_back({a, a + cells + 2, a + cells + 1});
    }
  return w.add_mesh(v, t);
}

// n x n x `layers` spheres of diameter d on a grid of pitch 0.99 d (neighbours overlap by 1 %),
// between two platens: the bottom layer a fixed group, the top one a group sheared along x at
// `velocity` under a servo holding `load` along z. `prepare(world, first_id)` runs before the
// platens are made (velocities, bonds).
struct ShearedLayers {
  World w;
  int top = -1;
};
inline ShearedLayers sheared_layers(WorldSettings ws, int n, int layers, double d, double velocity, double load,
                                    const std::function<void(World&, std::int64_t)>& prepare = {}) {
  ShearedLayers out{World(ws)};
  World& w = out.w;
  const double a = 0.99 * d;
  std::vector<double> xyz;
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (double c : {(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a}) xyz.push_back(c);
  const std::int64_t first = w.add_particles(xyz, std::vector<double>(xyz.size() / 3, 0.5 * d));
  if (prepare) prepare(w, first);
  std::vector<std::int64_t> bottom, upper;
  for (std::int64_t k = 0; k < std::int64_t(xyz.size() / 3); ++k) {
    const std::int64_t layer = k / (n * n);
    if (layer == 0) bottom.push_back(first + k);
    if (layer == layers - 1) upper.push_back(first + k);
  }
  GroupMotion held;
  held.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  w.add_group(bottom, held);
  GroupMotion shear;
  shear.translation = {Dof::velocity, Dof::fixed, Dof::servo};
  shear.velocity = {velocity, 0, 0};
  shear.servo[2].target_force = load;
  out.top = w.add_group(upper, shear);
  return out;
}

// random_box(600) settled, then bonded with a strength low enough that bonds break as it goes on
// (more of them when installed stress-free: their contacts keep rest overlaps). dt 5e-4.
inline World bonded_box(WorldSettings ws, bool stress_free) {
  ws.dt = 5e-4;
  World w = random_box(600, ws);
  w.cycle(3000);  // settle
  BondMaterial bm;
  bm.tensile_strength = 0.05;
  w.install_bonds(bm, 2e-5, {}, stress_free);
  return w;
}

}  // namespace asperity::test
