// Output files: what a run leaves behind for people and other programs (design.md "Outputs").
//
//  - JSON summaries, from a small value tree (Json).
//  - Time series (Series): named columns with units, written to HDF5 (one dataset per column,
//    a `units` attribute on each) and to CSV (header `name [unit]`).
//  - Particle snapshots (SnapshotSeries): one HDF5 file per snapshot plus an XDMF file that lists
//    the series, so ParaView opens it as points (and contacts as lines) with attributes.
//  - PNG plots drawn by gnuplot, run as a subprocess on a script file.
//
// Every file is written under a temporary name in the target directory and renamed over the
// target only when complete (AtomicFile): a crash or a Ctrl-C never leaves a half-written file
// under the real name, and a reader (ParaView reloading, a plot script) never sees one.
//
// No HDF5 type appears here: the HDF5 C API is an implementation detail of engine/io/.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "asperity/error.hpp"

namespace asperity {
class World;
}

namespace asperity::io {

// ---------------------------------------------------------------------------------------------
// Files written whole or not at all.

// Opens nothing itself: it names a temporary path beside `target` (same directory, so the final
// rename is atomic) that the caller writes, then commit() renames it over the target. If the
// object dies uncommitted (an exception on the way), the temporary file is removed.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_, temp_;
  bool committed_ = false;
};

void write_text_file(const std::filesystem::path& path, std::string_view contents);
// True when `path` ends with a PNG's IEND chunk: a program that writes PNGs (gnuplot) may exit 0
// after a write failed on a full disk, leaving a truncated image.
bool is_complete_png(const std::filesystem::path& path);
// Writes `bytes` to `temp` (an AtomicFile's temporary path) with every write and the close
// checked, so that a full disk or a file-size limit is an Error naming `target`, never a short
// file that looks complete. sync: also flush it to the device before returning (checkpoints).
void write_bytes(const std::filesystem::path& temp, std::span<const unsigned char> bytes,
                 const std::string& target, bool sync = false);
// mkdir -p; an existing directory is fine, an existing file of that name is an Error.
void make_directories(const std::filesystem::path& path);

// ---------------------------------------------------------------------------------------------
// JSON

struct Json {
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;  // keeps the order given
  std::variant<std::nullptr_t, bool, std::int64_t, double, std::string, Array, Object> value;

  Json() : value(nullptr) {}
  Json(std::nullptr_t) : value(nullptr) {}
  Json(bool b) : value(b) {}
  Json(int i) : value(std::int64_t{i}) {}
  Json(std::int64_t i) : value(i) {}
  Json(double d) : value(d) {}
  Json(const char* s) : value(std::string(s)) {}
  Json(std::string s) : value(std::move(s)) {}
  Json(Array a) : value(std::move(a)) {}
  Json(Object o) : value(std::move(o)) {}
};

// Non-finite numbers have no JSON spelling; they are written as null.
std::string to_json_text(const Json& value, int indent = 2);
void write_json(const std::filesystem::path& path, const Json& value);

// ---------------------------------------------------------------------------------------------
// Columns, CSV

struct Column {
  std::string name;
  std::string unit;  // "" for dimensionless
  std::vector<double> values;
  std::string label() const { return unit.empty() ? name : name + " [" + unit + "]"; }
};

// Header row `name [unit],...`; each value in the shortest text that reads back exactly. Columns
// of unequal length leave the missing cells empty.
void write_csv(const std::filesystem::path& path, std::span<const Column> columns);

// Scalar attributes (run parameters, units, step, ...) attached to an HDF5 file.
using Attribute = std::variant<double, std::int64_t, std::string>;
using Attributes = std::vector<std::pair<std::string, Attribute>>;

// ---------------------------------------------------------------------------------------------
// Time series

class Series {
 public:
  // (name, unit) per column. Names must be unique, non-empty and contain no '/'.
  explicit Series(std::vector<std::pair<std::string, std::string>> columns);

  std::size_t column_count() const { return columns_.size(); }
  std::size_t row_count() const { return columns_.empty() ? 0 : columns_[0].values.size(); }
  // Index of the column called `name`, or -1.
  int find(std::string_view name) const;
  const Column& column(std::size_t i) const { return columns_.at(i); }
  std::span<const Column> columns() const { return columns_; }
  // One value per column, in column order.
  void append_row(std::span<const double> row);
  void clear();

  Attributes& attributes() { return attributes_; }
  const Attributes& attributes() const { return attributes_; }

  // One 1-D float64 dataset per column at the root, with a `units` attribute; the root carries
  // the series' attributes and `columns` (the names in order, comma separated).
  void write_hdf5(const std::filesystem::path& path) const;
  void write_csv(const std::filesystem::path& path) const;

 private:
  std::vector<Column> columns_;
  Attributes attributes_;
};

// ---------------------------------------------------------------------------------------------
// Snapshots

struct Snapshot {
  std::uint64_t step = 0;
  double time = 0;
  std::int64_t id_base = 0;  // added to the engine's ids (the Lua layer numbers from 1)
  // Particles, in id order; vectors as x0,y0,z0,x1,...
  std::vector<std::int64_t> id;
  std::vector<double> position, velocity, radius;
  std::vector<std::int32_t> group;  // -1: none (group ids shifted by id_base like particle ids)
  std::vector<std::int32_t> tag;    // the world's per-particle tag (not shifted)
  std::vector<double> force, angular_velocity;  // N, rad/s, as x0,y0,z0,x1,...
  // Since the first snapshot of the series, per particle (filled by SnapshotSeries::write).
  std::vector<double> displacement;
  // Touching ball-ball pairs. index_a/b are rows of the particle arrays (what XDMF lines need);
  // id_a/b are particle ids.
  bool has_contacts = false;
  std::vector<std::int64_t> id_a, id_b;
  std::vector<std::int32_t> index_a, index_b;
  std::vector<double> normal, point, overlap, normal_force, shear_force;
  // Intact bonds (when the world has any), same conventions as contacts.
  bool has_bonds = false;
  std::vector<std::int64_t> bond_id_a, bond_id_b;
  std::vector<std::int32_t> bond_index_a, bond_index_b;
  std::vector<double> bond_normal_force, bond_shear_force, bond_sigma, bond_tau, bond_gap;
  std::vector<std::int32_t> bond_holds;  // 1 the beam, 2 the contact bond, 3 both (model.md 5)
  Attributes attributes;
  Attributes particle_attributes;  // on /particles (the keys of group and tag)
  // The XDMF time of this snapshot when the series is indexed by something other than the
  // simulated time (e.g. the shear displacement in mm); unset: `time`.
  std::optional<double> index_time;
};

// Reads the world through its public API (bonds whenever the world has any). id_base: see
// Snapshot.
Snapshot take_snapshot(const World& world, bool with_contacts, std::int64_t id_base = 0);

// Keeps only the particles with keep[row] true (rows in the snapshot's order); contacts and bonds
// with a dropped particle go too, and the remaining ones' rows are renumbered.
void drop_particles(Snapshot& snapshot, const std::vector<bool>& keep);

// Layout: /particles/{id,position,velocity,radius,group,tag,force,angular_velocity,
// displacement,index}, /contacts/{id_a,id_b,pair,
// normal,point,overlap,normal_force,shear_force}, /bonds/{id_a,id_b,pair,normal_force,
// shear_force,sigma,tau,gap}; root attributes step, time, id_base and the snapshot's own.
// Dimensional datasets have a `units` attribute.
void write_snapshot_hdf5(const std::filesystem::path& path, const Snapshot& snapshot);

// A directory of NAME_000000.h5, NAME_000001.h5, ... and NAME.xdmf (particles as points) plus,
// when contacts are written, NAME_contacts.xdmf (contacts as lines between particle centres),
// and with bonds NAME_bonds.xdmf.
// The XDMF files are rewritten (atomically) after every snapshot so they are always complete.
// A new series removes the files of an earlier series of the same name in the directory
// (NAME_NNNNNN.h5 and NAME*.xdmf), so a rerun never mixes its snapshots with stale ones.
// Each snapshot gets the displacement of every particle since the series' first snapshot (by id;
// zero for a particle first seen later).
struct SnapshotSeriesOptions {
  std::string time_label;   // what the XDMF time is, e.g. "shear displacement (mm)"; "" = time (s)
  Attributes keys;          // legends written on /particles, e.g. {"group_key", "1: lower platen"}
  // Continue a series whose first `keep` snapshots a run interrupted earlier wrote (a resumed
  // run): they are read back (index, and the first positions the displacements are measured
  // from) and any later files removed. 0: a new series, every file of the name removed.
  std::size_t keep = 0;
};
class SnapshotSeries {
 public:
  SnapshotSeries(std::filesystem::path directory, std::string name, SnapshotSeriesOptions options = {});
  std::filesystem::path write(Snapshot snapshot);
  std::size_t count() const { return entries_.size(); }
  std::filesystem::path xdmf_path() const;
  std::filesystem::path contacts_xdmf_path() const;
  std::filesystem::path bonds_xdmf_path() const;

 private:
  struct Entry {
    std::string file;
    std::uint64_t step;
    double time;  // the index time (see Snapshot::index_time)
    std::size_t particles, contacts, bonds;
    bool has_contacts, has_bonds;
  };
  void write_xdmf() const;
  std::string file_name(std::size_t index) const;
  std::filesystem::path directory_;
  std::string name_;
  SnapshotSeriesOptions options_;
  std::vector<Entry> entries_;
  std::unordered_map<std::int64_t, std::array<double, 3>> reference_;  // first position, by id
};

// ---------------------------------------------------------------------------------------------
// Reading HDF5 back (tests, scripts that post-process)

// Full paths of every dataset in the file ("/particles/position"), sorted.
std::vector<std::string> hdf5_datasets(const std::filesystem::path& path);
std::vector<std::size_t> hdf5_shape(const std::filesystem::path& path, const std::string& dataset);
// Any numeric dataset, converted to double, flattened in row-major order.
std::vector<double> read_hdf5(const std::filesystem::path& path, const std::string& dataset);
// Attribute of a dataset or group ("/" for the file); nullopt if it does not exist.
std::optional<Attribute> read_hdf5_attribute(const std::filesystem::path& path,
                                             const std::string& object, const std::string& name);

// ---------------------------------------------------------------------------------------------
// Plots

struct PlotOptions {
  std::string title;
  std::string xlabel, ylabel;  // default: from the columns' names and units
  bool logx = false, logy = false;
  int width = 900, height = 600;  // pixels
  bool points = false;            // markers instead of lines
};

// Draws ys against x into a PNG with gnuplot. Throws Error if gnuplot is missing or fails
// (its message is included).
void plot_png(const std::filesystem::path& path, const Column& x, std::span<const Column> ys,
              const PlotOptions& options = {});
bool gnuplot_available();

}  // namespace asperity::io
