// engine/surface/generator.cpp - the spectral generator of self-affine surfaces [2-41..2-57].
//
// Design notes
// - Frequencies are the integers u, v in [-(n-1)/2, (n-1)/2], cycles per side length L (spec
//   section 1). The roll-off chi = 1/(2 Lc) (cycles per metre) is converted to the same unit by
//   multiplying by L, so |w| and chi are compared in cycles per side. The PSD is evaluated in
//   these units too: with an anisotropic exponent the ratio between directions of |w|^-beta(theta)
//   depends on the unit, and "cycles per side" is the one the spec defines.
// - n is odd, so the only self-conjugate frequency is (0, 0), which gets P = 0 (zero mean). There
//   is no Nyquist row or column to special-case.
// - The Fourier coefficients C(u, v) = sqrt(P) exp(i phi) have deterministic amplitudes and random
//   phases only, as the spec's [2-38..2-47] prescribe: the periodogram of a generated surface is
//   P itself, mode by mode, which is why H comes back from the PSD almost exactly.
// - Hermitian symmetry is carried by the phase field (phi(-u,-v) = -phi(u,v)) and by P being
//   even (theta and theta + pi give the same cos^2 and sin^2). FFTW's c2r transform receives the
//   half-plane u >= 0 only and produces a real array; the imaginary part is never formed.
// - Variance: the raw transform is scaled to s2 after the fact ([2-52, 2-53], Parseval gives the
//   same factor), twice, with compensated sums, so the variance is s2 to a few ulps.
#include "asperity/error.hpp"
#include "asperity/surface.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <stdexcept>

#include "surface/fft.hpp"
#include "surface/numeric.hpp"
#include "surface/random.hpp"

namespace asperity::surface {

using detail::CompensatedSum;
using detail::pi;

// ------------------------------------------------------------------------------------------------
// Parameters

SurfaceParams SurfaceParams::isotropic(double hurst, double corr_length, double variance,
                                       std::uint64_t seed, int n, double side) {
  SurfaceParams p;
  p.n = n;
  p.side = side;
  p.hurst_x = p.hurst_y = hurst;
  p.corr_length_x = p.corr_length_y = corr_length;
  p.variance = variance;
  p.seed = seed;
  return p;
}

bool SurfaceParams::is_isotropic() const {
  const double s2x = variance_x > 0 ? variance_x : variance;
  const double s2y = variance_y > 0 ? variance_y : variance;
  return hurst_x == hurst_y && corr_length_x == corr_length_y && s2x == s2y;
}

void validate(const SurfaceParams& p) {
  auto fail = [](const std::string& msg) { throw Error("surface: " + msg); };
  if (p.n < 3 || p.n % 2 == 0)
    fail("n = " + std::to_string(p.n) + " must be odd and >= 3 (e.g. 257 or 365)");
  if (!(p.side > 0) || !std::isfinite(p.side)) fail("side must be a positive length in metres");
  for (auto [name, h] : {std::pair{"hurst_x", p.hurst_x}, std::pair{"hurst_y", p.hurst_y}})
    if (!(h > 0 && h <= 1))
      fail(std::string(name) + " = " + std::to_string(h) + " must lie in (0, 1]");
  for (auto [name, lc] :
       {std::pair{"corr_length_x", p.corr_length_x}, std::pair{"corr_length_y", p.corr_length_y}})
    if (!(lc > 0) || !std::isfinite(lc))
      fail(std::string(name) + " must be a positive length in metres");
  if (!(p.variance > 0) || !std::isfinite(p.variance))
    fail("variance must be positive (m^2; e.g. 0.547e-6 for 0.547 mm^2)");
  if (p.variance_x < 0 || p.variance_y < 0 || !std::isfinite(p.variance_x) ||
      !std::isfinite(p.variance_y))
    fail("variance_x and variance_y must be >= 0 (0 means equal to variance)");
}

// Spec table 4 (thesis Table 3-2): H, Lc in cm, s2 in mm^2.
namespace {
struct ReferenceRow {
  const char* name;
  double hurst, lc_cm, s2_mm2;
};
constexpr ReferenceRow reference_rows[] = {
    {"S1", 0.75, 1.6, 0.547}, {"S2", 0.75, 1.6, 0.328}, {"S3", 0.75, 2.0, 0.547},
    {"S4", 0.75, 2.0, 0.328}, {"S5", 0.52, 1.6, 0.547}, {"S6", 0.52, 1.6, 0.328},
    {"S7", 0.52, 2.0, 0.547}, {"S8", 0.52, 2.0, 0.328},
};
}  // namespace

std::vector<std::string> reference_surface_names() {
  std::vector<std::string> names;
  for (const auto& row : reference_rows) names.emplace_back(row.name);
  return names;
}

SurfaceParams reference_surface(std::string_view name, std::uint64_t seed, int n, double side) {
  for (const auto& row : reference_rows) {
    if (name == row.name) {
      SurfaceParams p =
          SurfaceParams::isotropic(row.hurst, row.lc_cm * 1e-2, row.s2_mm2 * 1e-6, seed, n, side);
      p.name = row.name;
      return p;
    }
  }
  std::ostringstream msg;
  msg << "unknown reference surface '" << name << "'; valid names:";
  for (const auto& row : reference_rows) msg << ' ' << row.name;
  throw Error(msg.str());
}

// ------------------------------------------------------------------------------------------------
// Phase field

PhaseField::PhaseField(int n, std::uint64_t seed) : n_(n), seed_(seed) {
  if (n < 3 || n % 2 == 0)
    throw Error("PhaseField: n = " + std::to_string(n) + " must be odd and >= 3");
  const int h = (n - 1) / 2;
  phase_.assign(static_cast<std::size_t>(n) * n, 0.0);
  auto at = [&](int u, int v) -> double& {
    return phase_[static_cast<std::size_t>(v + h) * n + (u + h)];
  };
  detail::Xoshiro256StarStar rng(seed);
  // Square shells m = max(|u|, |v|) = 1, 2, ...: the draws for shell m do not depend on n, so a
  // seed keeps its large-scale shape when the grid is refined. Within a shell, the half-plane
  // representatives (v > 0, or v = 0 and u > 0) in row order; the partner gets -phi.
  for (int m = 1; m <= h; ++m) {
    for (int v = 0; v <= m; ++v) {
      for (int u = -m; u <= m; ++u) {
        if (std::max(std::abs(u), v) != m) continue;
        if (v == 0 && u <= 0) continue;
        const double phi = 2.0 * pi * rng.uniform();
        at(u, v) = phi;
        at(-u, -v) = -phi;
      }
    }
  }
}

double PhaseField::phase(int u, int v) const {
  const int h = (n_ - 1) / 2;
  if (std::abs(u) > h || std::abs(v) > h)
    throw Error("PhaseField::phase: frequency outside the grid");
  return phase_[static_cast<std::size_t>(v + h) * n_ + (u + h)];
}

// ------------------------------------------------------------------------------------------------
// PSD and generation

namespace {
// Polar radius of the ellipse with semi-axes (ax, ay) at direction (c, s) = (cos, sin) [2-48].
double ellipse(double c, double s, double ax, double ay) {
  return 1.0 / std::sqrt((c / ax) * (c / ax) + (s / ay) * (s / ay));
}
}  // namespace

double spectral_density(const SurfaceParams& p, int u, int v) {
  if (u == 0 && v == 0) return 0.0;  // zero mean
  const double w = std::hypot(static_cast<double>(u), static_cast<double>(v));
  const double c = u / w, s = v / w;
  const double hurst = ellipse(c, s, p.hurst_x, p.hurst_y);  // [2-48] H(theta)
  // [2-50] chi(theta) in cycles per metre, times L for cycles per side.
  const double chi =
      p.side * ellipse(c, s, 1.0 / (2.0 * p.corr_length_x), 1.0 / (2.0 * p.corr_length_y));
  const double beta = 2.0 * hurst + 2.0;
  // [2-47, 2-51] power law outside the roll-off, its value at |w| = chi inside (continuous).
  double psd = std::pow(std::max(w, chi), -beta);
  const double s2x = p.variance_x > 0 ? p.variance_x : p.variance;
  const double s2y = p.variance_y > 0 ? p.variance_y : p.variance;
  if (s2x != s2y) psd *= ellipse(c, s, s2x / p.variance, s2y / p.variance);  // [2-53]
  return psd;
}

HeightMap generate_surface(const SurfaceParams& params, const PhaseField& phases) {
  validate(params);
  if (phases.n() != params.n)
    throw Error("generate_surface: the phase field has n = " + std::to_string(phases.n()) +
                " but the parameters n = " + std::to_string(params.n) +
                "; build PhaseField(n, seed)");
  const int n = params.n;
  const int h = (n - 1) / 2;
  const int n_half = n / 2 + 1;  // = h + 1: u = 0..h

  // FFTW half-spectrum layout: row j holds v = j (j <= h) or j - n, column k holds u = k.
  std::vector<detail::Complex> half(static_cast<std::size_t>(n) * n_half);
  for (int j = 0; j < n; ++j) {
    const int v = j <= h ? j : j - n;
    for (int u = 0; u <= h; ++u) {
      const double amplitude = std::sqrt(spectral_density(params, u, v));
      half[static_cast<std::size_t>(j) * n_half + u] =
          std::polar(amplitude, phases.phase(u, v));  // [2-54..2-56]
    }
  }
  std::vector<double> z = detail::inverse_real_2d(n, n, half);

  // Zero mean (already zero up to rounding since P(0,0) = 0) and exact variance.
  CompensatedSum sum;
  for (double zi : z) sum.add(zi);
  const double mean = sum.value() / static_cast<double>(z.size());
  for (double& zi : z) zi -= mean;
  for (int pass = 0; pass < 2; ++pass) {
    CompensatedSum sq;
    for (double zi : z) sq.add(zi * zi);
    const double variance = sq.value() / static_cast<double>(z.size());
    const double scale = std::sqrt(params.variance / variance);
    for (double& zi : z) zi *= scale;
  }

  HeightMap map;
  map.nx = map.ny = n;
  map.spacing = params.spacing();
  map.height = std::move(z);
  map.params = params;
  map.params->seed = phases.seed();
  return map;
}

HeightMap generate_surface(const SurfaceParams& params) {
  validate(params);
  return generate_surface(params, PhaseField(params.n, params.seed));
}

}  // namespace asperity::surface
