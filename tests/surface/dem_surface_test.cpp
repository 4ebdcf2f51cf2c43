// tests/surface/dem_surface_test.cpp - spec surfaces.md section 3: numerical profilometer, DEM
// mean plane by the modified Abbott curve, surface vs porosity particles, noise study; and the
// elevation-map plot.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include <unistd.h>

#include "asperity/error.hpp"
#include "asperity/io.hpp"
#include "asperity/surface.hpp"

namespace asperity::surface {
namespace {

// Brute force: every sphere against every node, written independently of the binned code.
double brute_height(const std::vector<double>& pos, const std::vector<double>& radii, double x,
                    double y, bool lower) {
    double best = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t p = 0; p < radii.size(); ++p) {
        const double dx = x - pos[3 * p], dy = y - pos[3 * p + 1];
        const double q = radii[p] * radii[p] - dx * dx - dy * dy;
        if (q < 0) continue;
        const double z = lower ? pos[3 * p + 2] + std::sqrt(q) : pos[3 * p + 2] - std::sqrt(q);
        if (std::isnan(best) || (lower ? z > best : z < best)) best = z;
    }
    return best;
}

TEST(Profilometer, SpheresOnTheNodesGiveTheirTopsExactly) {
    // One small sphere per node (R < h/2: each covers its own node only), random centre heights.
    const int nx = 17, ny = 11;
    const double h = 1e-3, r = 0.45e-3, x0 = 0.2, y0 = -0.1;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> uz(-1e-3, 1e-3);
    std::vector<double> pos, radii, zc;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            zc.push_back(uz(rng));
            pos.insert(pos.end(), {x0 + i * h, y0 + j * h, zc.back()});
            radii.push_back(r);
        }
    const ProfilometerGrid grid{nx, ny, h, x0, y0};
    const auto lower = profilometer(pos, radii, grid, HalfSide::lower);
    const auto upper = profilometer(pos, radii, grid, HalfSide::upper);
    EXPECT_EQ(lower.covered, static_cast<std::size_t>(nx * ny));
    EXPECT_EQ(lower.particles, static_cast<std::size_t>(nx * ny));
    for (int k = 0; k < nx * ny; ++k) {
        EXPECT_EQ(lower.surface.height[k], zc[k] + r);  // exact: the cap at the centre is R
        EXPECT_EQ(upper.surface.height[k], zc[k] - r);
        EXPECT_EQ(lower.particle[k], k);
    }
}

TEST(Profilometer, OverlappingCapsMatchTheBruteForceMaximum) {
    // Spheres larger than the spacing on a coarser lattice, some nodes outside every disc.
    const int nx = 23, ny = 19;
    const double h = 0.5e-3;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> pos, radii;
    for (int b = 0; b < 6; ++b)
        for (int a = 0; a < 7; ++a) {
            pos.insert(pos.end(), {(3.3 * a + u(rng)) * h, (3.4 * b + u(rng)) * h, 1e-3 * u(rng)});
            radii.push_back((0.8 + 1.2 * u(rng)) * h);
        }
    for (HalfSide side : {HalfSide::lower, HalfSide::upper}) {
        const bool lower = side == HalfSide::lower;
        const auto res = profilometer(pos, radii, {nx, ny, h, 0.0, 0.0}, side);
        std::size_t covered = 0;
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const double want = brute_height(pos, radii, i * h, j * h, lower);
                const double got = res.surface.at(i, j);
                if (std::isnan(want)) {
                    EXPECT_TRUE(std::isnan(got)) << i << "," << j;
                    EXPECT_EQ(res.particle[j * nx + i], -1);
                } else {
                    ++covered;
                    EXPECT_EQ(got, want) << i << "," << j;
                    // The recorded particle is the one that gives that height.
                    const auto p = res.particle[j * nx + i];
                    ASSERT_GE(p, 0);
                    const double dx = i * h - pos[3 * p], dy = j * h - pos[3 * p + 1];
                    const double cap = std::sqrt(radii[p] * radii[p] - dx * dx - dy * dy);
                    EXPECT_EQ(lower ? pos[3 * p + 2] + cap : pos[3 * p + 2] - cap, got);
                }
            }
        EXPECT_EQ(res.covered, covered);
        EXPECT_GT(covered, 0u);
        EXPECT_LT(covered, static_cast<std::size_t>(nx * ny));
    }
    // A subset leaves the other spheres out.
    const std::vector<std::int64_t> subset = {0, 5};
    const auto some = profilometer(pos, radii, {nx, ny, h, 0.0, 0.0}, HalfSide::lower, subset);
    EXPECT_LE(some.particles, 2u);
    for (auto p : some.particle) EXPECT_TRUE(p == -1 || p == 0 || p == 5);
}

TEST(Profilometer, RejectsInconsistentInput) {
    std::vector<double> pos = {0, 0, 0, 1, 1};
    std::vector<double> radii = {1, 1};
    EXPECT_THROW(profilometer(pos, radii, {4, 4, 1.0, 0, 0}, HalfSide::lower), Error);
    pos.push_back(1);
    EXPECT_THROW(profilometer(pos, radii, {4, 4, 0.0, 0, 0}, HalfSide::lower), Error);
    const std::vector<std::int64_t> bad = {2};
    EXPECT_THROW(profilometer(pos, radii, {4, 4, 1.0, 0, 0}, HalfSide::lower, bad), Error);
}

double rms_of(const HeightMap& m) { return std::sqrt(amplitude_stats(m).variance); }

TEST(DemMeanPlane, RecoversTheShiftOfAMixtureWithHoles) {
    // 40 % of the nodes on the synthetic surface shifted by dv, the rest below it by an
    // exponential depth (caps between contacts, holes): the mean of d is far off, the mode is dv.
    const HeightMap syn = generate_surface(reference_surface("S1", 7, 129));
    const double rms = rms_of(syn), dv = -0.2e-3;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::exponential_distribution<double> depth(1.0 / (0.2 * rms));
    HeightMap dem = syn;
    std::size_t on = 0;
    for (std::size_t k = 0; k < dem.size(); ++k) {
        const bool coincide = u(rng) < 0.4;
        on += coincide;
        dem.height[k] = syn.height[k] + dv - (coincide ? 0.0 : depth(rng));
    }
    dem.height[5] = std::numeric_limits<double>::quiet_NaN();  // an uncovered node is skipped
    const DemMeanPlane mp = dem_mean_plane(dem, syn);
    EXPECT_EQ(mp.points, dem.size() - 1);
    EXPECT_NEAR(mp.shift, dv, 0.01 * rms);
    EXPECT_LT(mp.mean_difference, dv - 0.1 * rms);  // why the mode, not the mean
    // With a tolerance below the depths' scale the coinciding share is the 40 % put there.
    DemMeanPlaneOptions tight;
    tight.tolerance = 1e-4 * rms;
    const DemMeanPlane mt = dem_mean_plane(dem, syn, tight);
    EXPECT_NEAR(mt.coinciding_fraction, static_cast<double>(on) / dem.size(), 0.005);
    // The curves: F increasing from ~0 to 1, steepest at the shift.
    ASSERT_EQ(mp.dv.size(), 401u);
    EXPECT_TRUE(std::is_sorted(mp.cumulative.begin(), mp.cumulative.end()));
    EXPECT_DOUBLE_EQ(mp.cumulative.back(), 1.0);
    const auto peak = std::max_element(mp.density.begin(), mp.density.end()) - mp.density.begin();
    EXPECT_NEAR(mp.dv[peak], dv, 2 * (mp.dv[1] - mp.dv[0]) + 0.01 * rms);
}

TEST(DemMeanPlane, ProfilometerOfSpheresPressedOnTheSurface) {
    // A DEM-like lower half: spheres of radius 2h on every second node, each touching the
    // synthetic surface shifted by dv with its top. The profilometer sees those tops (a quarter of
    // the nodes, d = dv exactly) and caps below the surface in between.
    const HeightMap syn = generate_surface(reference_surface("S5", 3, 129));
    const double h = syn.spacing, r = 2 * h, dv = 0.35e-3;
    std::vector<double> pos, radii;
    for (int j = 0; j < syn.ny; j += 2)
        for (int i = 0; i < syn.nx; i += 2) {
            pos.insert(pos.end(), {i * h, j * h, syn.at(i, j) + dv - r});
            radii.push_back(r);
        }
    const auto dem = profilometer(pos, radii, {syn.nx, syn.ny, h, 0.0, 0.0}, HalfSide::lower);
    EXPECT_EQ(dem.covered, syn.size());
    const DemMeanPlane mp = dem_mean_plane(dem.surface, syn);
    EXPECT_NEAR(mp.shift, dv, 0.01 * rms_of(syn));
    EXPECT_GT(mp.coinciding_fraction, 0.2);
    // Surface particles: those whose top (the node under their centre) the profilometer sees.
    // A few are overtopped there by a neighbour on a steep slope and show only caps below the
    // surface: porosity.
    std::vector<std::int64_t> tops;
    for (int j = 0, p = 0; j < syn.ny; j += 2)
        for (int i = 0; i < syn.nx; i += 2, ++p)
            if (dem.particle[static_cast<std::size_t>(j) * syn.nx + i] == p) tops.push_back(p);
    const auto cls = classify_surface_particles(dem, syn, mp.shift, 1e-3 * rms_of(syn));
    EXPECT_EQ(cls.surface, tops);
    EXPECT_EQ(cls.surface.size() + cls.porosity.size(), dem.particles);
    EXPECT_GT(cls.retained_fraction, 0.99);
}

TEST(SurfaceParticles, DeepParticlesArePorosity) {
    // Small spheres, one per node; every 7th sits 3 rms deeper (seen through a hole).
    const HeightMap syn = generate_surface(reference_surface("S4", 2, 65));
    const double h = syn.spacing, r = 0.45 * h, rms = rms_of(syn), dv = -0.1e-3;
    std::vector<double> pos, radii;
    std::vector<std::int64_t> deep;
    for (int j = 0; j < syn.ny; ++j)
        for (int i = 0; i < syn.nx; ++i) {
            const auto id = static_cast<std::int64_t>(radii.size());
            const bool hole = id % 7 == 0;
            if (hole) deep.push_back(id);
            pos.insert(pos.end(), {i * h, j * h, syn.at(i, j) + dv - r - (hole ? 3 * rms : 0.0)});
            radii.push_back(r);
        }
    const auto dem = profilometer(pos, radii, {syn.nx, syn.ny, h, 0, 0}, HalfSide::lower);
    const DemMeanPlane mp = dem_mean_plane(dem.surface, syn);
    EXPECT_NEAR(mp.shift, dv, 1e-3 * rms);
    const auto cls = classify_surface_particles(dem, syn, mp.shift, 0.5 * rms);
    EXPECT_EQ(cls.porosity, deep);
    EXPECT_EQ(cls.surface.size() + deep.size(), radii.size());
    EXPECT_NEAR(cls.retained_fraction, 1.0 - static_cast<double>(deep.size()) / radii.size(), 1e-12);
    EXPECT_NEAR(cls.node_fraction, cls.retained_fraction, 1e-12);
    // A band wider than the holes keeps everything: why the band has to be chosen.
    EXPECT_EQ(classify_surface_particles(dem, syn, mp.shift, 4 * rms).porosity.size(), 0u);
    EXPECT_THROW(classify_surface_particles(dem, syn, mp.shift, -1.0), Error);
}

TEST(NoiseStudy, HurstFallsAndVarianceGrowsWithTheNoise) {
    const HeightMap syn = generate_surface(reference_surface("S1", 1, 257));
    std::vector<double> levels;
    for (int k = 0; k <= 10; ++k) levels.push_back(0.1 * k);
    const auto study = noise_study(syn, levels, 42);
    ASSERT_EQ(study.size(), levels.size());
    const double s2 = study[0].variance;
    EXPECT_NEAR(study[0].hurst_psd, 0.75, 0.06);
    for (std::size_t k = 1; k < study.size(); ++k) {
        EXPECT_LT(study[k].hurst_psd, study[k - 1].hurst_psd) << "level " << levels[k];
        EXPECT_LT(study[k].hurst_structure, study[k - 1].hurst_structure) << "level " << levels[k];
        EXPECT_GT(study[k].variance, study[k - 1].variance) << "level " << levels[k];
        // Uncorrelated noise adds its variance: s2 (1 + level^2).
        EXPECT_NEAR(study[k].variance / s2, 1 + levels[k] * levels[k], 0.03) << "level " << levels[k];
    }
    std::printf("level  H_psd  H_S    s2/s2_0  r2_psd\n");
    for (const auto& l : study)
        std::printf("%5.2f  %5.3f  %5.3f  %6.3f  %6.4f\n", l.level, l.hurst_psd, l.hurst_structure,
                    l.variance / s2, l.psd_fit_r2);
}

TEST(MapPlot, WritesAPng) {
    if (!io::gnuplot_available()) GTEST_SKIP() << "gnuplot missing";
    const HeightMap m = generate_surface(reference_surface("S5", 1, 65));
    const auto dir = std::filesystem::temp_directory_path() /
                     ("asperity_map_plot_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string file = (dir / "map.png").string();
    plot_height_map_png(m, file, {.title = "S5"});
    std::ifstream in(file, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG");
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace asperity::surface
