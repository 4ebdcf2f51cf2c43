// engine/surface/dem_surface.cpp - from a synthetic surface to a DEM surface (spec surfaces.md
// section 3, thesis 3.4.1): numerical profilometer, mean plane of the DEM surface by the modified
// Abbott curve, surface vs porosity particles [3-52..3-54], and the noise study.
//
// Design notes
// - Profilometer. Each sphere scatters its cap height zc +- sqrt(R^2 - dx^2 - dy^2) onto the
//   nodes of its disc's bounding box, keeping the highest (lower half) or lowest (upper half)
//   value per node. That is the "binned" form of the spec: the grid is the bin structure, every
//   sphere touches only the (2R/h + 1)^2 nodes around it, so the cost is O(N + nodes) for radii
//   of the order of the spacing, whatever the number of particles stacked below the surface.
//   Ties keep the first particle in input order, so the result is deterministic. Node
//   coordinates are computed as x0 + i h (not accumulated), so a sphere centred on a node gives
//   exactly zc + R there.
// - Mean plane [thesis 3.4.1]. For a shift dv, the synthetic surface has "reached" the DEM
//   surface at the nodes where z_syn + dv >= z_dem: their share is the empirical cumulative
//   distribution F(dv) of d = z_dem - z_syn (the modified Abbott curve). Particles pressed against
//   the mold make many nodes coincide with the mold surface, one value of d shared by a large
//   share of the nodes: F jumps there and dv_mp is where F is steepest, the mode of d. The mean of
//   d would not do: holes of the packing (porosity) pull it away from the surface by an amount
//   that depends on the packing, not on where the surface is.
//   The density dF/ddv is a Gaussian kernel estimate, computed on a fine bin grid (linear binning
//   and a discrete convolution: O(n + bins * kernel)); its bandwidth follows Silverman's rule,
//   h = 0.9 min(sd, IQR / 1.34) n^(-1/5) (Silverman, Density Estimation, 1986, eq. 3.31), robust
//   to the long porosity tail through the IQR. The kernel peak locates the mode globally; it is
//   then refined by the half-sample mode of the values within one bandwidth of it, the place
//   where F rises most steeply at the finest scale. The refinement matters because the
//   coinciding nodes form a spike beside a one-sided tail (caps and holes lie below the surface
//   of a lower half): the kernel estimate alone is pulled towards the tail by a fraction of the
//   bandwidth, the half-sample mode lands on the spike. "Coinciding" nodes are those within
//   `tolerance` of dv_mp, by default 1 % of the synthetic surface's rms height (7 um for S1):
//   well above contact overlaps with the mold, well below the drop of a sphere's cap one grid
//   step away from its top. (The bandwidth would be no default: when most nodes coincide to
//   rounding, the IQR and with it the bandwidth collapse to nearly zero.)
// - Surface vs porosity [3-52..3-54]. A profilometer particle is a surface particle when one of
//   its nodes lies within `band` of the DEM mean plane z_syn + dv_mp: a particle touching the
//   mold has its top there, whereas a particle seen through a hole of the packing lies deeper at
//   all its nodes. The spec's "3 standard deviations of the height" band keeps nearly everything,
//   so the band is the caller's choice and the retained fraction is reported.
// - Noise study. Noise is Gaussian (Box-Muller on the portable xoshiro256** of random.hpp, so a
//   seed gives the same noise everywhere), one field scaled per level: common random numbers make
//   the measured H and s2 vary smoothly with the level instead of jumping with each new draw. The
//   fit windows are those of the clean map: the automatic windows follow the measured correlation
//   length, which the noise shortens, and would otherwise move the estimator with the level.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "asperity/error.hpp"
#include "asperity/surface.hpp"
#include "surface/numeric.hpp"
#include "surface/random.hpp"

namespace asperity::surface {

using detail::CompensatedSum;
using detail::pi;

namespace {

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

void require_same_grid(const HeightMap& a, const HeightMap& b, const char* who) {
  if (a.nx != b.nx || a.ny != b.ny || a.height.size() != b.height.size())
    throw Error(std::string(who) + ": the DEM map is " + std::to_string(a.nx) + " x " +
                std::to_string(a.ny) + " but the synthetic one " + std::to_string(b.nx) + " x " +
                std::to_string(b.ny) + "; measure the DEM surface on the synthetic grid");
}

// Half-sample mode (Bickel and Fruehwirth, Comput. Stat. Data Anal. 50, 2006) of the sorted
// values within [lo, hi]: repeatedly keep the shortest interval holding half of the remaining
// values, down to two or three. Exact on a spike of equal values, which a kernel estimate smears
// towards the side with more mass nearby.
double half_sample_mode(std::span<const double> sorted, double lo, double hi) {
  auto first = std::lower_bound(sorted.begin(), sorted.end(), lo);
  auto last = std::upper_bound(sorted.begin(), sorted.end(), hi);
  std::size_t a = static_cast<std::size_t>(first - sorted.begin());
  std::size_t n = static_cast<std::size_t>(last - first);
  if (n == 0) return 0.5 * (lo + hi);
  while (n > 3) {
    const std::size_t half = (n + 1) / 2;
    std::size_t best = a;
    double shortest = std::numeric_limits<double>::infinity();
    for (std::size_t k = a; k + half <= a + n; ++k) {
      const double w = sorted[k + half - 1] - sorted[k];
      if (w < shortest) {
        shortest = w;
        best = k;
      }
    }
    a = best;
    n = half;
  }
  if (n == 3) {  // the closer pair; the middle value when both gaps are equal
    const double left = sorted[a + 1] - sorted[a], right = sorted[a + 2] - sorted[a + 1];
    if (left < right) return 0.5 * (sorted[a] + sorted[a + 1]);
    if (right < left) return 0.5 * (sorted[a + 1] + sorted[a + 2]);
    return sorted[a + 1];
  }
  return n == 2 ? 0.5 * (sorted[a] + sorted[a + 1]) : sorted[a];
}

double rms_about_mean(const HeightMap& map) { return std::sqrt(amplitude_stats(map).variance); }

}  // namespace

// ------------------------------------------------------------------------------------------------
// Profilometer

ProfilometerResult profilometer(std::span<const double> positions, std::span<const double> radii,
                                const ProfilometerGrid& grid, HalfSide side,
                                std::span<const std::int64_t> subset) {
  if (grid.nx < 1 || grid.ny < 1) throw Error("profilometer: the grid needs nx, ny >= 1");
  if (!(grid.spacing > 0)) throw Error("profilometer: the grid spacing must be > 0 (m)");
  if (positions.size() != 3 * radii.size())
    throw Error("profilometer: " + std::to_string(positions.size()) + " position values for " +
                std::to_string(radii.size()) + " radii; give x, y, z per particle");
  const std::size_t n = radii.size();
  const bool lower = side == HalfSide::lower;
  ProfilometerResult out;
  out.surface = HeightMap(grid.nx, grid.ny, grid.spacing);
  const double empty =
      lower ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  std::fill(out.surface.height.begin(), out.surface.height.end(), empty);
  out.particle.assign(out.surface.size(), -1);
  const double h = grid.spacing;

  auto scatter = [&](std::size_t p) {
    const double xc = positions[3 * p], yc = positions[3 * p + 1], zc = positions[3 * p + 2];
    const double r = radii[p];
    if (!(r >= 0) || !std::isfinite(xc) || !std::isfinite(yc) || !std::isfinite(zc))
      throw Error("profilometer: particle " + std::to_string(p) +
                  " has a non-finite position or a negative radius");
    // Nodes of the disc's bounding box, clipped to the grid.
    const double ilo = std::ceil((xc - r - grid.x0) / h), ihi = std::floor((xc + r - grid.x0) / h);
    const double jlo = std::ceil((yc - r - grid.y0) / h), jhi = std::floor((yc + r - grid.y0) / h);
    if (ihi < 0 || jhi < 0 || ilo > grid.nx - 1 || jlo > grid.ny - 1) return;
    const int i0 = static_cast<int>(std::max(ilo, 0.0));
    const int i1 = static_cast<int>(std::min(ihi, static_cast<double>(grid.nx - 1)));
    const int j0 = static_cast<int>(std::max(jlo, 0.0));
    const int j1 = static_cast<int>(std::min(jhi, static_cast<double>(grid.ny - 1)));
    const double r2 = r * r;
    for (int j = j0; j <= j1; ++j) {
      const double dy = grid.y0 + j * h - yc;
      for (int i = i0; i <= i1; ++i) {
        const double dx = grid.x0 + i * h - xc;
        const double q = r2 - dx * dx - dy * dy;
        if (q < 0) continue;  // outside the disc
        const double cap = std::sqrt(q);
        const double z = lower ? zc + cap : zc - cap;
        double& best = out.surface.at(i, j);
        if (lower ? z > best : z < best) {
          best = z;
          out.particle[static_cast<std::size_t>(j) * grid.nx + i] = static_cast<std::int64_t>(p);
        }
      }
    }
  };

  if (subset.empty()) {
    for (std::size_t p = 0; p < n; ++p) scatter(p);
  } else {
    for (std::int64_t p : subset) {
      if (p < 0 || static_cast<std::size_t>(p) >= n)
        throw Error("profilometer: subset index " + std::to_string(p) + " outside [0, " +
                    std::to_string(n) + ")");
      scatter(static_cast<std::size_t>(p));
    }
  }

  std::vector<std::int64_t> seen;
  for (std::size_t k = 0; k < out.surface.size(); ++k) {
    if (out.particle[k] < 0) {
      out.surface.height[k] = not_a_number;
    } else {
      ++out.covered;
      seen.push_back(out.particle[k]);
    }
  }
  std::sort(seen.begin(), seen.end());
  out.particles = static_cast<std::size_t>(std::unique(seen.begin(), seen.end()) - seen.begin());
  return out;
}

// ------------------------------------------------------------------------------------------------
// Mean plane of the DEM surface (modified Abbott curve)

DemMeanPlane dem_mean_plane(const HeightMap& dem, const HeightMap& synthetic,
                            const DemMeanPlaneOptions& options) {
  require_same_grid(dem, synthetic, "dem_mean_plane");
  if (options.levels < 2) throw Error("dem_mean_plane: levels must be >= 2");
  std::vector<double> d;
  d.reserve(dem.size());
  for (std::size_t k = 0; k < dem.size(); ++k)
    if (std::isfinite(dem.height[k]) && std::isfinite(synthetic.height[k]))
      d.push_back(dem.height[k] - synthetic.height[k]);
  if (d.size() < 2)
    throw Error(
        "dem_mean_plane: fewer than 2 nodes have a DEM height; is the profilometer "
        "grid where the particles are?");
  std::sort(d.begin(), d.end());
  const double n = static_cast<double>(d.size());

  DemMeanPlane out;
  out.points = d.size();
  CompensatedSum sum;
  for (double v : d) sum.add(v);
  out.mean_difference = sum.value() / n;
  CompensatedSum sq;
  for (double v : d) sq.add((v - out.mean_difference) * (v - out.mean_difference));
  const double sd = std::sqrt(sq.value() / n);
  auto quantile = [&](double q) {  // linear interpolation between order statistics
    const double pos = q * (n - 1);
    const std::size_t k = static_cast<std::size_t>(std::floor(pos));
    const double t = pos - k;
    return k + 1 < d.size() ? d[k] + t * (d[k + 1] - d[k]) : d[k];
  };
  const double iqr = quantile(0.75) - quantile(0.25);
  const double lo = d.front(), hi = d.back();

  double spread = std::min(sd, iqr / 1.34);
  if (!(spread > 0)) spread = sd;  // more than half the nodes share one value: use the sd
  double bw = options.bandwidth > 0 ? options.bandwidth : 0.9 * spread * std::pow(n, -0.2);
  if (!(bw > 0)) {
    // Every node has the same d: the DEM surface is the synthetic one shifted rigidly.
    out.shift = lo;
    out.bandwidth = 0.0;
    out.tolerance = options.tolerance > 0 ? options.tolerance : 0.01 * rms_about_mean(synthetic);
    out.coinciding_fraction = 1.0;
    out.dv = {lo, lo};
    out.cumulative = {1.0, 1.0};
    out.density = {not_a_number, not_a_number};
    return out;
  }
  out.bandwidth = bw;

  // Kernel density on a bin grid covering [lo - 4 bw, hi + 4 bw], bin width <= bw / 8.
  const double margin = 4.0 * bw;
  const double start = lo - margin, range = hi - lo + 2.0 * margin;
  const std::size_t max_bins = std::size_t{1} << 21;
  const std::size_t bins =
      std::min(max_bins, static_cast<std::size_t>(std::ceil(range / (bw / 8.0))) + 1);
  const double width = range / static_cast<double>(bins - 1);
  std::vector<double> counts(bins, 0.0);
  for (double v : d) {  // linear binning: each value split between its two bin centres
    const double g = (v - start) / width;
    const std::size_t k = std::min(bins - 2, static_cast<std::size_t>(std::floor(g)));
    const double t = g - static_cast<double>(k);
    counts[k] += 1.0 - t;
    counts[k + 1] += t;
  }
  const int reach = static_cast<int>(std::ceil(4.0 * bw / width));
  std::vector<double> kernel(2 * reach + 1);
  for (int m = -reach; m <= reach; ++m) {
    const double u = m * width / bw;
    kernel[m + reach] = std::exp(-0.5 * u * u) / (std::sqrt(2.0 * pi) * bw * n);
  }
  std::vector<double> density(bins, 0.0);
  for (std::size_t k = 0; k < bins; ++k) {
    if (counts[k] == 0) continue;
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(k) - reach);
    const std::ptrdiff_t b =
        std::min<std::ptrdiff_t>(bins - 1, static_cast<std::ptrdiff_t>(k) + reach);
    for (std::ptrdiff_t m = a; m <= b; ++m)
      density[m] += counts[k] * kernel[m - static_cast<std::ptrdiff_t>(k) + reach];
  }
  const std::size_t peak =
      static_cast<std::size_t>(std::max_element(density.begin(), density.end()) - density.begin());
  const double kernel_mode = start + static_cast<double>(peak) * width;
  out.shift = half_sample_mode(std::span<const double>(d), kernel_mode - bw, kernel_mode + bw);
  out.tolerance = options.tolerance > 0 ? options.tolerance : 0.01 * rms_about_mean(synthetic);
  const auto first = std::lower_bound(d.begin(), d.end(), out.shift - out.tolerance);
  const auto last = std::upper_bound(d.begin(), d.end(), out.shift + out.tolerance);
  out.coinciding_fraction = static_cast<double>(last - first) / n;

  // The curves for plots: F exactly from the sorted differences, the density interpolated.
  for (int l = 0; l < options.levels; ++l) {
    const double v = lo + (hi - lo) * l / (options.levels - 1);
    out.dv.push_back(v);
    out.cumulative.push_back(
        static_cast<double>(std::upper_bound(d.begin(), d.end(), v) - d.begin()) / n);
    const double g = (v - start) / width;
    const std::size_t k = std::min(bins - 2, static_cast<std::size_t>(std::floor(g)));
    const double t = g - static_cast<double>(k);
    out.density.push_back((1.0 - t) * density[k] + t * density[k + 1]);
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Surface vs porosity particles [3-52..3-54]

SurfaceParticles classify_surface_particles(const HeightMap& dem,
                                            std::span<const std::int64_t> node_particle,
                                            const HeightMap& synthetic, double shift, double band) {
  require_same_grid(dem, synthetic, "classify_surface_particles");
  if (node_particle.size() != dem.size())
    throw Error("classify_surface_particles: " + std::to_string(node_particle.size()) +
                " node particles for " + std::to_string(dem.size()) +
                " nodes; pass the profilometer's result");
  if (!(band >= 0) || !std::isfinite(band))
    throw Error("classify_surface_particles: band must be a finite length >= 0 (m)");
  if (!std::isfinite(shift)) throw Error("classify_surface_particles: shift must be finite");
  // (particle, within band) per covered node; a particle is "surface" if any node says so.
  std::vector<std::pair<std::int64_t, bool>> nodes;
  std::size_t within = 0;
  for (std::size_t k = 0; k < dem.size(); ++k) {
    if (node_particle[k] < 0 || !std::isfinite(dem.height[k])) continue;
    const bool in = std::abs(dem.height[k] - (synthetic.height[k] + shift)) <= band;
    within += in;
    nodes.emplace_back(node_particle[k], in);
  }
  SurfaceParticles out;
  out.band = band;
  out.shift = shift;
  if (nodes.empty()) return out;
  out.node_fraction = static_cast<double>(within) / static_cast<double>(nodes.size());
  std::sort(nodes.begin(), nodes.end());
  for (std::size_t k = 0; k < nodes.size();) {
    const std::int64_t p = nodes[k].first;
    bool in = false;
    for (; k < nodes.size() && nodes[k].first == p; ++k) in = in || nodes[k].second;
    (in ? out.surface : out.porosity).push_back(p);
  }
  out.retained_fraction = static_cast<double>(out.surface.size()) /
                          static_cast<double>(out.surface.size() + out.porosity.size());
  return out;
}

// ------------------------------------------------------------------------------------------------
// Noise study

std::vector<NoiseLevel> noise_study(const HeightMap& map, std::span<const double> levels,
                                    std::uint64_t seed, const AnalysisOptions& options) {
  for (double level : levels)
    if (!(level >= 0) || !std::isfinite(level))
      throw Error(
          "noise_study: noise levels must be finite and >= 0 (fractions of the rms "
          "height, e.g. 0.1 for 10 %)");
  AnalysisOptions o = options;
  o.directions = 1;  // the study needs the radial estimates only; skip most of the polar work
  const RoughnessSummary clean = analyze(map, o);
  // Freeze the clean map's fit windows (see the design notes).
  o.structure_fit_min_lag = clean.hurst_structure.x_min;
  o.structure_fit_max_lag = clean.hurst_structure.x_max;
  o.psd_fit_min_frequency = clean.hurst_psd.x_min;
  o.psd_fit_max_frequency = clean.hurst_psd.x_max;
  const double rms = clean.amplitude.rms;

  // One standard normal field (Box-Muller on pairs of uniforms in (0, 1]).
  std::vector<double> noise(map.size());
  detail::Xoshiro256StarStar rng(seed);
  for (std::size_t k = 0; k < noise.size(); k += 2) {
    const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    noise[k] = radius * std::cos(2.0 * pi * u2);
    if (k + 1 < noise.size()) noise[k + 1] = radius * std::sin(2.0 * pi * u2);
  }

  std::vector<NoiseLevel> out;
  for (double level : levels) {
    HeightMap noisy = map;
    for (std::size_t k = 0; k < noisy.size(); ++k) noisy.height[k] += level * rms * noise[k];
    const RoughnessSummary r = analyze(noisy, o);
    NoiseLevel l;
    l.level = level;
    l.noise_rms = level * rms;
    l.variance = r.amplitude.variance;
    l.hurst_psd = r.hurst_psd.hurst;
    l.hurst_structure = r.hurst_structure.hurst;
    l.psd_fit_r2 = r.hurst_psd.r2;
    l.structure_fit_r2 = r.hurst_structure.r2;
    l.correlation_length = r.correlation_length;
    out.push_back(l);
  }
  return out;
}

}  // namespace asperity::surface
