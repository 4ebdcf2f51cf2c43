// Time series: columns held in memory while the run goes, written whole at the end (or whenever
// the script asks). Recording a row costs one push_back per column; a run of 10^6 steps recorded
// every 100 steps is 10^4 rows, nothing next to the particles.
#include <unordered_set>

#include "asperity/io.hpp"
#include "io/hdf5_file.hpp"

namespace asperity::io {

Series::Series(std::vector<std::pair<std::string, std::string>> columns) {
  std::unordered_set<std::string> seen;
  for (auto& [name, unit] : columns) {
    if (name.empty()) throw Error("series: a column has an empty name");
    if (name.find('/') != std::string::npos)
      throw Error("series: column name '" + name + "' contains '/' (not allowed in HDF5 names)");
    if (!seen.insert(name).second) throw Error("series: column '" + name + "' given twice");
    columns_.push_back(Column{std::move(name), std::move(unit), {}});
  }
  if (columns_.empty()) throw Error("series: give at least one column");
}

int Series::find(std::string_view name) const {
  for (std::size_t i = 0; i < columns_.size(); ++i)
    if (columns_[i].name == name) return static_cast<int>(i);
  return -1;
}

void Series::append_row(std::span<const double> row) {
  if (row.size() != columns_.size())
    throw Error("series: a row needs " + std::to_string(columns_.size()) + " values, got " +
                std::to_string(row.size()));
  for (std::size_t i = 0; i < row.size(); ++i) columns_[i].values.push_back(row[i]);
}

void Series::clear() {
  for (Column& c : columns_) c.values.clear();
}

void Series::write_hdf5(const std::filesystem::path& path) const {
  AtomicFile file(path);
  {
    h5::Handle f = h5::create_file(file.temp_path());
    std::string names;
    for (const Column& c : columns_) {
      h5::write_doubles(f, c.name, c.values, 0, c.unit, path.string());
      names += (names.empty() ? "" : ",") + c.name;
    }
    h5::write_attribute(f, "columns", names, path.string());
    h5::write_attributes(f, attributes_, path.string());
    h5::write_image(f, file.temp_path(), path.string());
  }
  file.commit();
}

void Series::write_csv(const std::filesystem::path& path) const {
  io::write_csv(path, columns_);
}

}  // namespace asperity::io
