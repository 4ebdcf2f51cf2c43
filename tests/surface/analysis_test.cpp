// tests/surface/analysis_test.cpp - roughness analysis against surfaces with known answers
// (spec surfaces.md section 2): a tilted plane, a sinusoid, white noise, a random walk.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "asperity/error.hpp"
#include "asperity/surface.hpp"

namespace asperity::surface {
namespace {

constexpr double pi = std::numbers::pi;

HeightMap plane_map(int nx, int ny, double h, double a, double b, double c) {
    HeightMap m(nx, ny, h);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) m.at(i, j) = a * m.x(i) + b * m.y(j) + c;
    return m;
}

// z = A cos(2 pi (x - xc) / lambda), xc the grid centre: even about the centre and whole periods
// (nx = 360, lambda = 60 steps), so the mean plane is exactly z = 0.
constexpr double amplitude = 2e-4;
constexpr int wave_steps = 60;
HeightMap cosine_map(int nx = 360, int ny = 40, double h = 1e-4) {
    HeightMap m(nx, ny, h);
    const double xc = 0.5 * (nx - 1);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) m.at(i, j) = amplitude * std::cos(2 * pi * (i - xc) / wave_steps);
    return m;
}

HeightMap white_noise(int n, double sigma, unsigned seed) {
    HeightMap m(n, n, 1e-3);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, sigma);
    for (double& z : m.height) z = normal(rng);
    return m;
}

TEST(MeanPlane, RemovesATiltedPlaneExactly) {
    const double a = 0.013, b = -0.021, c = 0.0042;
    const HeightMap m = plane_map(50, 37, 2e-4, a, b, c);
    const Plane p = fit_mean_plane(m);
    EXPECT_NEAR(p.a, a, 1e-14);
    EXPECT_NEAR(p.b, b, 1e-14);
    EXPECT_NEAR(p.c, c, 1e-16);
    const RoughnessSummary r = analyze(m);
    EXPECT_LT(r.amplitude.rms, 1e-17);
    EXPECT_LT(r.amplitude.ra, 1e-17);
    EXPECT_NEAR(r.mean_plane.a, a, 1e-14);
    for (double s : r.structure_radial.value) EXPECT_LT(s, 1e-32);
    // Profiles: the same with a line.
    const Profile row = row_profile(m, 5);
    const Line line = fit_mean_line(row);
    EXPECT_NEAR(line.a, a, 1e-14);
    EXPECT_NEAR(line.c, b * m.y(5) + c, 1e-16);
    EXPECT_LT(amplitude_stats(remove_mean_line(row)).rms, 1e-17);
}

TEST(Amplitude, SinusoidRaRmsAndMoments) {
    const HeightMap m = cosine_map();
    const Plane p = fit_mean_plane(m);
    EXPECT_LT(std::abs(p.a) + std::abs(p.b) + std::abs(p.c) / amplitude, 1e-12);
    const AmplitudeStats st = amplitude_stats(m);
    EXPECT_NEAR(st.ra, 2 * amplitude / pi, 1e-3 * amplitude);              // [2-2] 2A/pi
    EXPECT_NEAR(st.rms, amplitude / std::sqrt(2.0), 1e-12 * amplitude);    // [2-3] A/sqrt2
    EXPECT_NEAR(st.skewness, 0.0, 1e-10);
    EXPECT_NEAR(st.kurtosis, 1.5, 1e-10);  // <cos^4> / <cos^2>^2 = (3/8) / (1/4)
    EXPECT_NEAR(st.max, amplitude * std::cos(pi / wave_steps), 1e-12 * amplitude);  // half-step samples
}

TEST(LagMap, FftSumsEqualTheDirectDoubleLoop) {
    // A non-periodic random map, odd and even sizes: every lattice lag checked.
    HeightMap m(13, 10, 1e-3);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int j = 0; j < m.ny; ++j)
        for (int i = 0; i < m.nx; ++i) m.at(i, j) = u(rng) + 0.1 * i;  // with a trend
    double mean = 0;
    for (double z : m.height) mean += z / m.size();
    const LagMap lags(m);
    for (int dy = -(m.ny - 1); dy < m.ny; ++dy)
        for (int dx = -(m.nx - 1); dx < m.nx; ++dx) {
            if (dx == 0 && dy == 0) continue;
            double s = 0, r = 0;
            int n = 0;
            for (int j = 0; j < m.ny; ++j)
                for (int i = 0; i < m.nx; ++i) {
                    const int i2 = i + dx, j2 = j + dy;
                    if (i2 < 0 || j2 < 0 || i2 >= m.nx || j2 >= m.ny) continue;
                    const double d = m.at(i2, j2) - m.at(i, j);
                    s += d * d;
                    r += (m.at(i, j) - mean) * (m.at(i2, j2) - mean);
                    ++n;
                }
            ASSERT_NEAR(lags.structure_at(dx, dy), s / n, 1e-12) << dx << "," << dy;
            ASSERT_NEAR(lags.autocovariance_at(dx, dy), r / n, 1e-12) << dx << "," << dy;
            ASSERT_EQ(lags.pairs_at(dx, dy), n);
        }
}

TEST(StructureFunction, SinusoidAlongAndAcrossTheWave) {
    const HeightMap m = cosine_map();
    const double h = m.spacing, lambda = wave_steps * h;
    auto expected = [&](double tau) {  // [2-9] 2 A^2 sin^2(pi tau / lambda)
        const double s = std::sin(pi * tau / lambda);
        return 2 * amplitude * amplitude * s * s;
    };
    const double plateau = 2 * amplitude * amplitude;
    const LagMap lags(m);
    const LagSeries along = lags.structure_function(0.0, lambda);
    ASSERT_EQ(along.lag.size(), static_cast<std::size_t>(wave_steps));
    for (std::size_t k = 0; k < along.lag.size(); ++k) {
        EXPECT_NEAR(along.lag[k], (k + 1) * h, 1e-15);
        EXPECT_NEAR(along.value[k], expected(along.lag[k]), 0.02 * plateau) << k;
    }
    const LagSeries reverse = lags.structure_function(pi, lambda);  // same pairs
    for (std::size_t k = 0; k < along.lag.size(); ++k) EXPECT_EQ(reverse.value[k], along.value[k]);
    const LagSeries across = lags.structure_function(pi / 2, 0.5 * m.ny * h);
    ASSERT_FALSE(across.value.empty());
    for (double s : across.value) EXPECT_LT(s, 1e-12 * plateau);
    // Diagonal: exact lattice steps of h sqrt2, the wave sees tau / sqrt2.
    const LagSeries diagonal = lags.structure_function(pi / 4, 30 * h);
    EXPECT_NEAR(diagonal.lag[0], std::sqrt(2.0) * h, 1e-15);
    for (std::size_t k = 0; k < diagonal.lag.size(); ++k)
        EXPECT_NEAR(diagonal.value[k], expected(diagonal.lag[k] / std::sqrt(2.0)), 0.02 * plateau);
    // 30 degrees: interpolated in the lag map.
    const LagSeries oblique = lags.structure_function(pi / 6, 30 * h);
    for (std::size_t k = 0; k < oblique.lag.size(); ++k)
        EXPECT_NEAR(oblique.value[k], expected(oblique.lag[k] * std::cos(pi / 6)), 0.03 * plateau);
    // Variogram = S / 2; a profile along the wave gives the same S (up to the finite sample).
    const LagSeries gamma = variogram(along);
    EXPECT_DOUBLE_EQ(gamma.value[7], 0.5 * along.value[7]);
    const LagSeries profile = structure_function(row_profile(m, 3), lambda);
    for (std::size_t k = 0; k < profile.lag.size(); ++k)
        EXPECT_NEAR(profile.value[k], along.value[k], 1e-12 * plateau);
    // Autocovariance R = s2 - S/2 [2-6]: A^2/2 cos(2 pi tau / lambda).
    const LagSeries r = lags.autocovariance(0.0, lambda);
    for (std::size_t k = 0; k < r.lag.size(); ++k)
        EXPECT_NEAR(r.value[k], 0.5 * amplitude * amplitude * std::cos(2 * pi * r.lag[k] / lambda),
                    0.02 * plateau);
}

TEST(StructureFunction, WhiteNoiseIsFlat) {
    const double sigma = 1e-4;
    const HeightMap m = white_noise(256, sigma, 3);
    const RoughnessSummary r = analyze(m);
    const double s2 = r.amplitude.variance;
    EXPECT_NEAR(s2 / (sigma * sigma), 1.0, 0.02);
    EXPECT_NEAR(r.amplitude.skewness, 0.0, 0.03);
    EXPECT_NEAR(r.amplitude.kurtosis, 3.0, 0.06);
    EXPECT_NEAR(r.amplitude.ra / r.amplitude.rms, std::sqrt(2 / pi), 0.01);  // Gaussian
    for (const LagSeries* s : {&r.structure_radial, &r.structure_x, &r.structure_y})
        for (std::size_t k = 0; k < s->lag.size(); ++k)
            EXPECT_NEAR(s->value[k] / (2 * s2), 1.0, 0.03) << k;
    const LagSeries oblique = structure_function(m, 0.3);
    for (double v : oblique.value) EXPECT_NEAR(v / (2 * s2), 1.0, 0.03);
    // Reached at the first ring (mean lag ~1.2 h): the rule interpolates from S(0) = 0.
    const double first = r.structure_radial.lag[0];
    EXPECT_NEAR(r.correlation_length, (1 - std::exp(-1.0)) * first, 0.03 * first);
    // No self-affine range above the "roll-off" 1 / (2 xi): the automatic PSD window is empty.
    EXPECT_EQ(r.hurst_psd.points, 0);
    EXPECT_TRUE(std::isnan(r.hurst_psd.hurst));
    // Flat spectrum over the whole band: slope 0.
    const PowerLawFit flat = hurst_from_psd(r.psd_radial, 2, 4 / (m.nx * m.spacing), 0.5 / m.spacing);
    EXPECT_NEAR(flat.slope, 0.0, 0.05);
    const LagSeries cov = autocovariance_radial(m);
    for (double v : cov.value) EXPECT_LT(std::abs(v), 0.03 * s2);
}

TEST(Psd, ParsevalNormalisation) {
    const HeightMap m = white_noise(64, 1.0, 4);
    const AmplitudeStats st = amplitude_stats(m);
    for (Window w : {Window::none, Window::hann}) {
        const Spectrum s = radial_psd(m, w);
        const double df = 1.0 / (m.nx * m.spacing);
        double total = 0;
        for (std::size_t k = 0; k < s.psd.size(); ++k) total += s.psd[k] * s.count[k] * df * df;
        if (w == Window::none)
            EXPECT_NEAR(total / st.variance, 1.0, 1e-12);
        else
            EXPECT_NEAR(total / st.variance, 1.0, 0.05);  // window-corrected on average
    }
    const Profile p = row_profile(m, 10);
    const Spectrum s1 = profile_psd(p, Window::none);
    double total = 0;
    for (double v : s1.psd) total += v / (p.height.size() * p.spacing);
    EXPECT_NEAR(total / amplitude_stats(p).variance, 1.0, 1e-12);
}

TEST(Hurst, RandomWalkProfileHasHalf) {
    // Brownian profile: S(tau) = sigma^2 tau / h exactly in expectation, H = 1/2.
    std::mt19937_64 rng(11);
    std::normal_distribution<double> normal(0.0, 1e-5);
    double sum_s = 0, sum_p = 0;
    const int profiles = 8;
    for (int k = 0; k < profiles; ++k) {
        Profile p{1e-4, {}};
        double z = 0;
        for (int i = 0; i < 4096; ++i) p.height.push_back(z += normal(rng));
        AnalysisOptions o;
        o.structure_fit_max_lag = 50 * p.spacing;  // no roll-off in a random walk
        o.psd_fit_min_frequency = 20 / (4096 * p.spacing);
        const ProfileSummary r = analyze(p, o);
        sum_s += r.hurst_structure.hurst / profiles;
        sum_p += r.hurst_psd.hurst / profiles;
    }
    EXPECT_NEAR(sum_s, 0.5, 0.05);
    EXPECT_NEAR(sum_p, 0.5, 0.1);
}

TEST(Fits, PowerLawAndCorrelationLengthRule) {
    std::vector<double> x, y;
    for (int k = 1; k <= 20; ++k) {
        x.push_back(k * 0.1);
        y.push_back(3.0 * std::pow(k * 0.1, 1.4));
    }
    const PowerLawFit fit = fit_power_law(x, y, 0.2, 1.5);
    EXPECT_EQ(fit.points, 14);
    EXPECT_NEAR(fit.slope, 1.4, 1e-12);
    EXPECT_NEAR(fit.intercept, std::log(3.0), 1e-12);
    EXPECT_NEAR(fit.r2, 1.0, 1e-12);
    EXPECT_EQ(fit_power_law(x, y, 5, 6).points, 0);
    EXPECT_TRUE(std::isnan(fit_power_law(x, y, 5, 6).hurst));
    // S = 2 s2 (1 - exp(-tau / xi)): the rule returns xi.
    LagSeries s;
    const double s2 = 2.5e-7, xi = 4e-3;
    for (int k = 1; k <= 400; ++k) {
        s.lag.push_back(k * 5e-5);
        s.value.push_back(2 * s2 * (1 - std::exp(-s.lag.back() / xi)));
    }
    EXPECT_NEAR(correlation_length(s, s2) / xi, 1.0, 1e-4);
    EXPECT_TRUE(std::isnan(correlation_length(s, 10 * s2)));
    const PowerLawFit hs = hurst_from_structure(s, 5e-5, 2e-4);
    EXPECT_EQ(hs.points, 4);
    EXPECT_NEAR(hs.hurst, 0.5, 0.01);  // exponential model: S ~ tau at small lags
    EXPECT_NEAR(hurst_from_structure(variogram(s), 5e-5, 2e-4).hurst, hs.hurst, 1e-12);
}

TEST(Slopes, Z2Z3OnAPlaneAndASinusoid) {
    const double a = 0.2, b = -0.1;
    const HeightMap plane = plane_map(30, 30, 1e-3, a, b, 0.0);
    for (double angle : {0.0, pi / 2, pi / 4, pi / 6, 2.0}) {
        const SlopeSeries s = slope_statistics(plane, angle, 5);
        ASSERT_EQ(s.step.size(), 5u);
        const double slope = std::abs(a * std::cos(angle) + b * std::sin(angle));
        for (std::size_t k = 0; k < s.step.size(); ++k) {
            EXPECT_NEAR(s.z2[k], slope, 1e-12) << angle;  // [2-13]: bilinear is exact on planes
            EXPECT_LT(s.z3[k], 1e-9);                     // [2-14]
        }
    }
    const HeightMap wave = cosine_map();
    const SlopeSeries s = slope_statistics(wave, 0.0, 10);
    const LagSeries sf = structure_function(wave, 0.0);
    const double kw = 2 * pi / (wave_steps * wave.spacing);
    for (std::size_t k = 0; k < s.step.size(); ++k) {
        const double tau = s.step[k];
        EXPECT_NEAR(s.z2[k], std::sqrt(sf.value[k]) / tau, 1e-9 * s.z2[k]);  // same pairs as S
        // Analytic values for whole periods; the rows hold a fraction of a period more.
        EXPECT_NEAR(s.z2[k], amplitude * std::sqrt(2.0) * std::abs(std::sin(kw * tau / 2)) / tau,
                    0.025 * s.z2[k]);
        EXPECT_NEAR(s.z3[k], amplitude * std::sqrt(2.0) * (1 - std::cos(kw * tau)) / (tau * tau),
                    0.025 * s.z3[k]);
    }
    const SlopeSeries profile = slope_statistics(row_profile(wave, 0), 10);
    EXPECT_NEAR(profile.z2[0], s.z2[0], 1e-9 * s.z2[0]);
    EXPECT_NEAR(profile.z3[3], s.z3[3], 1e-9 * s.z3[3]);
}

TEST(Colatitude, PlaneFacesOneWay) {
    const double dip = 20.5 * pi / 180;  // mid-bin: 20 degrees exactly would sit on an edge
    const HeightMap plane = plane_map(40, 40, 1e-3, std::tan(dip), 0.0, 0.0);
    const ColatitudeDistribution up = colatitude_distribution(plane, 0.0);
    EXPECT_EQ(up.samples, 39u * 40u);
    EXPECT_DOUBLE_EQ(up.fraction_positive, 1.0);
    EXPECT_NEAR(up.mean_positive, dip, 1e-12);
    EXPECT_NEAR(up.max_positive, dip, 1e-12);
    EXPECT_EQ(up.bin_edges.size(), 91u);
    EXPECT_DOUBLE_EQ(up.positive[20], 1.0);  // [20, 21) degrees
    const ColatitudeDistribution down = colatitude_distribution(plane, pi);
    EXPECT_DOUBLE_EQ(down.fraction_positive, 0.0);
    EXPECT_NEAR(down.mean_negative, dip, 1e-12);
    const ColatitudeDistribution across = colatitude_distribution(plane, pi / 2);
    EXPECT_EQ(across.fraction_positive, 0.0);
    EXPECT_EQ(across.mean_negative, 0.0);
    // Diagonal: one lattice step, apparent dip atan(tan(dip) / sqrt2).
    const ColatitudeDistribution diag = colatitude_distribution(plane, pi / 4);
    EXPECT_NEAR(diag.step, std::sqrt(2.0) * 1e-3, 1e-15);
    EXPECT_NEAR(diag.mean_positive, std::atan(std::tan(dip) / std::sqrt(2.0)), 1e-12);
    double total = 0;
    for (std::size_t b = 0; b < up.positive.size(); ++b) total += up.positive[b] + up.negative[b];
    EXPECT_NEAR(total, 1.0, 1e-12);
    // A sinusoid faces both ways equally (a step straddling a crest or trough can be exactly flat:
    // the samples sit half a step off the extremes, and flat steps count on neither side).
    const ColatitudeDistribution wave = colatitude_distribution(cosine_map(), 0.0);
    double pos = 0, neg = 0;
    for (std::size_t b = 0; b < wave.positive.size(); ++b) {
        pos += wave.positive[b];
        neg += wave.negative[b];
    }
    EXPECT_NEAR(pos, wave.fraction_positive, 1e-12);
    EXPECT_NEAR(pos, neg, 0.01);
    EXPECT_GT(pos + neg, 1.0 - 2.0 / wave_steps - 1e-12);  // at most 2 flat steps per period
    EXPECT_NEAR(wave.mean_positive, wave.mean_negative, 1e-3 * wave.mean_positive);
    const ColatitudeDistribution prof = colatitude_distribution(row_profile(plane, 3));
    EXPECT_NEAR(prof.mean_positive, dip, 1e-12);
}

TEST(Abbott, BearingCurve) {
    const std::vector<double> z = {4.0, 1.0, 3.0, 2.0};
    const AbbottCurve c = abbott_curve(z, 4);
    ASSERT_EQ(c.height.size(), 4u);
    EXPECT_EQ(c.height, (std::vector<double>{4.0, 3.0, 2.0, 1.0}));
    EXPECT_EQ(c.bearing_fraction, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
    const AbbottCurve w = abbott_curve(white_noise(64, 1.0, 9), 101);
    for (std::size_t k = 1; k < w.height.size(); ++k) {
        EXPECT_LT(w.height[k], w.height[k - 1]);
        EXPECT_GE(w.bearing_fraction[k], w.bearing_fraction[k - 1]);
    }
    EXPECT_DOUBLE_EQ(w.bearing_fraction.back(), 1.0);
}

TEST(Profiles, ExtractionAlongAnyDirection) {
    const HeightMap plane = plane_map(21, 11, 1e-3, 0.5, 0.25, 0.0);
    const Profile col = column_profile(plane, 4);
    ASSERT_EQ(col.height.size(), 11u);
    EXPECT_NEAR(col.height[3], 0.5 * 4e-3 + 0.25 * 3e-3, 1e-15);
    const Profile diag = line_profile(plane, 5e-3, 5e-3, pi / 4, std::sqrt(2.0) * 1e-3);
    ASSERT_EQ(diag.height.size(), 11u);  // (0,0) .. (10,10)
    EXPECT_NEAR(diag.height.front(), 0.0, 1e-15);
    EXPECT_NEAR(diag.height.back(), 0.75 * 10e-3, 1e-15);
    const Profile oblique = line_profile(plane, 10e-3, 5e-3, 0.4);
    const Line line = fit_mean_line(oblique);  // bilinear is exact on a plane
    EXPECT_NEAR(line.a, 0.5 * std::cos(0.4) + 0.25 * std::sin(0.4), 1e-12);
    EXPECT_THROW(row_profile(plane, 11), asperity::Error);
    EXPECT_THROW(line_profile(plane, 1.0, 0.0, 0.0), asperity::Error);
}

TEST(Polar, IsotropicSurfaceLooksTheSameEverywhere) {
    const HeightMap m = generate_surface(SurfaceParams::isotropic(0.6, 0.016, 1e-6, 5, 257, 0.1));
    AnalysisOptions o;
    o.directions = 6;
    const auto polar = polar_roughness(remove_mean_plane(m), o);
    ASSERT_EQ(polar.size(), 6u);
    for (const auto& d : polar) {
        EXPECT_NEAR(d.hurst_psd, 0.6, 0.1) << d.angle;
        EXPECT_NEAR(d.hurst_structure, polar[0].hurst_structure, 0.05) << d.angle;
        EXPECT_NEAR(d.variance / 1e-6, 0.85, 0.15) << d.angle;  // profiles lose their own means
        EXPECT_NEAR(d.correlation_length / polar[0].correlation_length, 1.0, 0.3) << d.angle;
    }
    EXPECT_NEAR(polar[1].angle, pi / 6, 1e-15);
}

}  // namespace
}  // namespace asperity::surface
