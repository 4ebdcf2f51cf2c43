// tests/surface/io_test.cpp - height maps through HDF5, CSV and ESRI ASCII grid files.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "asperity/error.hpp"
#include "asperity/surface.hpp"

namespace asperity::surface {
namespace {

namespace fs = std::filesystem;

class SurfaceIo : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("asperity_surface_io_" + std::to_string(::getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST_F(SurfaceIo, Hdf5RoundTripIsBitwiseExact) {
    SurfaceParams p = reference_surface("S3", 99, 65);
    p.hurst_y = 0.6;
    p.variance_x = 7e-7;
    const HeightMap m = generate_surface(p);
    save_hdf5(m, path("s.h5"));
    EXPECT_FALSE(fs::exists(path("s.h5.tmp")));
    const HeightMap back = load_hdf5(path("s.h5"));
    EXPECT_EQ(back.nx, m.nx);
    EXPECT_EQ(back.ny, m.ny);
    EXPECT_EQ(back.spacing, m.spacing);
    EXPECT_TRUE(bitwise_equal(back.height, m.height));
    ASSERT_TRUE(back.params.has_value());
    const SurfaceParams& q = *back.params;
    EXPECT_EQ(q.n, p.n);
    EXPECT_EQ(q.side, p.side);
    EXPECT_EQ(q.hurst_x, p.hurst_x);
    EXPECT_EQ(q.hurst_y, p.hurst_y);
    EXPECT_EQ(q.corr_length_x, p.corr_length_x);
    EXPECT_EQ(q.corr_length_y, p.corr_length_y);
    EXPECT_EQ(q.variance, p.variance);
    EXPECT_EQ(q.variance_x, p.variance_x);
    EXPECT_EQ(q.variance_y, p.variance_y);
    EXPECT_EQ(q.seed, 99u);
    EXPECT_EQ(q.name, "S3");
}

TEST_F(SurfaceIo, Hdf5MeasuredMapWithoutParameters) {
    HeightMap m(7, 4, 2.5e-5);  // rectangular: ny rows of nx
    for (std::size_t k = 0; k < m.size(); ++k) m.height[k] = 1e-6 * static_cast<double>(k) - 3e-6;
    save_hdf5(m, path("scan.h5"));
    const HeightMap back = load_hdf5(path("scan.h5"));
    EXPECT_EQ(back.nx, 7);
    EXPECT_EQ(back.ny, 4);
    EXPECT_EQ(back.at(6, 1), m.at(6, 1));
    EXPECT_TRUE(bitwise_equal(back.height, m.height));
    EXPECT_FALSE(back.params.has_value());
    EXPECT_EQ(load_hdf5(path("scan.h5"), 1e-3).spacing, 1e-3);
    EXPECT_THROW(load_hdf5(path("missing.h5")), asperity::Error);
    std::ofstream(path("text.h5")) << "not hdf5\n";
    EXPECT_THROW(load_hdf5(path("text.h5")), asperity::Error);
}

TEST_F(SurfaceIo, CsvRoundTripReadsWhatWasWritten) {
    const HeightMap m = generate_surface(reference_surface("S6", 4, 33));
    save_csv(m, path("s.csv"));
    const HeightMap back = load_grid(path("s.csv"));
    EXPECT_EQ(back.nx, m.nx);
    EXPECT_EQ(back.ny, m.ny);
    EXPECT_EQ(back.spacing, m.spacing);  // from "# spacing ="
    EXPECT_TRUE(bitwise_equal(back.height, m.height));
    GridImportOptions o;
    o.spacing = 1e-3;
    o.height_scale = 1e3;  // e.g. heights in mm -> here m to mm
    const HeightMap scaled = load_grid(path("s.csv"), o);
    EXPECT_EQ(scaled.spacing, 1e-3);
    EXPECT_DOUBLE_EQ(scaled.at(3, 2), 1e3 * m.at(3, 2));
}

TEST_F(SurfaceIo, WhitespaceGridAndErrors) {
    std::ofstream(path("g.txt")) << "# a scan\n1 2 3\n\n4\t5\t6\r\n7;8;+9\n";
    GridImportOptions o;
    o.spacing = 0.5e-3;
    const HeightMap g = load_grid(path("g.txt"), o);
    EXPECT_EQ(g.nx, 3);
    EXPECT_EQ(g.ny, 3);
    EXPECT_EQ(g.at(0, 0), 1.0);
    EXPECT_EQ(g.at(2, 1), 6.0);  // row = y index
    EXPECT_EQ(g.at(2, 2), 9.0);
    EXPECT_THROW(load_grid(path("g.txt")), asperity::Error);  // no spacing anywhere
    std::ofstream(path("ragged.csv")) << "1,2,3\n4,5\n";
    try {
        load_grid(path("ragged.csv"), o);
        FAIL();
    } catch (const asperity::Error& e) {
        EXPECT_NE(std::string(e.what()).find("ragged.csv:2"), std::string::npos) << e.what();
    }
    std::ofstream(path("header.csv")) << "x,y,z\n1,2,3\n";
    EXPECT_THROW(load_grid(path("header.csv"), o), asperity::Error);
}

TEST_F(SurfaceIo, EsriAsciiGridIsFlippedToIncreasingY) {
    std::ofstream(path("dem.asc")) << "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\n"
                                      "cellsize 0.001\nNODATA_value -9999\n"
                                      "10 11 12\n"   // northmost row: largest y
                                      "20 21 22\n";
    const HeightMap m = load_grid(path("dem.asc"));
    EXPECT_EQ(m.nx, 3);
    EXPECT_EQ(m.ny, 2);
    EXPECT_EQ(m.spacing, 0.001);
    EXPECT_EQ(m.at(0, 0), 20.0);
    EXPECT_EQ(m.at(2, 1), 12.0);
    std::ofstream(path("gap.asc")) << "ncols 2\nnrows 1\ncellsize 1\nnodata_value -9999\n"
                                      "1 -9999\n";
    EXPECT_THROW(load_grid(path("gap.asc")), asperity::Error);
}

}  // namespace
}  // namespace asperity::surface
