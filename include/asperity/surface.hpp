// asperity/surface.hpp - self-affine rough surfaces: spectral generator, height maps, roughness
// analysis and height-map files. Specification: docs/surfaces.md sections 1, 2 and 4.
//
// Design notes
// - Plain data in, plain data out: every result is a struct of doubles and std::vector<double>,
//   so the Lua binding can push it as a table field by field. No FFTW, Eigen or HDF5 type appears
//   here; the implementation lives in engine/surface/.
// - Units are SI throughout: metres, m^2 for variances, cycles per metre for frequencies, radians
//   for every angle (directions and colatitudes). The reference table of the spec (cm, mm^2) is
//   converted once, in reference_surface().
// - Grid convention: height[j * nx + i] is the height at x = i * spacing, y = j * spacing
//   (row = y index, column = x index), as in the HDF5 dataset `height`.
// - A generated surface is periodic with period `side` (the spectral method makes it so), hence
//   spacing = side / n and the n grid points cover [0, side) in each direction. The frequency
//   integers u, v of the spec are cycles per side length.
// - Directions: angle 0 is +x, pi/2 is +y. A direction and its opposite give the same statistics
//   for symmetric quantities (structure function, H); the colatitude distribution distinguishes
//   them (a positive slope along +x is a negative one along -x).
// - Analysis functions take heights as they are; analyze() removes the least-squares mean plane
//   first (spec section 2: "removed before anything else"). Call remove_mean_plane() yourself
//   before the individual functions when you want the same.
// - Errors at this boundary (bad parameters, unreadable files, indices out of range) throw
//   asperity::Error (asperity/error.hpp) with a message saying what was wrong and what to do.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace asperity::surface {

// ------------------------------------------------------------------------------------------------
// Generation parameters [2-41..2-57]

struct SurfaceParams {
  int n = 365;            // grid points per side; odd so that only u = v = 0 is self-conjugate
  double side = 0.10;     // L (m): side length and period of the surface
  double hurst_x = 0.75;  // Hx: roughness exponent of profiles along x (0 < H <= 1)
  double hurst_y = 0.75;  // Hy
  double corr_length_x = 0.016;  // Lcx (m): self-affine correlation length, roll-off chi = 1/(2 Lc)
  double corr_length_y = 0.016;  // Lcy (m)
  double variance = 0.547e-6;    // s2 (m^2): the height variance, exact by construction
  double variance_x = 0.0;  // s2x (m^2): anisotropic spectral weight along x; 0 = equal to variance
  double variance_y = 0.0;  // s2y (m^2); 0 = equal to variance
  std::uint64_t seed = 1;   // seed of the phase field
  std::string name;         // "S1".."S8" for the reference surfaces, free text otherwise

  // Isotropic parameters in SI units.
  static SurfaceParams isotropic(double hurst, double corr_length, double variance,
                                 std::uint64_t seed = 1, int n = 365, double side = 0.10);

  bool is_isotropic() const;
  double spacing() const { return side / n; }
};

// Throws asperity::Error naming the offending field when the parameters cannot be used.
void validate(const SurfaceParams& params);

// The eight reference surfaces of spec table 4 (thesis Table 3-2), "S1".."S8", converted to SI
// (Lc in m, s2 in m^2). An unknown name throws asperity::Error listing the valid names.
SurfaceParams reference_surface(std::string_view name, std::uint64_t seed = 1, int n = 365,
                                double side = 0.10);
std::vector<std::string> reference_surface_names();

// ------------------------------------------------------------------------------------------------
// Phase field: the random phases phi(u, v) ~ U(0, 2 pi) of one seed, with phi(-u, -v) = -phi(u, v)
// (Hermitian symmetry [2-38, 2-39]). Built once and reused for any parameter set of the same n, so
// surfaces of different H, Lc, s2 share their hills and holes (S1..S8).
//
// The phases are drawn in square shells of increasing max(|u|, |v|) (see generator.cpp), so the
// low-frequency phases of a seed do not depend on n: the same seed at n = 257 and n = 365 gives the
// same large-scale shape. The generator is xoshiro256** seeded by splitmix64, written out in
// engine/surface/random.hpp, so the phases are identical on every platform and library version.
class PhaseField {
 public:
  PhaseField(int n, std::uint64_t seed);

  int n() const { return n_; }
  std::uint64_t seed() const { return seed_; }
  // Phase of frequency (u, v), both in [-(n-1)/2, (n-1)/2]; phase(0, 0) = 0.
  double phase(int u, int v) const;

 private:
  int n_;
  std::uint64_t seed_;
  std::vector<double> phase_;  // centred layout: (v + h) * n + (u + h), h = (n - 1) / 2
};

// ------------------------------------------------------------------------------------------------
// Height maps and profiles

struct HeightMap {
  int nx = 0;                           // columns (x direction)
  int ny = 0;                           // rows (y direction)
  double spacing = 0.0;                 // grid step (m), the same along x and y
  std::vector<double> height;           // ny * nx heights (m), height[j * nx + i]
  std::optional<SurfaceParams> params;  // generation parameters, when generated

  HeightMap() = default;
  HeightMap(int nx, int ny, double spacing);  // zero heights

  double& at(int i, int j) { return height[static_cast<std::size_t>(j) * nx + i]; }
  double at(int i, int j) const { return height[static_cast<std::size_t>(j) * nx + i]; }
  double x(int i) const { return i * spacing; }
  double y(int j) const { return j * spacing; }
  std::size_t size() const { return height.size(); }
};

struct Profile {
  double spacing = 0.0;        // step between samples (m)
  std::vector<double> height;  // heights (m)
};

// Row j (along x) and column i (along y) of a map: exact grid values.
Profile row_profile(const HeightMap& map, int row);
Profile column_profile(const HeightMap& map, int column);
// Profile through (x0, y0) (m) along `angle`, `step` apart (0: the grid spacing), sampled with
// bilinear interpolation as far as it stays inside the map in both directions from (x0, y0).
Profile line_profile(const HeightMap& map, double x0, double y0, double angle, double step = 0.0);

// ------------------------------------------------------------------------------------------------
// Generator [2-41..2-57]

// The (unnormalised) PSD of the spec at integer frequency (u, v), including the variance ellipse:
// P = |w|^-(2 H(theta) + 2) outside the roll-off ellipse chi(theta), constant inside, 0 at the
// centre. The generator scales it afterwards so the variance is exactly params.variance.
double spectral_density(const SurfaceParams& params, int u, int v);

// A surface with the given parameters and phases (phases.n() must equal params.n; the map's
// params.seed is set to phases.seed()). Zero mean; variance params.variance to rounding.
HeightMap generate_surface(const SurfaceParams& params, const PhaseField& phases);
// Same, with PhaseField(params.n, params.seed).
HeightMap generate_surface(const SurfaceParams& params);

// ------------------------------------------------------------------------------------------------
// Analysis [2-1..2-17]

struct Plane {  // z = a x + b y + c [2-1], x, y in metres from the grid origin
  double a = 0.0, b = 0.0, c = 0.0;
};
struct Line {  // z = a s + c along a profile, s = k * spacing
  double a = 0.0, c = 0.0;
};

Plane fit_mean_plane(const HeightMap& map);
HeightMap remove_mean_plane(const HeightMap& map);  // residual heights z - (a x + b y + c)
Line fit_mean_line(const Profile& profile);
Profile remove_mean_line(const Profile& profile);

struct AmplitudeStats {
  double mean = 0.0;
  double ra = 0.0;        // [2-2] mean |z - mean|
  double rms = 0.0;       // [2-3] sqrt of variance
  double variance = 0.0;  // population variance (1/N) about the mean
  double skewness = 0.0;  // [2-5] m3 / m2^1.5
  double kurtosis = 0.0;  // [2-5] m4 / m2^2 (3 for a Gaussian; not the excess)
  double min = 0.0, max = 0.0;
  std::size_t count = 0;
};
AmplitudeStats amplitude_stats(std::span<const double> heights);
AmplitudeStats amplitude_stats(const HeightMap& map);
AmplitudeStats amplitude_stats(const Profile& profile);

// A function of the lag: structure function S [2-9], variogram S/2, autocovariance R [2-6].
struct LagSeries {
  double angle = 0.0;         // direction (rad); NaN for radial averages and profiles
  std::vector<double> lag;    // m
  std::vector<double> value;  // m^2
  std::vector<double> pairs;  // number of height pairs behind each value
};

// Lag statistics of a map, computed once with FFTs for every lattice lag (dx, dy) and then read
// along any direction or averaged over rings. See analysis.cpp for the sampling rules:
// - x, y and the diagonals read exact lattice lags, k steps of (1,0), (0,1), (1,1), (1,-1);
// - other angles read the lag map at k * spacing along the direction with bilinear interpolation
//   of S (not of the heights, which would smooth the surface and bias S low at small lags);
// - radial averages pool all lattice lags with |d| in [k - 1/2, k + 1/2) spacings, weighted by
//   their pair counts, and report the pair-weighted mean |d| as the lag.
// Autocovariance is about the map mean. max_lag <= 0 means half the smaller side.
class LagMap {
 public:
  explicit LagMap(const HeightMap& map);

  LagSeries structure_function(double angle, double max_lag = 0.0) const;
  LagSeries structure_function_radial(double max_lag = 0.0) const;
  LagSeries autocovariance(double angle, double max_lag = 0.0) const;
  LagSeries autocovariance_radial(double max_lag = 0.0) const;
  double variance() const { return variance_; }  // about the mean

  // Exact values at a lattice lag (dx, dy) in grid steps, |dx| < nx, |dy| < ny.
  double structure_at(int dx, int dy) const;
  double autocovariance_at(int dx, int dy) const;
  double pairs_at(int dx, int dy) const;

 private:
  enum class Quantity { structure, autocovariance };
  LagSeries along(Quantity q, double angle, double max_lag) const;
  LagSeries radial(Quantity q, double max_lag) const;
  std::size_t index(int dx, int dy) const;

  int nx_ = 0, ny_ = 0;
  double spacing_ = 0.0;
  double variance_ = 0.0;
  std::vector<double> structure_;  // (2 nx - 1) x ny: dx in [-(nx-1), nx-1], dy in [0, ny-1]
  std::vector<double> covariance_;
};

// Convenience wrappers (each builds a LagMap; build one yourself for several directions).
LagSeries structure_function(const HeightMap& map, double angle, double max_lag = 0.0);
LagSeries structure_function_radial(const HeightMap& map, double max_lag = 0.0);
LagSeries autocovariance(const HeightMap& map, double angle, double max_lag = 0.0);
LagSeries autocovariance_radial(const HeightMap& map, double max_lag = 0.0);
// Profiles: direct sums over the pairs; max_lag <= 0 means half the profile length.
LagSeries structure_function(const Profile& profile, double max_lag = 0.0);
LagSeries autocovariance(const Profile& profile, double max_lag = 0.0);
// gamma = S / 2
LagSeries variogram(const LagSeries& structure_function);

// Power spectral density, two-sided, normalised so that its sum times the frequency cell equals
// the variance (Parseval): m^4 for maps (per (cycle/m)^2), m^3 for profiles (per cycle/m).
enum class Window { none, hann };
struct Spectrum {
  std::vector<double> frequency;  // cycles per metre (ring or bin centre)
  std::vector<double> psd;
  std::vector<double> count;  // Fourier modes behind each value
};
// Ring average over |f| in unit-width rings of the fundamental frequency 1/(n spacing).
Spectrum radial_psd(const HeightMap& map, Window window = Window::hann);
// Same, restricted to wave vectors within +-half_width of `angle` (or of angle + pi).
Spectrum sector_psd(const HeightMap& map, double angle, double half_width,
                    Window window = Window::hann);
// One-sided in frequency (f > 0), both signs folded, for profiles.
Spectrum profile_psd(const Profile& profile, Window window = Window::hann);

// Least-squares straight line through (log x, log y) for x in [x_min, x_max] and y > 0.
struct PowerLawFit {
  double hurst = 0.0;               // the roughness exponent the slope stands for
  double slope = 0.0;               // d log y / d log x
  double intercept = 0.0;           // log y at x = 1
  double r2 = 0.0;                  // coefficient of determination of the log-log fit
  double x_min = 0.0, x_max = 0.0;  // the window actually used
  int points = 0;                   // 0 (and NaN hurst) when fewer than 3 points fell in the window
};
PowerLawFit fit_power_law(std::span<const double> x, std::span<const double> y, double x_min,
                          double x_max);
// [2-12] S ~ tau^(2H): hurst = slope / 2.
PowerLawFit hurst_from_structure(const LagSeries& structure_function, double min_lag,
                                 double max_lag);
// PSD ~ f^-(dimension + 2H): dimension 2 for radial/sector map spectra, 1 for profiles.
PowerLawFit hurst_from_psd(const Spectrum& spectrum, int dimension, double min_frequency,
                           double max_frequency);

// Correlation length rule: the smallest lag at which S reaches (1 - 1/e) * 2 * variance, linearly
// interpolated between the two lags that bracket it; NaN when S never gets there.
double correlation_length(const LagSeries& structure_function, double variance);

// Roll-off length Lc = 1 / (2 f_c), f_c the corner of a broken power law fitted to the spectrum
// below the fit window: flat below f_c, the given power-law fit above. Estimates the generator's
// Lc (chi = 1/(2 Lc) [2-50]); NaN without rings below the fit window.
double rolloff_length(const Spectrum& spectrum, const PowerLawFit& psd_fit);

// Z2 (RMS slope) and Z3 (RMS curvature) against the step tau [2-13, 2-14]:
//   Z2(tau) = sqrt(<(z(r + tau) - z(r))^2>) / tau
//   Z3(tau) = sqrt(<(z(r + tau) - 2 z(r) + z(r - tau))^2>) / tau^2
struct SlopeSeries {
  double angle = 0.0;        // NaN for profiles
  std::vector<double> step;  // m
  std::vector<double> z2;    // dimensionless
  std::vector<double> z3;    // 1/m
};
// Steps k * spacing, k = 1..max_steps, along `angle` (bilinear interpolation off the lattice
// directions, exact on x, y and the diagonals).
SlopeSeries slope_statistics(const HeightMap& map, double angle, int max_steps = 20);
SlopeSeries slope_statistics(const Profile& profile, int max_steps = 20);

// Colatitude (apparent dip) distribution [2-17]: theta* = atan((z(r + step) - z(r)) / step)
// along `angle`, positive slopes (facing the direction) and negative slopes separately.
struct ColatitudeDistribution {
  double angle = 0.0;              // NaN for profiles
  double step = 0.0;               // m
  std::vector<double> bin_edges;   // rad, bins + 1 edges over [0, pi/2]
  std::vector<double> positive;    // fraction of all samples with theta* > 0 in each |theta*| bin
  std::vector<double> negative;    // same for theta* < 0 (by |theta*|)
  double fraction_positive = 0.0;  // share of samples with theta* > 0
  double mean_positive = 0.0;      // mean theta* over positive samples (rad)
  double mean_negative = 0.0;      // mean |theta*| over negative samples (rad)
  double max_positive = 0.0;
  double max_negative = 0.0;
  std::size_t samples = 0;
};
ColatitudeDistribution colatitude_distribution(const HeightMap& map, double angle,
                                               double step = 0.0, int bins = 90);
ColatitudeDistribution colatitude_distribution(const Profile& profile, double step = 0.0,
                                               int bins = 90);

// Abbott-Firestone (bearing area) curve: bearing_fraction[k] = share of the values >= height[k],
// at `levels` heights evenly spaced from the maximum down to the minimum.
struct AbbottCurve {
  std::vector<double> height;            // m, decreasing
  std::vector<double> bearing_fraction;  // increasing from 1/N to 1
};
AbbottCurve abbott_curve(std::span<const double> values, int levels = 201);
AbbottCurve abbott_curve(const HeightMap& map, int levels = 201);

// ------------------------------------------------------------------------------------------------
// One-call analysis (what scripts/surface.lua writes to summary.json)

struct AnalysisOptions {
  bool remove_mean_plane = true;
  Window window = Window::hann;  // for the PSD
  double max_lag = 0.0;          // m; <= 0: half the smaller side
  // Structure-function fit window (m). <= 0: automatic, lags from 1 spacing to a quarter of the
  // measured correlation length (at least 6 lags), i.e. well below Lc (see analysis.cpp).
  double structure_fit_min_lag = 0.0;
  double structure_fit_max_lag = 0.0;
  // PSD fit window (cycles/m). <= 0: automatic, from 1/(2 correlation length) (about 2.5 times
  // the roll-off of generated surfaces; at least 4 fundamentals) to 0.7 times Nyquist (0.35/h).
  double psd_fit_min_frequency = 0.0;
  double psd_fit_max_frequency = 0.0;
  int directions = 12;  // polar data: directions evenly spread over [0, pi)
  // rad, PSD sector per direction; <= 0: max(pi / (2 directions), pi / 8) (sectors overlap
  // with many directions: fewer modes per sector make H and the roll-off too noisy)
  double sector_half_width = 0.0;
  int abbott_levels = 201;
  int colatitude_bins = 90;
  int slope_max_steps = 20;
};

struct DirectionalRoughness {
  double angle = 0.0;               // rad
  double hurst_structure = 0.0;     // from S along the direction
  double hurst_psd = 0.0;           // from the PSD sector around the direction
  double variance = 0.0;            // mean variance of profiles along it (smaller side long)
  double correlation_length = 0.0;  // the rule above on S along it, with that variance
  double rolloff_length = 0.0;      // Lc from the corner of the PSD sector
};

struct RoughnessSummary {
  Plane mean_plane;
  AmplitudeStats amplitude;
  double correlation_length = 0.0;  // from the radially averaged S (the (1 - 1/e) rule)
  double rolloff_length = 0.0;      // Lc from the corner of the radially averaged PSD
  PowerLawFit hurst_structure;      // radially averaged S
  PowerLawFit hurst_psd;            // radially averaged 2-D PSD
  LagSeries structure_radial;
  LagSeries structure_x, structure_y;
  Spectrum psd_radial;
  AbbottCurve abbott;
  std::vector<DirectionalRoughness> polar;
};
RoughnessSummary analyze(const HeightMap& map, const AnalysisOptions& options = {});

// Per-direction H, s2, Lc (for polar plots) at options.directions angles over [0, pi).
// `map` is used as given (no plane removal).
std::vector<DirectionalRoughness> polar_roughness(const HeightMap& map,
                                                  const AnalysisOptions& options = {});

struct ProfileSummary {
  Line mean_line;
  AmplitudeStats amplitude;
  double correlation_length = 0.0;
  double rolloff_length = 0.0;
  PowerLawFit hurst_structure;
  PowerLawFit hurst_psd;
  LagSeries structure;
  Spectrum psd;
};
ProfileSummary analyze(const Profile& profile, const AnalysisOptions& options = {});

// ------------------------------------------------------------------------------------------------
// From a synthetic surface to a DEM surface (spec section 3, thesis 3.4.1;
// engine/surface/dem_surface.cpp)

// Which half of a joint the particles form: the profilometer reads the top of the lower half
// (highest particle point over each node) and the bottom of the upper half (lowest point).
enum class HalfSide { lower, upper };

// The profilometer's grid: node (i, j) is at (x0 + i spacing, y0 + j spacing) in the particles'
// frame. Usually the synthetic map's grid (same nx, ny, spacing) placed where the mold was.
struct ProfilometerGrid {
  int nx = 0, ny = 0;
  double spacing = 0.0;       // m
  double x0 = 0.0, y0 = 0.0;  // m
};

struct ProfilometerResult {
  HeightMap surface;                   // z_dem per node (m); NaN where no particle covers it
  std::vector<std::int64_t> particle;  // per node: the particle giving the height, -1 if none
  std::size_t covered = 0;             // nodes with a height
  std::size_t particles = 0;           // distinct particles giving at least one node
};

// Numerical profilometer: for each node the highest (lower half) or lowest (upper half) point
// of the spheres whose disc covers it, zc +- sqrt(R^2 - (x - xc)^2 - (y - yc)^2).
// positions: x0, y0, z0, x1, ... (3 N values), radii: N values. `subset` (indices into them)
// restricts the particles considered; empty means all. Particle numbers in the result are
// indices into positions/radii. Cost O(N (2R/h + 1)^2 + nx ny): each sphere visits only the
// nodes of its disc's bounding box.
ProfilometerResult profilometer(std::span<const double> positions, std::span<const double> radii,
                                const ProfilometerGrid& grid, HalfSide side,
                                std::span<const std::int64_t> subset = {});

// Mean plane of a DEM surface by the modified Abbott curve: the synthetic surface shifted by dv
// has reached the DEM surface at the nodes where z_syn + dv >= z_dem, so the share of such nodes
// as a function of dv is the cumulative distribution F(dv) of d = z_dem - z_syn. The DEM mean
// plane is the synthetic one shifted by dv_mp, the dv of steepest F (the mode of d), where most
// nodes of the DEM surface lie on the synthetic surface.
struct DemMeanPlaneOptions {
  int levels = 401;        // points of the returned curves, evenly spaced over [min d, max d]
  double bandwidth = 0.0;  // m, Gaussian kernel for dF/ddv; <= 0: Silverman's rule (see .cpp)
  double tolerance = 0.0;  // m, |d - dv_mp| <= tolerance counts as coinciding; <= 0: 1 % of
                           // the synthetic surface's rms height
};
struct DemMeanPlane {
  double shift = 0.0;                // dv_mp (m)
  double coinciding_fraction = 0.0;  // share of covered nodes with |d - dv_mp| <= tolerance
  double tolerance = 0.0;            // m, as used
  double bandwidth = 0.0;            // m, as used
  double mean_difference = 0.0;      // <d> (m): what a plain mean would give (biased by holes)
  std::size_t points = 0;            // nodes with a finite z_dem
  std::vector<double> dv;            // m, increasing
  std::vector<double> cumulative;    // F(dv): share of nodes with z_syn + dv >= z_dem
  std::vector<double> density;       // dF/ddv (1/m), kernel-smoothed
};
// dem and synthetic on the same grid (nx, ny); NaN heights of dem (uncovered nodes) are skipped.
DemMeanPlane dem_mean_plane(const HeightMap& dem, const HeightMap& synthetic,
                            const DemMeanPlaneOptions& options = {});

// Surface vs porosity particles [3-52..3-54]: a profilometer particle belongs to the rough
// surface when at least one of the nodes it gives satisfies |z_dem - (z_syn + shift)| <= band,
// i.e. it touches the expected surface somewhere; the others are porosity particles, seen by the
// profilometer through holes of the packing below (lower half) or above (upper half) it.
struct SurfaceParticles {
  std::vector<std::int64_t> surface;   // particle numbers (as in ProfilometerResult), sorted
  std::vector<std::int64_t> porosity;  // sorted
  double retained_fraction = 0.0;      // surface / (surface + porosity)
  double node_fraction = 0.0;          // share of covered nodes within the band
  double band = 0.0;                   // m
  double shift = 0.0;                  // m
};
SurfaceParticles classify_surface_particles(const HeightMap& dem,
                                            std::span<const std::int64_t> node_particle,
                                            const HeightMap& synthetic, double shift, double band);
inline SurfaceParticles classify_surface_particles(const ProfilometerResult& profile,
                                                   const HeightMap& synthetic, double shift,
                                                   double band) {
  return classify_surface_particles(profile.surface, profile.particle, synthetic, shift, band);
}

// Noise study: uncorrelated Gaussian noise of standard deviation level * rms(map) added to the
// map (one noise field of the seed, scaled per level), then H and s2 re-measured with the fit
// windows of the clean map, so only the surface changes between levels, not the estimator.
struct NoiseLevel {
  double level = 0.0;      // noise rms / height rms
  double noise_rms = 0.0;  // m
  double variance = 0.0;   // m^2, of the noisy map about its mean plane
  double hurst_psd = 0.0;
  double hurst_structure = 0.0;
  double psd_fit_r2 = 0.0;  // r^2 of the log-log PSD fit: how well a power law still holds
  double structure_fit_r2 = 0.0;
  double correlation_length = 0.0;  // m
};
std::vector<NoiseLevel> noise_study(const HeightMap& map, std::span<const double> levels,
                                    std::uint64_t seed = 1, const AnalysisOptions& options = {});

// ------------------------------------------------------------------------------------------------
// Elevation map plot (engine/surface/plot_map.cpp)

struct MapPlotOptions {
  std::string title;
  int width = 900, height = 800;  // pixels
  double length_scale = 1e3;      // axis values = metres * length_scale (mm by default)
  double height_scale = 1e3;      // colour values = metres * height_scale
  std::string length_unit = "mm", height_unit = "mm";
};
// Heat map of the heights (gnuplot, `with image`), drawn to a temporary name and renamed.
// NaN nodes are left blank. Throws Error when gnuplot is missing or fails.
void plot_height_map_png(const HeightMap& map, const std::string& path,
                         const MapPlotOptions& options = {});

// ------------------------------------------------------------------------------------------------
// Files (engine/surface/surface_io.cpp)

// HDF5: dataset `height` (ny x nx doubles, m, row = y index) with attributes `spacing` (m),
// `units` = "m" and, for generated maps, the generation parameters (n, side, hurst_x, hurst_y,
// correlation_length_x, correlation_length_y, variance, variance_x, variance_y, seed, name).
// Written to a temporary name and renamed, so a crash never leaves half a file.
void save_hdf5(const HeightMap& map, const std::string& path);
// `spacing_override` > 0 replaces (or supplies a missing) `spacing` attribute.
HeightMap load_hdf5(const std::string& path, double spacing_override = 0.0);

// CSV grid: one row of heights per line (row = y index, increasing y), separated by commas,
// semicolons, tabs or spaces; '#' lines are comments, and "# spacing = <m>" gives the spacing.
void save_csv(const HeightMap& map, const std::string& path);

struct GridImportOptions {
  double spacing = 0.0;       // m; <= 0: read it from the file ("# spacing =" or ESRI cellsize)
  double height_scale = 1.0;  // multiplies the values (e.g. 1e-6 for a scan in micrometres)
};
// Reads a CSV/whitespace grid as written by save_csv, or an ESRI ASCII grid (header ncols,
// nrows, xllcorner, yllcorner, cellsize, nodata_value; first data row is the northmost, so the
// rows are flipped to make row 0 the smallest y). Missing values are an error.
HeightMap load_grid(const std::string& path, const GridImportOptions& options = {});

}  // namespace asperity::surface
