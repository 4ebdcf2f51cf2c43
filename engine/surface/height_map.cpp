// engine/surface/height_map.cpp - height maps and profiles: construction, profile extraction,
// mean plane [2-1], amplitude parameters [2-2..2-5], Abbott-Firestone curve.
//
// Design notes
// - The mean plane z = a x + b y + c is the least-squares plane [2-1]. On a complete regular grid
//   the centred coordinates x - <x>, y - <y> and 1 are orthogonal, so the 3x3 normal equations
//   are diagonal and the solution is closed form (no solver needed, and no conditioning issue for
//   large coordinates): a = sum (x - <x>) z / sum (x - <x>)^2, likewise b, c = <z> - a <x> - b <y>.
// - Moments use two passes (mean first, then central moments) with compensated sums, so a surface
//   with a large offset still gives its variance to rounding.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "asperity/error.hpp"
#include "asperity/surface.hpp"
#include "surface/numeric.hpp"
#include "surface/sampling.hpp"

namespace asperity::surface {

using detail::CompensatedSum;

HeightMap::HeightMap(int nx_, int ny_, double spacing_)
    : nx(nx_),
      ny(ny_),
      spacing(spacing_),
      height(static_cast<std::size_t>(std::max(nx_, 0)) * std::max(ny_, 0), 0.0) {
  if (nx_ < 1 || ny_ < 1) throw Error("HeightMap: nx and ny must be >= 1");
  if (!(spacing_ > 0)) throw Error("HeightMap: spacing must be positive (m)");
}

// ------------------------------------------------------------------------------------------------
// Profiles

Profile row_profile(const HeightMap& map, int row) {
  if (row < 0 || row >= map.ny)
    throw Error("row_profile: row " + std::to_string(row) + " outside [0, " +
                std::to_string(map.ny - 1) + "]");
  Profile p{map.spacing, {}};
  p.height.assign(map.height.begin() + static_cast<std::ptrdiff_t>(row) * map.nx,
                  map.height.begin() + static_cast<std::ptrdiff_t>(row + 1) * map.nx);
  return p;
}

Profile column_profile(const HeightMap& map, int column) {
  if (column < 0 || column >= map.nx)
    throw Error("column_profile: column " + std::to_string(column) + " outside [0, " +
                std::to_string(map.nx - 1) + "]");
  Profile p{map.spacing, {}};
  p.height.reserve(map.ny);
  for (int j = 0; j < map.ny; ++j) p.height.push_back(map.at(column, j));
  return p;
}

Profile line_profile(const HeightMap& map, double x0, double y0, double angle, double step) {
  for (double v : {x0, y0, angle, step})
    if (!std::isfinite(v)) throw Error("line_profile: x0, y0, angle and step must be finite");
  if (step <= 0) step = map.spacing;
  // The walk below visits every point of the line inside the map: at most its diagonal over the
  // step, which a tiny step would make endless.
  constexpr double kMaxPoints = 1e7;
  const double diagonal = std::hypot(double(map.nx), double(map.ny)) * map.spacing;
  if (!(diagonal / step <= kMaxPoints)) {
    char m[200];
    std::snprintf(m, sizeof m,
                  "line_profile: step %.6g m would give up to %.6g points (at most "
                  "1e7; the map's spacing is %.6g m)",
                  step, diagonal / step, map.spacing);
    throw Error(m);
  }
  const double gx0 = x0 / map.spacing, gy0 = y0 / map.spacing;
  const double dx = std::cos(angle) * step / map.spacing, dy = std::sin(angle) * step / map.spacing;
  if (std::isnan(detail::sample(map, gx0, gy0)))
    throw Error("line_profile: the point (x0, y0) lies outside the map");
  int k_min = 0, k_max = 0;
  while (!std::isnan(detail::sample(map, gx0 + (k_min - 1) * dx, gy0 + (k_min - 1) * dy))) --k_min;
  while (!std::isnan(detail::sample(map, gx0 + (k_max + 1) * dx, gy0 + (k_max + 1) * dy))) ++k_max;
  Profile p{step, {}};
  for (int k = k_min; k <= k_max; ++k)
    p.height.push_back(detail::sample(map, gx0 + k * dx, gy0 + k * dy));
  return p;
}

// ------------------------------------------------------------------------------------------------
// Mean plane and line [2-1]

Plane fit_mean_plane(const HeightMap& map) {
  if (map.height.empty()) throw Error("fit_mean_plane: empty map");
  const double xm = 0.5 * (map.nx - 1), ym = 0.5 * (map.ny - 1);  // in grid steps
  CompensatedSum sz, sxz, syz;
  for (int j = 0; j < map.ny; ++j)
    for (int i = 0; i < map.nx; ++i) {
      const double z = map.at(i, j);
      sz.add(z);
      sxz.add((i - xm) * z);
      syz.add((j - ym) * z);
    }
  // sum over the grid of (i - xm)^2 = ny * nx (nx^2 - 1) / 12, likewise for j.
  const double nx = map.nx, ny = map.ny;
  const double sxx = ny * nx * (nx * nx - 1) / 12.0;
  const double syy = nx * ny * (ny * ny - 1) / 12.0;
  Plane plane;
  plane.a = sxx > 0 ? sxz.value() / sxx / map.spacing : 0.0;
  plane.b = syy > 0 ? syz.value() / syy / map.spacing : 0.0;
  plane.c = sz.value() / (nx * ny) - plane.a * xm * map.spacing - plane.b * ym * map.spacing;
  return plane;
}

HeightMap remove_mean_plane(const HeightMap& map) {
  const Plane p = fit_mean_plane(map);
  HeightMap out = map;
  for (int j = 0; j < map.ny; ++j)
    for (int i = 0; i < map.nx; ++i) out.at(i, j) -= p.a * map.x(i) + p.b * map.y(j) + p.c;
  return out;
}

Line fit_mean_line(const Profile& profile) {
  const auto n = profile.height.size();
  if (n == 0) throw Error("fit_mean_line: empty profile");
  const double km = 0.5 * (static_cast<double>(n) - 1);
  CompensatedSum sz, skz;
  for (std::size_t k = 0; k < n; ++k) {
    sz.add(profile.height[k]);
    skz.add((k - km) * profile.height[k]);
  }
  const double nn = static_cast<double>(n);
  const double skk = nn * (nn * nn - 1) / 12.0;
  Line line;
  line.a = skk > 0 ? skz.value() / skk / profile.spacing : 0.0;
  line.c = sz.value() / nn - line.a * km * profile.spacing;
  return line;
}

Profile remove_mean_line(const Profile& profile) {
  const Line line = fit_mean_line(profile);
  Profile out = profile;
  for (std::size_t k = 0; k < out.height.size(); ++k)
    out.height[k] -= line.a * (k * profile.spacing) + line.c;
  return out;
}

// ------------------------------------------------------------------------------------------------
// Amplitude parameters [2-2..2-5]

AmplitudeStats amplitude_stats(std::span<const double> z) {
  AmplitudeStats st;
  st.count = z.size();
  if (z.empty()) return st;
  CompensatedSum sum;
  st.min = st.max = z[0];
  for (double v : z) {
    sum.add(v);
    st.min = std::min(st.min, v);
    st.max = std::max(st.max, v);
  }
  const double n = static_cast<double>(z.size());
  st.mean = sum.value() / n;
  CompensatedSum s1, s2, s3, s4;
  for (double v : z) {
    const double d = v - st.mean, d2 = d * d;
    s1.add(std::abs(d));
    s2.add(d2);
    s3.add(d2 * d);
    s4.add(d2 * d2);
  }
  st.ra = s1.value() / n;  // [2-2]
  st.variance = s2.value() / n;
  st.rms = std::sqrt(st.variance);  // [2-3]
  if (st.variance > 0) {            // [2-5]
    st.skewness = s3.value() / n / std::pow(st.variance, 1.5);
    st.kurtosis = s4.value() / n / (st.variance * st.variance);
  } else {
    st.skewness = st.kurtosis = std::numeric_limits<double>::quiet_NaN();
  }
  return st;
}

AmplitudeStats amplitude_stats(const HeightMap& map) { return amplitude_stats(map.height); }
AmplitudeStats amplitude_stats(const Profile& profile) { return amplitude_stats(profile.height); }

// ------------------------------------------------------------------------------------------------
// Abbott-Firestone curve

AbbottCurve abbott_curve(std::span<const double> values, int levels) {
  if (values.empty()) throw Error("abbott_curve: no values");
  if (levels < 2) throw Error("abbott_curve: levels must be >= 2");
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  const double lo = sorted.front(), hi = sorted.back();
  const double n = static_cast<double>(sorted.size());
  AbbottCurve curve;
  for (int k = 0; k < levels; ++k) {
    // The last level is the minimum itself, so the curve ends at exactly 1.
    const double level = k == levels - 1 ? lo : hi - (hi - lo) * k / (levels - 1);
    const auto below = std::lower_bound(sorted.begin(), sorted.end(), level) - sorted.begin();
    curve.height.push_back(level);
    curve.bearing_fraction.push_back((n - static_cast<double>(below)) / n);
  }
  return curve;
}

AbbottCurve abbott_curve(const HeightMap& map, int levels) {
  return abbott_curve(map.height, levels);
}

}  // namespace asperity::surface
