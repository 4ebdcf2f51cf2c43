// HDF5 helpers: RAII handles, typed dataset and attribute writers, and the read-back functions
// of io.hpp. Only the long-stable part of the C API is used (no H5Ovisit3 / H5Oget_info3), so
// the code builds against HDF5 1.10 (Debian 12) and 1.12+.
#include "io/hdf5_file.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>

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

Handle create_file(const std::filesystem::path& path) {
  quiet_errors();
  Handle props(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_link_creation_order(props, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  if (H5Pset_userblock(props, kHeaderBytes) < 0) fail(path.string(), "bad user block size");
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (H5Pset_fapl_core(access, 1 << 20, 0) < 0) fail(path.string(), "cannot set up an in-memory file");
  Handle f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, props, access), H5Fclose);
  if (!f.valid()) fail(path.string(), "cannot create");
  return f;
}

namespace {
constexpr unsigned char kHdf5Signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
constexpr std::size_t kMagicBytes = 24;  // then the size at 24, the checksum at 32

// 64-bit checksum, four interleaved lanes of 8-byte words (fast on large files). Each step
// h -> rotl(h ^ w, 29) * odd is a bijection in w and in h, so a change of any one word always
// changes the result; several changes go unnoticed with probability ~2^-64.
std::uint64_t checksum(const unsigned char* data, std::size_t n) {
  constexpr std::uint64_t kOdd = 0x9e3779b97f4a7c15ULL;
  std::uint64_t h[4] = {0x243f6a8885a308d3ULL, 0x13198a2e03707344ULL, 0xa4093822299f31d0ULL,
                        0x082efa98ec4e6c89ULL};
  auto mix = [](std::uint64_t x, std::uint64_t w) { return std::rotl(x ^ w, 29) * kOdd; };
  std::size_t i = 0;
  for (; i + 32 <= n; i += 32)
    for (int l = 0; l < 4; ++l) {
      std::uint64_t w;
      std::memcpy(&w, data + i + 8 * l, 8);
      h[l] = mix(h[l], w);
    }
  for (; i < n; ++i) h[0] = mix(h[0], data[i]);
  std::uint64_t r = n;
  for (int l = 0; l < 4; ++l) r = mix(r, h[l]);
  return r ^ (r >> 31);
}

void put_u64(unsigned char* at, std::uint64_t v) {
  for (int k = 0; k < 8; ++k) at[k] = static_cast<unsigned char>(v >> (8 * k));
}
std::uint64_t get_u64(const unsigned char* at) {
  std::uint64_t v = 0;
  for (int k = 0; k < 8; ++k) v |= std::uint64_t(at[k]) << (8 * k);
  return v;
}
}  // namespace

std::vector<unsigned char> file_image(hid_t file, const std::string& name, const char* magic) {
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) fail(name, "flush failed");
  const ssize_t size = H5Fget_file_image(file, nullptr, 0);
  if (size <= 0) fail(name, "cannot take the file image");
  // The core driver's image may start at the superblock, without the user block (HDF5 1.10), or
  // hold the user block too: either way the file is the header and then the superblock. Taken
  // behind room for the header, so that the first case needs no second copy (a checkpoint of a
  // 10 cm joint is 120 MB, and the core driver holds one more).
  const std::size_t bytes = static_cast<std::size_t>(size);
  std::vector<unsigned char> image(kHeaderBytes + bytes);
  if (H5Fget_file_image(file, image.data() + kHeaderBytes, bytes) != size) fail(name, "cannot take the file image");
  const bool with_user_block = bytes >= kHeaderBytes + 8 && std::memcmp(image.data() + 2 * kHeaderBytes, kHdf5Signature, 8) == 0;
  if (with_user_block) {
    std::memmove(image.data(), image.data() + kHeaderBytes, bytes);
    image.resize(bytes);
  }
  if (image.size() < kHeaderBytes + 8 || std::memcmp(image.data() + kHeaderBytes, kHdf5Signature, 8) != 0)
    fail(name, "unexpected HDF5 file image");
  std::memset(image.data(), 0, kHeaderBytes);
  std::memcpy(image.data(), magic, std::min(std::strlen(magic), kMagicBytes - 1));
  put_u64(image.data() + 24, image.size() - kHeaderBytes);
  put_u64(image.data() + 32, checksum(image.data() + kHeaderBytes, image.size() - kHeaderBytes));
  return image;
}

void write_image(hid_t file, const std::filesystem::path& temp, const std::string& name, const char* magic,
                 bool sync) {
  const std::vector<unsigned char> image = file_image(file, name, magic);
  write_bytes(temp, image, name, sync);
}

std::vector<unsigned char> read_checked(const std::filesystem::path& path, const char* magic, bool* had_header) {
  const std::string name = path.string();
  std::vector<unsigned char> bytes;
  {
    // Sized once and read in one call (filled through an iterator, the vector grew by doubling:
    // two buffers of the file's size at once, and a third byte by byte).
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) fail(name, "does not exist or cannot be read");
    const std::streamoff size = in.tellg();
    if (size < 0) fail(name, "cannot tell its size");
    bytes.resize(static_cast<std::size_t>(size));
    in.seekg(0);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) fail(name, "read error");
  }
  const bool foreign = bytes.size() >= 8 && std::memcmp(bytes.data(), kHdf5Signature, 8) == 0;
  if (had_header) *had_header = !foreign;
  if (foreign) return bytes;  // not ours (or older): HDF5 checks it as well as it can
  const bool ours = bytes.size() >= kHeaderBytes && std::memcmp(bytes.data(), "asperity ", 9) == 0;
  const std::size_t magic_length = magic ? std::strlen(magic) : 0;
  if (!ours || (magic && std::memcmp(bytes.data(), magic, magic_length) != 0))
    fail(name, magic ? "not an HDF5 file with a header '" + std::string(magic, magic_length - 1) + "'"
                     : std::string("not an HDF5 file"));
  const std::uint64_t size = get_u64(bytes.data() + 24), sum = get_u64(bytes.data() + 32);
  if (size != bytes.size() - kHeaderBytes)
    fail(name, "truncated or damaged: " + std::to_string(bytes.size()) + " bytes, the header says " +
                   std::to_string(size + kHeaderBytes));
  if (sum != checksum(bytes.data() + kHeaderBytes, bytes.size() - kHeaderBytes))
    fail(name, "damaged: its checksum does not match its contents");
  return bytes;
}

namespace {
// HDF5's core driver copies an image twice by default (into the property list, then into the
// open file). These callbacks hand it our bytes instead (udata: their address), for a file
// opened read only: nothing is ever allocated, resized or freed by HDF5, and the handle keeps
// the bytes until the file is closed.
void* image_in_place(std::size_t, H5FD_file_image_op_t op, void* udata) {
  const bool ours = op == H5FD_FILE_IMAGE_OP_PROPERTY_LIST_SET || op == H5FD_FILE_IMAGE_OP_PROPERTY_LIST_COPY ||
                    op == H5FD_FILE_IMAGE_OP_FILE_OPEN;
  return ours ? udata : nullptr;  // a copy handed out (H5Pget_file_image) or a resize: refused
}
void* copy_in_place(void* dest, const void* src, std::size_t size, H5FD_file_image_op_t, void*) {
  if (dest != src) std::memcpy(dest, src, size);
  return dest;
}
herr_t free_nothing(void*, H5FD_file_image_op_t, void*) { return 0; }
void* share_udata(void* udata) { return udata; }
herr_t keep_udata(void*) { return 0; }
}  // namespace

Handle open_image(std::vector<unsigned char> bytes, const std::filesystem::path& path) {
  quiet_errors();
  auto image = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  void* at = const_cast<unsigned char*>(image->data());
  H5FD_file_image_callbacks_t in_place = {image_in_place, copy_in_place, nullptr, free_nothing,
                                          share_udata, keep_udata, at};
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  // Closing the file closes what is still open in it: nothing reads the bytes after the handle.
  if (H5Pset_fapl_core(access, 1 << 20, 0) < 0 || H5Pset_fclose_degree(access, H5F_CLOSE_STRONG) < 0 ||
      H5Pset_file_image_callbacks(access, &in_place) < 0 || H5Pset_file_image(access, at, image->size()) < 0)
    fail(path.string(), "cannot set up an in-memory file");
  // The core driver refuses a name that exists on disk when it opens an image (`path` is a file,
  // so nothing can exist below it), and HDF5 shares one open file among openings of one name
  // (this one reads our bytes: their address makes each opening its own file).
  const std::string image_name = path.string() + "/(in memory at " + std::to_string(reinterpret_cast<std::uintptr_t>(at)) + ")";
  Handle f(H5Fopen(image_name.c_str(), H5F_ACC_RDONLY, access), H5Fclose, std::move(image));
  if (!f.valid()) fail(path.string(), "cannot open (not an HDF5 file?)");
  return f;
}

Handle open_file_read(const std::filesystem::path& path) {
  quiet_errors();
  if (!std::filesystem::exists(path)) fail(path.string(), "does not exist");
  return open_image(read_checked(path), path);
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
