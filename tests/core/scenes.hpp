// Small scenes shared by the core tests.
#pragma once
#include <random>

#include "asperity/world.hpp"

namespace asperity::test {

// `n` spheres of random radius on a jittered grid (no overlaps) in a box of six planes, falling
// with random velocities, friction and rotation: a busy scene with rebuilds, slips and wall
// contacts. Gravity is scaled to the soft model (kn = 0.1 N/m) so overlaps stay small.
inline World random_box(int n, WorldSettings ws = {}, unsigned seed = 1) {
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
                                    (cz + 0.5) * cell + slack * (2 * u(rng) - 1)}, r);
    w.set_velocity(id, {2e-3 * (u(rng) - 0.5), 2e-3 * (u(rng) - 0.5), 2e-3 * (u(rng) - 0.5)});
  }
  w.add_plane({0, 0, 0}, {0, 0, 1});
  w.add_plane({0, 0, 0}, {1, 0, 0});
  w.add_plane({L, 0, 0}, {-1, 0, 0});
  w.add_plane({0, 0, 0}, {0, 1, 0});
  w.add_plane({0, L, 0}, {0, -1, 0});
  w.add_plane({0, 0, 2 * L + double(n / (side * side)) * cell}, {0, 0, -1});
  return w;
}

}  // namespace asperity::test
