// Thin RAII over the HDF5 C API, private to engine/io/.
//
// Every hid_t is owned by a Handle that closes it with the matching H5?close; errors become
// asperity::Error with the file name in the message. HDF5's own error printing is switched off
// (it writes a stack dump to stderr for things we handle, such as probing for an attribute).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <memory>
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
  // A file opened on bytes in memory (open_image) keeps them until it is closed.
  Handle(hid_t id, Closer close, std::shared_ptr<const std::vector<unsigned char>> image)
      : id_(id), close_(close), image_(std::move(image)) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_), image_(std::move(o.image_)) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      image_ = std::move(o.image_);
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
    image_.reset();  // after the close: HDF5 reads the file from it until then
  }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
  std::shared_ptr<const std::vector<unsigned char>> image_;
};

void quiet_errors();

// A new file for writing, built in memory (HDF5's core driver without a backing store) and put on
// disk by write_image: HDF5 itself then never writes to the disk, so a full disk is an error of
// ours, raised before the rename. (A failed H5Fclose on a full disk leaves HDF5 with a file it
// cannot close, and its clean-up at exit crashes.) Tracks link creation order so datasets list
// in the order they were written. The first kHeaderBytes are HDF5's user block (HDF5 finds its
// superblock after it; h5py, h5dump and ParaView read the file as usual), for write_image's header.
Handle create_file(const std::filesystem::path& path);

// The header in the user block: a magic line naming the kind of file ("asperity hdf5\n",
// "asperity checkpoint\n"; at most 23 bytes), the byte count of the rest and its checksum, so
// that a damaged file is refused before HDF5 parses it: HDF5 1.10 does not survive every
// corruption of its own metadata (it frees wild pointers).
inline constexpr std::size_t kHeaderBytes = 512;
inline constexpr const char* kFileMagic = "asperity hdf5\n";

// The complete image of a file from create_file, with the header filled in.
std::vector<unsigned char> file_image(hid_t file, const std::string& name, const char* magic = kFileMagic);
// file_image written to `temp` (an AtomicFile's temporary path) with every write checked;
// sync: flushed to the device too.
void write_image(hid_t file, const std::filesystem::path& temp, const std::string& name,
                 const char* magic = kFileMagic, bool sync = false);

// A whole file read for opening, its header checked when it has one (files written by other
// programs have none: they start with HDF5's signature). `magic`: the kind required (nullptr:
// any asperity header, or none). *had_header tells which it was.
std::vector<unsigned char> read_checked(const std::filesystem::path& path, const char* magic = nullptr,
                                        bool* had_header = nullptr);
// A file opened (read only) from bytes of read_checked, which the handle keeps: HDF5 reads them
// in place, without a copy of its own.
Handle open_image(std::vector<unsigned char> bytes, const std::filesystem::path& path);

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
