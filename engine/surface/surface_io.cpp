// engine/surface/surface_io.cpp - height maps to and from files: HDF5 (C API), CSV and ESRI ASCII
// grids.
//
// Design notes
// - HDF5 layout: dataset `height`, ny x nx IEEE little-endian doubles in metres, row = y
//   index; attributes on the dataset: `spacing` (m), `units` = "m", and for generated maps the
//   generation parameters under their SurfaceParams names (n, side, hurst_x, hurst_y,
//   correlation_length_x, correlation_length_y, variance, variance_x, variance_y, seed, name).
//   A measured scan only needs `height` and `spacing` (or a spacing given at load time).
// - Writing goes to "<path>.tmp" and is renamed over <path> once the file is closed, so readers
//   never see half a file (design.md, Outputs).
// - Doubles are written and read as doubles, so a round trip is bitwise exact. CSV uses
//   std::to_chars' shortest round-trip representation, exact as well.
// - HDF5 handles are owned by a small RAII type; every call's status is checked and turned into a
//   Error naming the file and the step that failed.
#include <hdf5.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "asperity/error.hpp"
#include "asperity/io.hpp"
#include "asperity/surface.hpp"
#include "io/hdf5_file.hpp"

namespace asperity::surface {
namespace {

// ------------------------------------------------------------------------------------------------
// HDF5 helpers

class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer, const std::string& what) : id_(id), closer_(closer) {
    if (id_ < 0) throw Error("HDF5: " + what + " failed");
  }
  ~Handle() { closer_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  Closer closer_;
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw Error("HDF5: " + what + " failed");
}

template <class T>
void write_scalar(hid_t obj, const char* name, hid_t file_type, hid_t mem_type, const T& value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar dataspace");
  Handle attr(H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("creating attribute ") + name);
  check(H5Awrite(attr, mem_type, &value), std::string("writing attribute ") + name);
}

void write_double(hid_t obj, const char* name, double v) {
  write_scalar(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v);
}

void write_string(hid_t obj, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  check(H5Tset_size(type, std::max<std::size_t>(value.size(), 1)), "string size");
  check(H5Tset_strpad(type, H5T_STR_NULLPAD), "string padding");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar dataspace");
  Handle attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("creating attribute ") + name);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  check(H5Awrite(attr, type, padded.data()), std::string("writing attribute ") + name);
}

bool has_attribute(hid_t obj, const char* name) { return H5Aexists(obj, name) > 0; }

template <class T>
T read_scalar(hid_t obj, const char* name, hid_t mem_type) {
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, std::string("opening attribute ") + name);
  T value{};
  check(H5Aread(attr, mem_type, &value), std::string("reading attribute ") + name);
  return value;
}

double read_double(hid_t obj, const char* name) {
  return read_scalar<double>(obj, name, H5T_NATIVE_DOUBLE);
}

// Fixed-length (as written here) or variable-length (as h5py writes) string attribute.
std::string read_string(hid_t obj, const char* name) {
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, std::string("opening attribute ") + name);
  Handle type(H5Aget_type(attr), H5Tclose, "attribute type");
  if (H5Tget_class(type) != H5T_STRING)
    throw Error(std::string("HDF5: attribute ") + name + " is not a string");
  if (H5Tis_variable_str(type) > 0) {
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
    check(H5Tset_size(mem, H5T_VARIABLE), "string size");
    char* text = nullptr;
    check(H5Aread(attr, mem, &text), std::string("reading attribute ") + name);
    std::string value = text ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(type);
  std::string value(size, '\0');
  check(H5Aread(attr, type, value.data()), std::string("reading attribute ") + name);
  value.resize(std::min(value.size(), value.find('\0')));
  return value;
}

// ------------------------------------------------------------------------------------------------
// Text helpers

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> tokens;
  std::string token;
  for (char c : line) {
    if (c == ',' || c == ';' || c == '\t' || c == ' ' || c == '\r') {
      if (!token.empty()) tokens.push_back(std::move(token));
      token.clear();
    } else {
      token.push_back(c);
    }
  }
  if (!token.empty()) tokens.push_back(std::move(token));
  return tokens;
}

bool parse_double(const std::string& token, double& value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && ptr == last;
}

[[noreturn]] void bad_file(const std::string& path, std::size_t line, const std::string& what) {
  throw Error(path + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// HDF5

void save_hdf5(const HeightMap& map, const std::string& path) {
  if (map.height.size() != static_cast<std::size_t>(map.nx) * map.ny || map.nx < 1)
    throw Error("save_hdf5: the map's nx * ny does not match its heights");
  // Built in memory and written with every write checked, under a temporary name renamed over
  // the target only when complete (io.hpp: AtomicFile, h5::create_file).
  io::AtomicFile atomic(path);
  {
    const io::h5::Handle file = io::h5::create_file(atomic.temp_path());
    const hsize_t dims[2] = {static_cast<hsize_t>(map.ny), static_cast<hsize_t>(map.nx)};
    Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose, "dataspace");
    Handle dset(
        H5Dcreate2(file, "height", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose, "creating dataset height");
    check(H5Dwrite(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, map.height.data()),
          "writing dataset height");
    write_double(dset, "spacing", map.spacing);
    write_string(dset, "units", "m");
    if (map.params) {
      const SurfaceParams& p = *map.params;
      write_scalar(dset, "n", H5T_STD_I32LE, H5T_NATIVE_INT, p.n);
      write_double(dset, "side", p.side);
      write_double(dset, "hurst_x", p.hurst_x);
      write_double(dset, "hurst_y", p.hurst_y);
      write_double(dset, "correlation_length_x", p.corr_length_x);
      write_double(dset, "correlation_length_y", p.corr_length_y);
      write_double(dset, "variance", p.variance);
      write_double(dset, "variance_x", p.variance_x);
      write_double(dset, "variance_y", p.variance_y);
      write_scalar(dset, "seed", H5T_STD_U64LE, H5T_NATIVE_UINT64, p.seed);
      write_string(dset, "name", p.name);
    }
    io::h5::write_image(file, atomic.temp_path(), path);
  }
  atomic.commit();
}

HeightMap load_hdf5(const std::string& path, double spacing_override) {
  if (!std::filesystem::exists(path)) throw Error("load_hdf5: no file " + path);
  // Read whole and its header checked first (io::h5::read_checked): HDF5 does not survive every
  // damaged file.
  const io::h5::Handle file = io::h5::open_file_read(path);
  if (H5Lexists(file, "height", H5P_DEFAULT) <= 0)
    throw Error("load_hdf5: " + path + " has no dataset 'height'");
  Handle dset(H5Dopen2(file, "height", H5P_DEFAULT), H5Dclose, "opening dataset height");
  Handle space(H5Dget_space(dset), H5Sclose, "dataset space");
  if (H5Sget_simple_extent_ndims(space) != 2)
    throw Error("load_hdf5: 'height' in " + path + " must be 2-D (ny x nx)");
  hsize_t dims[2];
  H5Sget_simple_extent_dims(space, dims, nullptr);

  HeightMap map;
  map.ny = static_cast<int>(dims[0]);
  map.nx = static_cast<int>(dims[1]);
  map.height.resize(static_cast<std::size_t>(dims[0]) * dims[1]);
  check(H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, map.height.data()),
        "reading dataset height");
  if (spacing_override > 0)
    map.spacing = spacing_override;
  else if (has_attribute(dset, "spacing"))
    map.spacing = read_double(dset, "spacing");
  else
    throw Error("load_hdf5: " + path +
                ": dataset 'height' has no 'spacing' attribute; pass the spacing "
                "(m) to load_hdf5");
  if (!(map.spacing > 0) || !std::isfinite(map.spacing))
    throw Error("load_hdf5: " + path + ": spacing must be finite and > 0");

  if (has_attribute(dset, "hurst_x")) {
    SurfaceParams p;
    p.n = read_scalar<int>(dset, "n", H5T_NATIVE_INT);
    p.side = read_double(dset, "side");
    p.hurst_x = read_double(dset, "hurst_x");
    p.hurst_y = read_double(dset, "hurst_y");
    p.corr_length_x = read_double(dset, "correlation_length_x");
    p.corr_length_y = read_double(dset, "correlation_length_y");
    p.variance = read_double(dset, "variance");
    p.variance_x = read_double(dset, "variance_x");
    p.variance_y = read_double(dset, "variance_y");
    p.seed = read_scalar<std::uint64_t>(dset, "seed", H5T_NATIVE_UINT64);
    if (has_attribute(dset, "name")) p.name = read_string(dset, "name");
    map.params = p;
  }
  return map;
}

// ------------------------------------------------------------------------------------------------
// CSV and ESRI ASCII grids

void save_csv(const HeightMap& map, const std::string& path) {
  if (map.height.size() != static_cast<std::size_t>(map.nx) * map.ny || map.nx < 1)
    throw Error("save_csv: the map's nx * ny does not match its heights");
  {
    std::ostringstream out;
    char buf[32];
    auto number = [&](double v) {
      const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
      return std::string(buf, res.ptr);
    };
    out << "# asperity height map, metres; row = y index (increasing y), column = x index\n";
    out << "# spacing = " << number(map.spacing) << "\n";
    out << "# nx = " << map.nx << ", ny = " << map.ny << "\n";
    std::string line;
    for (int j = 0; j < map.ny; ++j) {
      line.clear();
      for (int i = 0; i < map.nx; ++i) {
        if (i) line.push_back(',');
        line += number(map.at(i, j));
      }
      out << line << '\n';
    }
    // Written under a temporary name with every write checked (io::write_text_file).
    io::write_text_file(path, out.str());
  }
}

HeightMap load_grid(const std::string& path, const GridImportOptions& options) {
  std::ifstream in(path);
  if (!in) throw Error("load_grid: cannot open " + path);
  std::vector<std::vector<double>> rows;
  double file_spacing = 0.0;
  bool esri = false;
  long esri_cols = -1, esri_rows = -1;
  double nodata = std::nan("");
  std::vector<double> esri_values;

  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      // "# spacing = 2.7e-4" (as save_csv writes it)
      std::string body = lower(line.substr(first + 1));
      const auto key = body.find("spacing");
      const auto eq = body.find_first_of("=:", key == std::string::npos ? 0 : key);
      if (key != std::string::npos && eq != std::string::npos) {
        auto tokens = split(body.substr(eq + 1));
        if (tokens.empty() || !parse_double(tokens[0], file_spacing))
          bad_file(path, line_no, "cannot read the spacing value");
      }
      continue;
    }
    auto tokens = split(line);
    if (rows.empty() && esri_values.empty() && !tokens.empty() &&
        std::isalpha(static_cast<unsigned char>(tokens[0][0]))) {
      // ESRI ASCII grid header: "key value" lines before the data.
      const std::string key = lower(tokens[0]);
      double value = 0;
      if (tokens.size() != 2 || !parse_double(tokens[1], value))
        bad_file(path, line_no,
                 "expected numbers (or an ESRI header line 'key value'); comment out "
                 "column headers with '#'");
      esri = true;
      if (key == "ncols")
        esri_cols = static_cast<long>(value);
      else if (key == "nrows")
        esri_rows = static_cast<long>(value);
      else if (key == "cellsize")
        file_spacing = value;
      else if (key == "nodata_value")
        nodata = value;
      else if (key == "xllcorner" || key == "yllcorner" || key == "xllcenter" ||
               key == "yllcenter") { /* the origin does not matter to a height map */
      } else
        bad_file(path, line_no, "unknown ESRI grid header key '" + tokens[0] + "'");
      continue;
    }
    std::vector<double> values;
    for (const auto& t : tokens) {
      double v = 0;
      if (!parse_double(t, v)) bad_file(path, line_no, "'" + t + "' is not a number");
      if (esri && v == nodata)
        bad_file(path, line_no, "missing value (NODATA); fill the gaps before importing");
      values.push_back(v);
    }
    if (esri) {
      esri_values.insert(esri_values.end(), values.begin(), values.end());
    } else {
      if (!rows.empty() && values.size() != rows.front().size())
        bad_file(path, line_no,
                 "row has " + std::to_string(values.size()) + " values, the first row had " +
                     std::to_string(rows.front().size()));
      rows.push_back(std::move(values));
    }
  }

  HeightMap map;
  if (esri) {
    if (esri_cols < 1 || esri_rows < 1)
      throw Error("load_grid: " + path + ": ESRI header needs ncols and nrows");
    if (esri_values.size() != static_cast<std::size_t>(esri_cols * esri_rows))
      throw Error("load_grid: " + path + ": expected " + std::to_string(esri_cols * esri_rows) +
                  " values, found " + std::to_string(esri_values.size()));
    map.nx = static_cast<int>(esri_cols);
    map.ny = static_cast<int>(esri_rows);
    map.height.resize(esri_values.size());
    // ESRI rows run north to south; row 0 of the map is the smallest y.
    for (int j = 0; j < map.ny; ++j)
      for (int i = 0; i < map.nx; ++i)
        map.at(i, j) = esri_values[static_cast<std::size_t>(map.ny - 1 - j) * map.nx + i];
  } else {
    if (rows.empty()) throw Error("load_grid: " + path + " holds no heights");
    map.nx = static_cast<int>(rows.front().size());
    map.ny = static_cast<int>(rows.size());
    map.height.reserve(static_cast<std::size_t>(map.nx) * map.ny);
    for (const auto& r : rows) map.height.insert(map.height.end(), r.begin(), r.end());
  }
  if (options.height_scale != 1.0)
    for (double& z : map.height) z *= options.height_scale;
  map.spacing = options.spacing > 0 ? options.spacing : file_spacing;
  if (!(map.spacing > 0) || !std::isfinite(map.spacing))
    throw Error("load_grid: " + path +
                " gives no spacing ('# spacing = <m>' or ESRI cellsize); set "
                "GridImportOptions.spacing");
  return map;
}

}  // namespace asperity::surface
