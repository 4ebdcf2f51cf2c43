// engine/surface/sampling.hpp - reading a height map off the grid nodes, and the lag steps of a
// direction.
//
// Design notes
// - Directions along x, y and the two diagonals are read on the lattice exactly: their natural
//   step is one lattice vector (1,0), (0,1), (1,1) or (1,-1), i.e. spacing or spacing * sqrt(2).
//   Any other direction steps by one spacing along the direction and interpolates bilinearly.
// - Bilinear interpolation is exact at the nodes. Displacements within 1e-9 grid steps of a node
//   are snapped to it, so cos(pi/2) = 6e-17 does not turn an exact read into an interpolated one.
// - Interpolating heights averages four nodes and smooths the surface at the grid scale: a
//   structure function or slope read that way is biased low at lags of a few steps. Quantities
//   that allow it (the structure function, the autocovariance) therefore interpolate the lag
//   statistics instead (see LagMap); slopes and colatitudes off the lattice directions carry
//   this bias, which is why polar plots should prefer multiples of 45 degrees for them.
#pragma once

#include <cmath>
#include <numbers>

#include "asperity/surface.hpp"
#include "surface/numeric.hpp"

namespace asperity::surface::detail {

// Unit displacement of a direction in grid steps, and its length (in grid steps).
struct DirectionStep {
  double gx = 1.0, gy = 0.0;  // grid steps per natural step
  double length = 1.0;        // |(gx, gy)|: the natural step in spacings
  bool lattice = true;        // true for x, y and diagonals (exact reads)
};

inline DirectionStep direction_step(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  // Multiples of 45 degrees: angle / (pi/4) is an integer.
  if (near_integer(angle / (std::numbers::pi / 4.0), 1e-9)) {
    const double gx = std::round(c * std::numbers::sqrt2) == 0 ? 0.0 : (c > 0 ? 1.0 : -1.0);
    const double gy = std::round(s * std::numbers::sqrt2) == 0 ? 0.0 : (s > 0 ? 1.0 : -1.0);
    return {gx, gy, std::hypot(gx, gy), true};
  }
  return {c, s, 1.0, false};
}

// Height at grid coordinates (gx, gy) (in steps from node (0, 0)); NaN outside the grid.
inline double sample(const HeightMap& map, double gx, double gy) {
  if (near_integer(gx)) gx = std::round(gx);
  if (near_integer(gy)) gy = std::round(gy);
  // Written so that NaN (from a non-finite spacing or step) is outside too.
  if (!(gx >= 0 && gy >= 0 && gx <= map.nx - 1 && gy <= map.ny - 1)) return std::nan("");
  int i = static_cast<int>(std::floor(gx));
  int j = static_cast<int>(std::floor(gy));
  double fx = gx - i, fy = gy - j;
  if (fx == 0 && fy == 0) return map.at(i, j);
  if (i == map.nx - 1 && i > 0) {
    --i;
    fx = 1.0;
  }
  if (j == map.ny - 1 && j > 0) {
    --j;
    fy = 1.0;
  }
  // A map one node wide has no neighbour along that axis (and there fx or fy is 0).
  const int i1 = map.nx > 1 ? i + 1 : i, j1 = map.ny > 1 ? j + 1 : j;
  const double z00 = map.at(i, j), z10 = map.at(i1, j);
  const double z01 = map.at(i, j1), z11 = map.at(i1, j1);
  return (1 - fy) * ((1 - fx) * z00 + fx * z10) + fy * ((1 - fx) * z01 + fx * z11);
}

}  // namespace asperity::surface::detail
