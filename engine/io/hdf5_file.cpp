// HDF5 helpers: RAII handles, typed dataset and attribute writers, and the read-back functions
// of io.hpp. Only the long-stable part of the C API is used (no H5Ovisit3 / H5Oget_info3), so
// the code builds against HDF5 1.10 (Debian 12) and 1.12+.
#include "io/hdf5_file.hpp"

#include <algorithm>
#include <cstring>

namespace asperity::io::h5 {

namespace {
[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw Error("HDF5 file '" + file + "': " + what);
}

Handle dataspace(std::size_t n, std::size_t cols) {
  hsize_t dims[2] = {static_cast<hsize_t>(n), static_cast<hsize_t>(cols)};
  return Handle(H5Screate_simple(cols ? 2 : 1, dims, nullptr), H5Sclose);
}

template <class T>
void write_dataset(hid_t parent, const std::string& name, std::span<const T> data,
                   std::size_t cols, const std::string& unit, const std::string& file,
                   hid_t file_type, hid_t mem_type) {
  std::size_t rows = cols ? data.size() / cols : data.size();
  if (cols && rows * cols != data.size()) fail(file, "dataset " + name + ": ragged rows");
  Handle space = dataspace(rows, cols);
  Handle set(H5Dcreate2(parent, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT,
                        H5P_DEFAULT),
             H5Dclose);
  if (!set.valid()) fail(file, "cannot create dataset " + name);
  if (!data.empty() && H5Dwrite(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(file, "cannot write dataset " + name);
  if (!unit.empty()) write_attribute(set, "units", std::string(unit), file);
}
}  // namespace

void quiet_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Handle create_file(const std::filesystem::path& path, std::size_t userblock) {
  quiet_errors();
  Handle props(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_link_creation_order(props, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  if (userblock > 0 && H5Pset_userblock(props, userblock) < 0) fail(path.string(), "bad user block size");
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (H5Pset_fapl_core(access, 1 << 20, 0) < 0) fail(path.string(), "cannot set up an in-memory file");
  Handle f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, props, access), H5Fclose);
  if (!f.valid()) fail(path.string(), "cannot create");
  return f;
}

std::vector<unsigned char> file_image(hid_t file, const std::string& name) {
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) fail(name, "flush failed");
  const ssize_t size = H5Fget_file_image(file, nullptr, 0);
  if (size <= 0) fail(name, "cannot take the file image");
  std::vector<unsigned char> image(static_cast<std::size_t>(size));
  if (H5Fget_file_image(file, image.data(), image.size()) != size) fail(name, "cannot take the file image");
  return image;
}

void write_image(hid_t file, const std::filesystem::path& temp, const std::string& name) {
  const std::vector<unsigned char> image = file_image(file, name);
  write_bytes(temp, image, name);
}

Handle open_file_read(const std::filesystem::path& path) {
  quiet_errors();
  if (!std::filesystem::exists(path)) fail(path.string(), "does not exist");
  Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!f.valid()) fail(path.string(), "cannot open (not an HDF5 file?)");
  return f;
}

Handle create_group(hid_t parent, const std::string& name, const std::string& file) {
  Handle props(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_link_creation_order(props, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  Handle g(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, props, H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail(file, "cannot create group " + name);
  return g;
}

void write_doubles(hid_t parent, const std::string& name, std::span<const double> data,
                   std::size_t cols, const std::string& unit, const std::string& file) {
  write_dataset(parent, name, data, cols, unit, file, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);
}
void write_int64(hid_t parent, const std::string& name, std::span<const std::int64_t> data,
                 std::size_t cols, const std::string& unit, const std::string& file) {
  write_dataset(parent, name, data, cols, unit, file, H5T_STD_I64LE, H5T_NATIVE_INT64);
}
void write_int32(hid_t parent, const std::string& name, std::span<const std::int32_t> data,
                 std::size_t cols, const std::string& unit, const std::string& file) {
  write_dataset(parent, name, data, cols, unit, file, H5T_STD_I32LE, H5T_NATIVE_INT32);
}

void write_attribute(hid_t object, const std::string& name, const Attribute& value,
                     const std::string& file) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  herr_t status = -1;
  if (auto* d = std::get_if<double>(&value)) {
    Handle a(H5Acreate2(object, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
    if (a.valid()) status = H5Awrite(a, H5T_NATIVE_DOUBLE, d);
  } else if (auto* i = std::get_if<std::int64_t>(&value)) {
    Handle a(H5Acreate2(object, name.c_str(), H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
    if (a.valid()) status = H5Awrite(a, H5T_NATIVE_INT64, i);
  } else {
    // Variable-length UTF-8: h5py and ParaView read these as ordinary strings.
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    const char* text = std::get<std::string>(value).c_str();
    Handle a(H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (a.valid()) status = H5Awrite(a, type, &text);
  }
  if (status < 0) fail(file, "cannot write attribute " + name);
}

void write_attributes(hid_t object, const Attributes& attributes, const std::string& file) {
  for (const auto& [name, value] : attributes) write_attribute(object, name, value, file);
}

}  // namespace asperity::io::h5

namespace asperity::io {

using h5::Handle;

namespace {
herr_t collect_dataset(hid_t group, const char* name, const H5L_info_t*, void* out) {
  hid_t obj = H5Oopen(group, name, H5P_DEFAULT);
  if (obj >= 0) {
    if (H5Iget_type(obj) == H5I_DATASET)
      static_cast<std::vector<std::string>*>(out)->push_back("/" + std::string(name));
    H5Oclose(obj);
  }
  return 0;
}

Handle open_dataset(hid_t file, const std::string& dataset, const std::string& path) {
  if (H5Lexists(file, dataset.c_str(), H5P_DEFAULT) <= 0)
    throw Error("HDF5 file '" + path + "': no dataset " + dataset);
  Handle set(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw Error("HDF5 file '" + path + "': " + dataset + " is not a dataset");
  return set;
}
}  // namespace

std::vector<std::string> hdf5_datasets(const std::filesystem::path& path) {
  Handle f = h5::open_file_read(path);
  std::vector<std::string> names;
  H5Lvisit(f, H5_INDEX_NAME, H5_ITER_INC, collect_dataset, &names);
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::size_t> hdf5_shape(const std::filesystem::path& path,
                                    const std::string& dataset) {
  Handle f = h5::open_file_read(path);
  Handle set = open_dataset(f, dataset, path.string());
  Handle space(H5Dget_space(set), H5Sclose);
  int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return {dims.begin(), dims.end()};
}

std::vector<double> read_hdf5(const std::filesystem::path& path, const std::string& dataset) {
  Handle f = h5::open_file_read(path);
  Handle set = open_dataset(f, dataset, path.string());
  Handle type(H5Dget_type(set), H5Tclose);
  H5T_class_t cls = H5Tget_class(type);
  if (cls != H5T_INTEGER && cls != H5T_FLOAT)
    throw Error("HDF5 file '" + path.string() + "': dataset " + dataset + " is not numeric");
  Handle space(H5Dget_space(set), H5Sclose);
  hssize_t n = H5Sget_simple_extent_npoints(space);
  std::vector<double> out(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
  // HDF5 converts integers to double on read.
  if (!out.empty() && H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    throw Error("HDF5 file '" + path.string() + "': cannot read " + dataset);
  return out;
}

std::optional<Attribute> read_hdf5_attribute(const std::filesystem::path& path,
                                             const std::string& object, const std::string& name) {
  Handle f = h5::open_file_read(path);
  if (object != "/" && H5Lexists(f, object.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
  if (H5Aexists_by_name(f, object.c_str(), name.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
  Handle a(H5Aopen_by_name(f, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Handle type(H5Aget_type(a), H5Tclose);
  std::string where = "HDF5 file '" + path.string() + "': attribute " + object + "@" + name;
  switch (H5Tget_class(type)) {
    case H5T_INTEGER: {
      std::int64_t v = 0;
      if (H5Aread(a, H5T_NATIVE_INT64, &v) < 0) throw Error(where + ": cannot read");
      return Attribute{v};
    }
    case H5T_FLOAT: {
      double v = 0;
      if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0) throw Error(where + ": cannot read");
      return Attribute{v};
    }
    case H5T_STRING: {
      if (H5Tis_variable_str(type) > 0) {
        char* text = nullptr;
        if (H5Aread(a, type, &text) < 0) throw Error(where + ": cannot read");
        std::string s = text ? text : "";
        H5free_memory(text);
        return Attribute{s};
      }
      std::string s(H5Tget_size(type), '\0');
      if (H5Aread(a, type, s.data()) < 0) throw Error(where + ": cannot read");
      s.resize(std::strlen(s.c_str()));
      return Attribute{s};
    }
    default:
      throw Error(where + ": unsupported type (only numbers and strings)");
  }
}

}  // namespace asperity::io
