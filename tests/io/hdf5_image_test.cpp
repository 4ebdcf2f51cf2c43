// Files opened from their bytes in memory (io::h5::open_image): HDF5 reads our bytes in place,
// and nothing reads them once the file's handle is closed.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "io/hdf5_file.hpp"

using namespace asperity;

namespace {
std::filesystem::path written(const char* name, const std::vector<double>& values) {
  const auto path = std::filesystem::temp_directory_path() / name;
  {
    io::AtomicFile file(path);
    {
      const io::h5::Handle h = io::h5::create_file(file.temp_path());
      io::h5::write_doubles(h, "values", values, 0, "m", path.string());
      io::h5::write_image(h, file.temp_path(), path.string());
    }
    file.commit();
  }
  return path;
}

std::vector<double> read_values(hid_t set, std::size_t n) {
  std::vector<double> out(n, -1.0);
  if (H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0) return {};
  return out;
}
}  // namespace

TEST(Hdf5Image, ReadsTheBytesItKeepsAndNothingAfterTheClose) {
  std::vector<double> values(50000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.5 * double(i) - 3.0;
  const auto path = written("asperity_hdf5_image_test.h5", values);

  io::h5::Handle file = io::h5::open_file_read(path);  // the bytes read are the handle's alone
  ASSERT_TRUE(file.valid());
  io::h5::Handle set(H5Dopen2(file, "values", H5P_DEFAULT), H5Dclose);
  ASSERT_TRUE(set.valid());
  EXPECT_EQ(read_values(set, values.size()), values);
  // Moved, the handle keeps the bytes with it.
  io::h5::Handle moved = std::move(file);
  EXPECT_FALSE(file.valid());
  EXPECT_EQ(read_values(set, values.size()), values);
  // Closed while a dataset of it is still open: the dataset goes with it (the bytes are freed
  // now; a read of them would be a use after free, which the sanitizer build reports).
  moved.reset();
  EXPECT_TRUE(read_values(set, values.size()).empty());
  std::filesystem::remove(path);
}

TEST(Hdf5Image, TwoOpeningsOfOneFileAreIndependent) {
  const std::vector<double> values{1.0, 2.0, 3.0};
  const auto path = written("asperity_hdf5_image_twice.h5", values);
  io::h5::Handle first = io::h5::open_file_read(path);
  io::h5::Handle second = io::h5::open_file_read(path);
  first.reset();
  io::h5::Handle set(H5Dopen2(second, "values", H5P_DEFAULT), H5Dclose);
  ASSERT_TRUE(set.valid());
  EXPECT_EQ(read_values(set, values.size()), values);
  std::filesystem::remove(path);
}
