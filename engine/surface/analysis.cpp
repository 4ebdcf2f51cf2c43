// engine/surface/analysis.cpp - roughness analysis of height maps and profiles [2-6..2-17]:
// structure function, variogram, autocovariance, PSD, Hurst exponent, correlation length, Z2/Z3,
// colatitudes, polar data.
//
// Design notes
// - Lag statistics of a map (LagMap) come from FFT correlations of the zero-padded map, exact for
//   every lattice lag d = (dx, dy) at O(N log N) cost. With pairs r, r + d both inside the map
//   (N(d) = (nx - |dx|)(ny - |dy|) of them):
//       S(d) = [sum z(r)^2 + sum z(r+d)^2 - 2 sum z(r) z(r+d)] / N(d)       [2-9]
//       R(d) = sum z(r) z(r+d) / N(d)                                      [2-6]
//   The sums are two correlations, of z with z and of z^2 with the mask of the map (read at d
//   and -d), computed with a padding of at least 2n - 1 so nothing wraps around. The result equals the direct double
//   loop over pairs to rounding, for maps that are not periodic too (measured scans).
// - Directional reads (see sampling.hpp): x, y, diagonals on the lattice; other angles bilinearly
//   interpolate S(d) between lattice lags. S is smooth in d away from the origin, whereas
//   interpolating heights would low-pass the surface and bias S (and H) at small lags.
// - Radial averages pool lattice lags in rings |d| in [k - 1/2, k + 1/2) spacings, weighted by
//   pair count, and report the pair-weighted mean |d|, which is the abscissa a power-law fit wants.
// - PSD: periodogram |Z(f)|^2 h^2 / (N <w^2>) of the mean-free map times a separable Hann window
//   w (default; a measured map is not periodic and its edges would otherwise leak a |f|^-2 ridge
//   into the spectrum), averaged over unit rings of the fundamental frequency. The ring average is
//   the less biased H estimator for gridded data (spec section 2): slope -(2 + 2H).
// - Fit windows, when not given (AnalysisOptions), follow from the measured correlation length xi
//   (the (1 - 1/e) rule below), so measured and generated maps are treated alike:
//     structure function: lags from the first step to max(xi / 4, 6 steps), "well below Lc";
//     PSD: from max(1 / (2 xi), 4 / (n h)) to 0.7 times the Nyquist frequency, 0.35 / h. For
//     generated surfaces xi ~ 0.35..0.45 Lc (S1..S8), so 1 / (2 xi) lies 2.2..2.9 times above the
//     roll-off 1 / (2 Lc); 0.7 Nyquist keeps whole rings (the corners beyond Nyquist only hold
//     the lattice's diagonal modes). Measured at n = 257 over 10 seeds with the Hann window:
//     H = 0.30, 0.50, 0.80 -> 0.300, 0.492, 0.795, scatter 0.013..0.019 per surface.
// - Correlation length rule: the smallest lag where S reaches (1 - 1/e) of its plateau 2 s2,
//   linearly interpolated between the bracketing lags (S(0) = 0 is the point before the first).
//   For S = 2 s2 (1 - exp(-tau / xi)) that is xi, to the linear interpolation's error.
// - Roll-off length: the correlation-length rule above measures where heights decorrelate, which
//   for the spec's spectrum lands at 0.35..0.45 Lc. The generator's Lc itself is a corner of the
//   PSD (chi = 1 / (2 Lc) [2-50]), so it is also estimated there: a broken power law, flat below
//   f_c and the fitted power law above, fitted in log space to the rings below the fit window.
//   Measured at n = 365 (4 seeds): Lc = 0.8, 1.6, 2.0 cm -> 0.78, 1.55..1.59, 1.87..1.91 cm;
//   Lc = 4 cm (corner at 1.25 fundamentals) -> 3.3..3.6 cm. Per direction (PSD sectors) the
//   corner rests on the few modes of the lowest rings of a sector: with the Hann window, whose
//   3-bin smear matters there, it scatters by tens of percent; a periodic (generated) map read
//   with Window::none gives it to about 20 %.
// - Window: Hann by default because measured and DEM maps are not periodic. A generated surface
//   is periodic, and without window its periodogram is the prescribed PSD mode by mode (H exact
//   to 0.002 at n = 257); after the mean-plane removal, though, the removed ramp is not periodic
//   and biases H low near 1 (0.78 for 0.80) unless a window is used.
// - Per-direction data (polar plots) describe profiles along the direction, each about its own
//   mean, as a profilometer trace would be analysed: s2(theta) is the mean variance of profiles as
//   long as the smaller side of the map, exact from S along theta (see polar()), and Lc(theta)
//   applies the rule with that s2(theta). Against the whole-map variance instead, a direction
//   across long ridges (whose heights a profile along it sees as a constant offset) would never
//   reach its plateau and get an inflated correlation length.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "asperity/error.hpp"
#include "asperity/surface.hpp"
#include "surface/fft.hpp"
#include "surface/numeric.hpp"
#include "surface/sampling.hpp"

namespace asperity::surface {

using detail::CompensatedSum;
using detail::pi;

namespace {

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

double default_max_lag(int nx, int ny, double spacing) { return 0.5 * std::min(nx, ny) * spacing; }

void require_map(const HeightMap& map, const char* who) {
  if (map.nx < 2 || map.ny < 2 || map.height.size() != static_cast<std::size_t>(map.nx) * map.ny)
    throw Error(std::string(who) + ": the map needs nx, ny >= 2 and nx * ny heights");
  if (!(map.spacing > 0)) throw Error(std::string(who) + ": spacing must be > 0");
}

void require_finite_value(double v, const char* who, const char* what) {
  if (!std::isfinite(v))
    throw Error(std::string(who) + ": " + what + " must be finite, got " + std::to_string(v));
}

// Lags (or rings) up to max_lag, as an int no larger than `cap`: converted in double first, as a
// max_lag of 1e300 cast straight to int is undefined.
int lag_count(double max_lag, double spacing, int cap) {
  const double k = std::floor(max_lag / spacing + 1e-9);
  if (!(k > 0)) return 0;
  return k >= cap ? cap : static_cast<int>(k);
}

void require_profile(const Profile& p, const char* who) {
  if (p.height.size() < 3) throw Error(std::string(who) + ": the profile needs at least 3 heights");
  if (!(p.spacing > 0)) throw Error(std::string(who) + ": spacing must be > 0");
}

double mean_of(std::span<const double> z) {
  CompensatedSum s;
  for (double v : z) s.add(v);
  return s.value() / static_cast<double>(z.size());
}

std::vector<double> hann(int n) {
  std::vector<double> w(n, 1.0);
  if (n > 1)
    for (int i = 0; i < n; ++i) w[i] = 0.5 * (1.0 - std::cos(2.0 * pi * i / (n - 1)));
  return w;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// LagMap

LagMap::LagMap(const HeightMap& map) {
  require_map(map, "LagMap");
  nx_ = map.nx;
  ny_ = map.ny;
  spacing_ = map.spacing;
  const double mean = mean_of(map.height);
  const int px = detail::fft_friendly_size(2 * nx_ - 1);
  const int py = detail::fft_friendly_size(2 * ny_ - 1);
  const std::size_t padded = static_cast<std::size_t>(px) * py;
  std::vector<double> z(padded, 0.0), z2(padded, 0.0), mask(padded, 0.0);
  CompensatedSum sq;
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const double v = map.at(i, j) - mean;
      const std::size_t k = static_cast<std::size_t>(j) * px + i;
      z[k] = v;
      z2[k] = v * v;
      mask[k] = 1.0;
      sq.add(v * v);
    }
  variance_ = sq.value() / static_cast<double>(map.size());

  // Correlation c_fg(d) = sum_r f(r) g(r + d) = IFFT(conj(F) G) / (px py).
  const auto fz = detail::forward_real_2d(py, px, z);
  const auto fz2 = detail::forward_real_2d(py, px, z2);
  const auto fm = detail::forward_real_2d(py, px, mask);
  std::vector<detail::Complex> czz(fz.size()), cz2m(fz.size());
  for (std::size_t k = 0; k < fz.size(); ++k) {
    czz[k] = std::norm(fz[k]);
    cz2m[k] = std::conj(fz2[k]) * fm[k];
  }
  const auto zz = detail::inverse_real_2d(py, px, czz);    // sum z(r) z(r+d) * px py
  const auto z2m = detail::inverse_real_2d(py, px, cz2m);  // sum over r, r+d inside of z(r)^2
  const double norm = 1.0 / static_cast<double>(padded);
  auto wrapped = [&](const std::vector<double>& c, int dx, int dy) {
    const int ix = dx >= 0 ? dx : dx + px;
    const int iy = dy >= 0 ? dy : dy + py;
    return c[static_cast<std::size_t>(iy) * px + ix] * norm;
  };

  const std::size_t width = 2 * nx_ - 1;
  structure_.assign(width * ny_, 0.0);
  covariance_.assign(width * ny_, 0.0);
  for (int dy = 0; dy < ny_; ++dy)
    for (int dx = -(nx_ - 1); dx < nx_; ++dx) {
      const double pairs = pairs_at(dx, dy);
      const double cross = wrapped(zz, dx, dy);
      // sum z(r)^2 over the pairs' first points is z2m(d); over their second points z2m(-d).
      const double squares = wrapped(z2m, dx, dy) + wrapped(z2m, -dx, -dy);
      structure_[index(dx, dy)] = std::max(0.0, (squares - 2.0 * cross) / pairs);  // [2-9]
      covariance_[index(dx, dy)] = cross / pairs;                                  // [2-6]
    }
}

std::size_t LagMap::index(int dx, int dy) const {
  if (dy < 0) {  // S(-d) = S(d), R(-d) = R(d)
    dx = -dx;
    dy = -dy;
  }
  if (std::abs(dx) >= nx_ || dy >= ny_) throw Error("LagMap: lag outside the map");
  return static_cast<std::size_t>(dy) * (2 * nx_ - 1) + (dx + nx_ - 1);
}

double LagMap::structure_at(int dx, int dy) const { return structure_[index(dx, dy)]; }
double LagMap::autocovariance_at(int dx, int dy) const { return covariance_[index(dx, dy)]; }
double LagMap::pairs_at(int dx, int dy) const {
  return static_cast<double>(nx_ - std::abs(dx)) * static_cast<double>(ny_ - std::abs(dy));
}

LagSeries LagMap::along(Quantity q, double angle, double max_lag) const {
  require_finite_value(angle, "structure_function", "angle");
  require_finite_value(max_lag, "structure_function", "max_lag");
  if (max_lag <= 0) max_lag = default_max_lag(nx_, ny_, spacing_);
  const auto& data = q == Quantity::structure ? structure_ : covariance_;
  auto step = detail::direction_step(angle);
  if (step.gy < 0 || (step.gy == 0 && step.gx < 0)) {
    step.gx = -step.gx;
    step.gy = -step.gy;
  }
  LagSeries out;
  out.angle = angle;
  for (int k = 1;; ++k) {
    const double lag = k * step.length * spacing_;
    if (lag > max_lag * (1 + 1e-12)) break;
    double gx = k * step.gx, gy = k * step.gy;
    if (detail::near_integer(gx)) gx = std::round(gx);
    if (detail::near_integer(gy)) gy = std::round(gy);
    if (std::abs(gx) > nx_ - 1 || gy > ny_ - 1) break;
    // Bilinear in the lag plane; on lattice lags the weights are 1, 0, 0, 0.
    int i0 = static_cast<int>(std::floor(gx)), j0 = static_cast<int>(std::floor(gy));
    double fx = gx - i0, fy = gy - j0;
    if (i0 == nx_ - 1) {
      --i0;
      fx = 1.0;
    }
    if (j0 == ny_ - 1) {
      --j0;
      fy = 1.0;
    }
    double value = 0.0, pairs = 0.0;
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const double w = (a ? fx : 1 - fx) * (b ? fy : 1 - fy);
        if (w == 0) continue;
        value += w * data[index(i0 + a, j0 + b)];
        pairs += w * pairs_at(i0 + a, j0 + b);
      }
    out.lag.push_back(lag);
    out.value.push_back(value);
    out.pairs.push_back(pairs);
  }
  return out;
}

LagSeries LagMap::radial(Quantity q, double max_lag) const {
  require_finite_value(max_lag, "structure_function_radial", "max_lag");
  if (max_lag <= 0) max_lag = default_max_lag(nx_, ny_, spacing_);
  const auto& data = q == Quantity::structure ? structure_ : covariance_;
  // No lag on the map is longer than nx + ny steps.
  const int rings = lag_count(max_lag, spacing_, nx_ + ny_);
  std::vector<CompensatedSum> value(rings + 1), lag(rings + 1);
  std::vector<double> pairs(rings + 1, 0.0);
  const int reach_x = std::min(rings, nx_ - 1), reach_y = std::min(rings, ny_ - 1);
  // Half plane (dy > 0, or dy = 0 and dx > 0): d and -d are the same pairs.
  for (int dy = 0; dy <= reach_y; ++dy)
    for (int dx = -reach_x; dx <= reach_x; ++dx) {
      if (dy == 0 && dx <= 0) continue;
      const double r = std::hypot(static_cast<double>(dx), static_cast<double>(dy));
      const int ring = static_cast<int>(std::floor(r + 0.5));
      if (ring < 1 || ring > rings) continue;
      const double n = pairs_at(dx, dy);
      value[ring].add(n * data[index(dx, dy)]);
      lag[ring].add(n * r);
      pairs[ring] += n;
    }
  LagSeries out;
  out.angle = not_a_number;
  for (int k = 1; k <= rings; ++k) {
    if (pairs[k] == 0) continue;
    out.lag.push_back(lag[k].value() / pairs[k] * spacing_);
    out.value.push_back(value[k].value() / pairs[k]);
    out.pairs.push_back(pairs[k]);
  }
  return out;
}

LagSeries LagMap::structure_function(double angle, double max_lag) const {
  return along(Quantity::structure, angle, max_lag);
}
LagSeries LagMap::structure_function_radial(double max_lag) const {
  return radial(Quantity::structure, max_lag);
}
LagSeries LagMap::autocovariance(double angle, double max_lag) const {
  return along(Quantity::autocovariance, angle, max_lag);
}
LagSeries LagMap::autocovariance_radial(double max_lag) const {
  return radial(Quantity::autocovariance, max_lag);
}

LagSeries structure_function(const HeightMap& map, double angle, double max_lag) {
  return LagMap(map).structure_function(angle, max_lag);
}
LagSeries structure_function_radial(const HeightMap& map, double max_lag) {
  return LagMap(map).structure_function_radial(max_lag);
}
LagSeries autocovariance(const HeightMap& map, double angle, double max_lag) {
  return LagMap(map).autocovariance(angle, max_lag);
}
LagSeries autocovariance_radial(const HeightMap& map, double max_lag) {
  return LagMap(map).autocovariance_radial(max_lag);
}

// Profiles: a direct O(n * lags) double loop is cheap in 1-D.
namespace {
LagSeries profile_lags(const Profile& p, double max_lag, bool structure) {
  require_profile(p, structure ? "structure_function" : "autocovariance");
  const int n = static_cast<int>(p.height.size());
  require_finite_value(max_lag, structure ? "structure_function" : "autocovariance", "max_lag");
  if (max_lag <= 0) max_lag = 0.5 * n * p.spacing;
  const int lags = lag_count(max_lag, p.spacing, n - 1);
  const double mean = mean_of(p.height);
  LagSeries out;
  out.angle = not_a_number;
  for (int k = 1; k <= lags; ++k) {
    CompensatedSum s;
    for (int i = 0; i + k < n; ++i) {
      const double a = p.height[i], b = p.height[i + k];
      s.add(structure ? (b - a) * (b - a) : (a - mean) * (b - mean));
    }
    out.lag.push_back(k * p.spacing);
    out.value.push_back(s.value() / (n - k));
    out.pairs.push_back(n - k);
  }
  return out;
}
}  // namespace

LagSeries structure_function(const Profile& profile, double max_lag) {
  return profile_lags(profile, max_lag, true);
}
LagSeries autocovariance(const Profile& profile, double max_lag) {
  return profile_lags(profile, max_lag, false);
}

LagSeries variogram(const LagSeries& s) {
  LagSeries g = s;
  for (double& v : g.value) v *= 0.5;
  return g;
}

// ------------------------------------------------------------------------------------------------
// Power spectral density

namespace {

// Periodogram on FFTW's half plane: ny rows (v), nx / 2 + 1 columns (u >= 0).
struct Periodogram {
  int nx = 0, ny = 0;
  double dfx = 0, dfy = 0;    // fundamental frequencies 1 / (n h)
  std::vector<double> power;  // m^4
};

Periodogram periodogram(const HeightMap& map, Window window) {
  require_map(map, "psd");
  const int nx = map.nx, ny = map.ny;
  const double mean = mean_of(map.height);
  std::vector<double> z(map.size());
  std::vector<double> wx(nx, 1.0), wy(ny, 1.0);
  if (window == Window::hann) {
    wx = hann(nx);
    wy = hann(ny);
  }
  CompensatedSum w2;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double w = wx[i] * wy[j];
      z[static_cast<std::size_t>(j) * nx + i] = (map.at(i, j) - mean) * w;
      w2.add(w * w);
    }
  const double n = static_cast<double>(map.size());
  const double mean_w2 = w2.value() / n;  // power lost to the window, given back below
  const auto fz = detail::forward_real_2d(ny, nx, z);
  Periodogram pg;
  pg.nx = nx;
  pg.ny = ny;
  pg.dfx = 1.0 / (nx * map.spacing);
  pg.dfy = 1.0 / (ny * map.spacing);
  pg.power.resize(fz.size());
  // Parseval: variance = sum_f P(f) dfx dfy with P = |Z|^2 h^2 / N.
  const double scale = map.spacing * map.spacing / (n * mean_w2);
  for (std::size_t k = 0; k < fz.size(); ++k) pg.power[k] = std::norm(fz[k]) * scale;
  return pg;
}

// Ring average; with half_width >= 0 only wave vectors within half_width of `angle` (mod pi).
Spectrum ring_average(const Periodogram& pg, double angle, double half_width) {
  const int cols = pg.nx / 2 + 1;
  const double df = std::max(pg.dfx, pg.dfy);
  const int rings = static_cast<int>(std::ceil(std::hypot(pg.nx * pg.dfx, pg.ny * pg.dfy) / df));
  std::vector<double> sum_p(rings + 1, 0.0), sum_f(rings + 1, 0.0), count(rings + 1, 0.0);
  for (int j = 0; j < pg.ny; ++j) {
    const int v = j <= pg.ny / 2 ? j : j - pg.ny;
    for (int u = 0; u < cols; ++u) {
      // Columns 0 < u < nx - u stand for (u, v) and (-u, -v): count them twice.
      const double mult = (u == 0 || 2 * u == pg.nx) ? 1.0 : 2.0;
      const double fx = u * pg.dfx, fy = v * pg.dfy;
      const double f = std::hypot(fx, fy);
      const int ring = static_cast<int>(std::floor(f / df + 0.5));
      if (ring < 1 || ring > rings) continue;
      if (half_width >= 0) {
        const double off = std::abs(std::remainder(std::atan2(fy, fx) - angle, pi));
        if (off > half_width) continue;
      }
      const double p = pg.power[static_cast<std::size_t>(j) * cols + u];
      sum_p[ring] += mult * p;
      sum_f[ring] += mult * f;
      count[ring] += mult;
    }
  }
  Spectrum s;
  for (int k = 1; k <= rings; ++k) {
    if (count[k] == 0) continue;
    s.frequency.push_back(sum_f[k] / count[k]);
    s.psd.push_back(sum_p[k] / count[k]);
    s.count.push_back(count[k]);
  }
  return s;
}

}  // namespace

Spectrum radial_psd(const HeightMap& map, Window window) {
  return ring_average(periodogram(map, window), 0.0, -1.0);
}

Spectrum sector_psd(const HeightMap& map, double angle, double half_width, Window window) {
  if (!(half_width > 0)) throw Error("sector_psd: half_width must be > 0 (rad)");
  return ring_average(periodogram(map, window), angle, half_width);
}

Spectrum profile_psd(const Profile& profile, Window window) {
  require_profile(profile, "profile_psd");
  const int n = static_cast<int>(profile.height.size());
  const double mean = mean_of(profile.height);
  const std::vector<double> w = window == Window::hann ? hann(n) : std::vector<double>(n, 1.0);
  std::vector<double> z(n);
  CompensatedSum w2;
  for (int i = 0; i < n; ++i) {
    z[i] = (profile.height[i] - mean) * w[i];
    w2.add(w[i] * w[i]);
  }
  const auto fz = detail::forward_real_1d(z);
  const double scale = profile.spacing / (n * (w2.value() / n));  // |Z|^2 h / N, window-corrected
  Spectrum s;
  for (int k = 1; k < static_cast<int>(fz.size()); ++k) {
    const double fold = 2 * k == n ? 1.0 : 2.0;  // f and -f together, except at Nyquist
    s.frequency.push_back(k / (n * profile.spacing));
    s.psd.push_back(fold * std::norm(fz[k]) * scale);
    s.count.push_back(fold);
  }
  return s;
}

// ------------------------------------------------------------------------------------------------
// Fits

PowerLawFit fit_power_law(std::span<const double> x, std::span<const double> y, double x_min,
                          double x_max) {
  PowerLawFit fit;
  fit.x_min = x_min;
  fit.x_max = x_max;
  fit.hurst = fit.slope = fit.intercept = fit.r2 = not_a_number;
  std::vector<double> lx, ly;
  for (std::size_t k = 0; k < std::min(x.size(), y.size()); ++k)
    if (x[k] >= x_min * (1 - 1e-12) && x[k] <= x_max * (1 + 1e-12) && x[k] > 0 && y[k] > 0 &&
        std::isfinite(y[k])) {
      lx.push_back(std::log(x[k]));
      ly.push_back(std::log(y[k]));
    }
  fit.points = static_cast<int>(lx.size());
  if (fit.points < 3) {
    fit.points = 0;
    return fit;
  }
  const double n = fit.points;
  double mx = 0, my = 0;
  for (int k = 0; k < fit.points; ++k) {
    mx += lx[k];
    my += ly[k];
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0, syy = 0;
  for (int k = 0; k < fit.points; ++k) {
    sxx += (lx[k] - mx) * (lx[k] - mx);
    sxy += (lx[k] - mx) * (ly[k] - my);
    syy += (ly[k] - my) * (ly[k] - my);
  }
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  fit.r2 = syy > 0 ? sxy * sxy / (sxx * syy) : 1.0;
  return fit;
}

PowerLawFit hurst_from_structure(const LagSeries& s, double min_lag, double max_lag) {
  PowerLawFit fit = fit_power_law(s.lag, s.value, min_lag, max_lag);
  fit.hurst = fit.slope / 2.0;  // [2-12] S ~ tau^(2H)
  return fit;
}

PowerLawFit hurst_from_psd(const Spectrum& s, int dimension, double min_f, double max_f) {
  if (dimension != 1 && dimension != 2)
    throw Error("hurst_from_psd: dimension must be 1 (profile) or 2 (map)");
  PowerLawFit fit = fit_power_law(s.frequency, s.psd, min_f, max_f);
  fit.hurst = (-fit.slope - dimension) / 2.0;  // P ~ f^-(d + 2H)
  return fit;
}

double correlation_length(const LagSeries& s, double variance) {
  const double target = (1.0 - std::exp(-1.0)) * 2.0 * variance;
  double prev_lag = 0.0, prev_value = 0.0;  // S(0) = 0
  for (std::size_t k = 0; k < s.lag.size(); ++k) {
    if (s.value[k] >= target) {
      const double t = (target - prev_value) / (s.value[k] - prev_value);
      return prev_lag + t * (s.lag[k] - prev_lag);
    }
    prev_lag = s.lag[k];
    prev_value = s.value[k];
  }
  return not_a_number;
}

double rolloff_length(const Spectrum& s, const PowerLawFit& fit) {
  if (fit.points == 0 || s.frequency.empty() || !(fit.x_min > s.frequency.front()))
    return not_a_number;
  // Broken power law: log P = intercept + slope log max(f, f_c). Scan f_c on a fixed log grid
  // (step 1 %) from half the first ring to the fit window and keep the least-squares corner.
  double best = not_a_number, best_error = std::numeric_limits<double>::infinity();
  const double lo = std::log(0.5 * s.frequency.front()), hi = std::log(fit.x_min);
  for (int step = 0; lo + 0.01 * step <= hi; ++step) {
    const double corner = std::exp(lo + 0.01 * step);
    double error = 0.0;
    for (std::size_t k = 0; k < s.frequency.size() && s.frequency[k] < fit.x_min; ++k) {
      if (!(s.psd[k] > 0)) continue;
      const double model = fit.intercept + fit.slope * std::log(std::max(s.frequency[k], corner));
      const double r = std::log(s.psd[k]) - model;
      error += r * r;
    }
    if (error < best_error) {
      best_error = error;
      best = corner;
    }
  }
  return 1.0 / (2.0 * best);  // chi = 1 / (2 Lc) [2-50]
}

// ------------------------------------------------------------------------------------------------
// Z2, Z3 [2-13, 2-14] and colatitudes [2-17]

SlopeSeries slope_statistics(const HeightMap& map, double angle, int max_steps) {
  require_map(map, "slope_statistics");
  require_finite_value(angle, "slope_statistics", "angle");
  const auto dir = detail::direction_step(angle);
  SlopeSeries out;
  out.angle = angle;
  for (int k = 1; k <= max_steps; ++k) {
    const double gx = k * dir.gx, gy = k * dir.gy, tau = k * dir.length * map.spacing;
    CompensatedSum s1, s2;
    std::size_t n1 = 0, n2 = 0;
    for (int j = 0; j < map.ny; ++j)
      for (int i = 0; i < map.nx; ++i) {
        const double z0 = map.at(i, j);
        const double zp = detail::sample(map, i + gx, j + gy);
        if (std::isnan(zp)) continue;
        s1.add((zp - z0) * (zp - z0));
        ++n1;
        const double zm = detail::sample(map, i - gx, j - gy);
        if (std::isnan(zm)) continue;
        const double curvature = zp - 2.0 * z0 + zm;
        s2.add(curvature * curvature);
        ++n2;
      }
    if (n2 == 0) break;
    out.step.push_back(tau);
    out.z2.push_back(std::sqrt(s1.value() / n1) / tau);
    out.z3.push_back(std::sqrt(s2.value() / n2) / (tau * tau));
  }
  return out;
}

SlopeSeries slope_statistics(const Profile& p, int max_steps) {
  require_profile(p, "slope_statistics");
  const int n = static_cast<int>(p.height.size());
  SlopeSeries out;
  out.angle = not_a_number;
  for (int k = 1; k <= max_steps && 2 * k < n; ++k) {
    const double tau = k * p.spacing;
    CompensatedSum s1, s2;
    for (int i = 0; i + k < n; ++i) {
      const double d = p.height[i + k] - p.height[i];
      s1.add(d * d);
    }
    for (int i = k; i + k < n; ++i) {
      const double c = p.height[i + k] - 2.0 * p.height[i] + p.height[i - k];
      s2.add(c * c);
    }
    out.step.push_back(tau);
    out.z2.push_back(std::sqrt(s1.value() / (n - k)) / tau);
    out.z3.push_back(std::sqrt(s2.value() / (n - 2 * k)) / (tau * tau));
  }
  return out;
}

namespace {

class ColatitudeHistogram {
 public:
  ColatitudeHistogram(double step, int bins) : step_(step), bins_(bins) {
    if (bins < 1) throw Error("colatitude_distribution: bins must be >= 1");
    out_.step = step;
    out_.positive.assign(bins, 0.0);
    out_.negative.assign(bins, 0.0);
    for (int b = 0; b <= bins; ++b) out_.bin_edges.push_back(0.5 * pi * b / bins);
  }
  void add(double dz) {
    // A node without a height (NaN: a profilometer's uncovered node) has no colatitude.
    if (!std::isfinite(dz)) return;
    const double theta = std::atan(dz / step_);  // [2-17]
    ++out_.samples;
    if (theta == 0) return;  // a flat step faces neither way
    const double mag = std::abs(theta);
    const int bin = std::min(bins_ - 1, static_cast<int>(mag / (0.5 * pi) * bins_));
    if (theta > 0) {
      out_.positive[bin] += 1;
      sum_pos_.add(mag);
      ++n_pos_;
      out_.max_positive = std::max(out_.max_positive, mag);
    } else {
      out_.negative[bin] += 1;
      sum_neg_.add(mag);
      ++n_neg_;
      out_.max_negative = std::max(out_.max_negative, mag);
    }
  }
  ColatitudeDistribution finish(double angle) {
    out_.angle = angle;
    const double n = static_cast<double>(out_.samples);
    if (n > 0) {
      for (auto& c : out_.positive) c /= n;
      for (auto& c : out_.negative) c /= n;
      out_.fraction_positive = n_pos_ / n;
    }
    out_.mean_positive = n_pos_ ? sum_pos_.value() / n_pos_ : 0.0;
    out_.mean_negative = n_neg_ ? sum_neg_.value() / n_neg_ : 0.0;
    return out_;
  }

 private:
  double step_;
  int bins_;
  ColatitudeDistribution out_;
  CompensatedSum sum_pos_, sum_neg_;
  std::size_t n_pos_ = 0, n_neg_ = 0;
};

}  // namespace

ColatitudeDistribution colatitude_distribution(const HeightMap& map, double angle, double step,
                                               int bins) {
  require_map(map, "colatitude_distribution");
  require_finite_value(angle, "colatitude_distribution", "angle");
  require_finite_value(step, "colatitude_distribution", "step");
  const auto dir = detail::direction_step(angle);
  if (step <= 0) step = dir.length * map.spacing;  // one lattice step on x, y, diagonals
  const double gx = std::cos(angle) * step / map.spacing;
  const double gy = std::sin(angle) * step / map.spacing;
  ColatitudeHistogram hist(step, bins);
  for (int j = 0; j < map.ny; ++j)
    for (int i = 0; i < map.nx; ++i) {
      const double zp = detail::sample(map, i + gx, j + gy);
      if (!std::isnan(zp)) hist.add(zp - map.at(i, j));
    }
  return hist.finish(angle);
}

ColatitudeDistribution colatitude_distribution(const Profile& p, double step, int bins) {
  require_profile(p, "colatitude_distribution");
  const int k = step <= 0 ? 1 : static_cast<int>(std::lround(step / p.spacing));
  if (k < 1 || !detail::near_integer(step <= 0 ? 1.0 : step / p.spacing, 1e-6))
    throw Error("colatitude_distribution: a profile step must be a multiple of its spacing");
  ColatitudeHistogram hist(k * p.spacing, bins);
  for (std::size_t i = 0; i + k < p.height.size(); ++i) hist.add(p.height[i + k] - p.height[i]);
  return hist.finish(not_a_number);
}

// ------------------------------------------------------------------------------------------------
// Automatic fit windows, polar data and the one-call analyses

namespace {

struct FitWindows {
  double lag_min, lag_max, f_min, f_max;
};

// See the design notes at the top of the file.
FitWindows fit_windows(const AnalysisOptions& o, double xi, double first_lag, double max_lag,
                       double spacing, int n) {
  FitWindows w;
  w.lag_min = o.structure_fit_min_lag > 0 ? o.structure_fit_min_lag : first_lag;
  const double reach = std::isfinite(xi) ? xi / 4.0 : max_lag / 4.0;
  w.lag_max =
      o.structure_fit_max_lag > 0 ? o.structure_fit_max_lag : std::max(reach, 6.0 * first_lag);
  const double fundamental = 1.0 / (n * spacing);
  const double above_rolloff = std::isfinite(xi) ? 0.5 / xi : 0.0;
  w.f_min = o.psd_fit_min_frequency > 0 ? o.psd_fit_min_frequency
                                        : std::max(above_rolloff, 4.0 * fundamental);
  w.f_max = o.psd_fit_max_frequency > 0 ? o.psd_fit_max_frequency : 0.35 / spacing;
  return w;
}

std::vector<DirectionalRoughness> polar(const LagMap& lags, const Periodogram& pg,
                                        const HeightMap& map, const AnalysisOptions& o) {
  if (o.directions < 1) throw Error("polar_roughness: directions must be >= 1");
  const double max_lag = o.max_lag > 0 ? o.max_lag : default_max_lag(map.nx, map.ny, map.spacing);
  // Sectors of at least +-22.5 degrees: narrower ones hold too few modes in the low rings, and the
  // sector H scattered by +-0.1 (roll-off length by a factor 2) at n = 257 with +-7.5 degrees.
  const double half_width =
      o.sector_half_width > 0 ? o.sector_half_width : std::max(pi / (2 * o.directions), pi / 8);
  const int side = std::min(map.nx, map.ny);
  std::vector<DirectionalRoughness> out;
  for (int d = 0; d < o.directions; ++d) {
    DirectionalRoughness r;
    r.angle = pi * d / o.directions;
    // Profiles of the smaller side's length along the direction: m samples one natural step
    // apart; S is needed up to m - 1 steps for their variance.
    const auto dir = detail::direction_step(r.angle);
    const int m = std::max(2, static_cast<int>(std::floor(side / dir.length + 1e-9)));
    const LagSeries s = lags.structure_function(r.angle, (m - 1) * dir.length * map.spacing);
    // Mean variance of those profiles, each about its own mean: for m samples,
    // var = (1/m^2) sum_{k=1}^{m-1} (m - k) S(k steps) (sum of squared differences of all pairs).
    CompensatedSum var;
    for (std::size_t k = 0; k < s.lag.size() && static_cast<int>(k) + 1 < m; ++k)
      var.add((m - 1.0 - static_cast<double>(k)) * s.value[k]);
    r.variance = var.value() / (static_cast<double>(m) * m);
    r.correlation_length = correlation_length(s, r.variance);
    const double first = s.lag.empty() ? map.spacing : s.lag.front();
    const auto win = fit_windows(o, r.correlation_length, first, max_lag, map.spacing, side);
    r.hurst_structure = hurst_from_structure(s, win.lag_min, win.lag_max).hurst;
    const Spectrum sector = ring_average(pg, r.angle, half_width);
    const PowerLawFit psd_fit = hurst_from_psd(sector, 2, win.f_min, win.f_max);
    r.hurst_psd = psd_fit.hurst;
    r.rolloff_length = rolloff_length(sector, psd_fit);
    out.push_back(r);
  }
  return out;
}

}  // namespace

std::vector<DirectionalRoughness> polar_roughness(const HeightMap& map, const AnalysisOptions& o) {
  return polar(LagMap(map), periodogram(map, o.window), map, o);
}

RoughnessSummary analyze(const HeightMap& input, const AnalysisOptions& o) {
  require_map(input, "analyze");
  RoughnessSummary r;
  HeightMap map = input;
  if (o.remove_mean_plane) {
    r.mean_plane = fit_mean_plane(input);
    map = remove_mean_plane(input);
  }
  r.amplitude = amplitude_stats(map);
  const double max_lag = o.max_lag > 0 ? o.max_lag : default_max_lag(map.nx, map.ny, map.spacing);
  const LagMap lags(map);
  r.structure_radial = lags.structure_function_radial(max_lag);
  r.structure_x = lags.structure_function(0.0, max_lag);
  r.structure_y = lags.structure_function(0.5 * pi, max_lag);
  r.correlation_length = correlation_length(r.structure_radial, lags.variance());
  const double first =
      r.structure_radial.lag.empty() ? map.spacing : r.structure_radial.lag.front();
  const auto win =
      fit_windows(o, r.correlation_length, first, max_lag, map.spacing, std::min(map.nx, map.ny));
  r.hurst_structure = hurst_from_structure(r.structure_radial, win.lag_min, win.lag_max);
  const Periodogram pg = periodogram(map, o.window);
  r.psd_radial = ring_average(pg, 0.0, -1.0);
  r.hurst_psd = hurst_from_psd(r.psd_radial, 2, win.f_min, win.f_max);
  r.rolloff_length = rolloff_length(r.psd_radial, r.hurst_psd);
  r.abbott = abbott_curve(map, o.abbott_levels);
  r.polar = polar(lags, pg, map, o);
  return r;
}

ProfileSummary analyze(const Profile& input, const AnalysisOptions& o) {
  require_profile(input, "analyze");
  ProfileSummary r;
  Profile p = input;
  if (o.remove_mean_plane) {
    r.mean_line = fit_mean_line(input);
    p = remove_mean_line(input);
  }
  r.amplitude = amplitude_stats(p);
  const int n = static_cast<int>(p.height.size());
  const double max_lag = o.max_lag > 0 ? o.max_lag : 0.5 * n * p.spacing;
  r.structure = structure_function(p, max_lag);
  r.correlation_length = correlation_length(r.structure, r.amplitude.variance);
  const auto win = fit_windows(o, r.correlation_length, p.spacing, max_lag, p.spacing, n);
  r.hurst_structure = hurst_from_structure(r.structure, win.lag_min, win.lag_max);
  r.psd = profile_psd(p, o.window);
  r.hurst_psd = hurst_from_psd(r.psd, 1, win.f_min, win.f_max);
  r.rolloff_length = rolloff_length(r.psd, r.hurst_psd);
  return r;
}

}  // namespace asperity::surface
