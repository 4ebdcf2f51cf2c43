// Thin RAII over the HDF5 C API, private to engine/io/.
//
// Every hid_t is owned by a Handle that closes it with the matching H5?close; errors become
// asperity::Error with the file name in the message. HDF5's own error printing is switched off
// (it writes a stack dump to stderr for things we handle, such as probing for an attribute).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "asperity/io.hpp"

namespace asperity::io::h5 {

class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

void quiet_errors();

// A new file for writing, built in memory (HDF5's core driver without a backing store) and put on
// disk by write_image: HDF5 itself then never writes to the disk, so a full disk is an error of
// ours, raised before the rename. (A failed H5Fclose on a full disk leaves HDF5 with a file it
// cannot close, and its clean-up at exit crashes.) Tracks link creation order so datasets list
// in the order they were written. userblock: bytes reserved at the start (0, or a power of two
// >= 512) for a header of the caller's.
Handle create_file(const std::filesystem::path& path, std::size_t userblock = 0);
// The complete file image of a file from create_file (flushed first).
std::vector<unsigned char> file_image(hid_t file, const std::string& name);
// file_image written to `temp` (an AtomicFile's temporary path) with every write checked.
void write_image(hid_t file, const std::filesystem::path& temp, const std::string& name);
Handle open_file_read(const std::filesystem::path& path);
Handle create_group(hid_t parent, const std::string& name, const std::string& file);

// 1-D (cols == 0) or 2-D (rows x cols) datasets, with a `units` attribute when unit is given.
void write_doubles(hid_t parent, const std::string& name, std::span<const double> data,
                   std::size_t cols, const std::string& unit, const std::string& file);
void write_int64(hid_t parent, const std::string& name, std::span<const std::int64_t> data,
                 std::size_t cols, const std::string& unit, const std::string& file);
void write_int32(hid_t parent, const std::string& name, std::span<const std::int32_t> data,
                 std::size_t cols, const std::string& unit, const std::string& file);

void write_attribute(hid_t object, const std::string& name, const Attribute& value,
                     const std::string& file);
void write_attributes(hid_t object, const Attributes& attributes, const std::string& file);

}  // namespace asperity::io::h5
