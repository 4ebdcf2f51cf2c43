// Particle snapshots: one HDF5 file per snapshot and an XDMF index over them.
//
// Why one file per snapshot rather than one growing file: each file can then be written under a
// temporary name and renamed when complete, so an interrupted run leaves only whole snapshots,
// and ParaView can reload the series while the run is still writing it.
//
// XDMF (www.xdmf.org, version 3 light data): a Temporal collection of Uniform grids. Particles
// are a Polyvertex topology over their positions, with an explicit connectivity 0..n-1 (stored
// as /particles/index) rather than the implicit form, which some readers handle differently.
// Contacts are a Polyline topology with two nodes per element, the two particles' rows, over the
// same positions: ParaView then draws the force chains as lines and colours them by force.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "asperity/io.hpp"
#include "asperity/world.hpp"
#include "io/hdf5_file.hpp"

namespace asperity::io {

Snapshot take_snapshot(const World& world, bool with_contacts, std::int64_t id_base) {
  Snapshot s;
  s.step = world.step_count();
  s.time = world.time();
  s.id_base = id_base;
  std::size_t n = world.particle_count();
  s.position = world.positions();
  s.velocity = world.velocities();
  s.radius = world.radii();
  s.force = world.forces();
  s.id.resize(n);
  s.group.resize(n);
  s.tag.resize(n);
  s.angular_velocity.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    auto id = static_cast<std::int64_t>(i);
    s.id[i] = id + id_base;
    int g = world.group_of(id);
    s.group[i] = g < 0 ? -1 : static_cast<std::int32_t>(g + id_base);
    s.tag[i] = static_cast<std::int32_t>(world.tag(id));
    Vec3 w = world.angular_velocity(id);
    s.angular_velocity[3 * i] = w.x;
    s.angular_velocity[3 * i + 1] = w.y;
    s.angular_velocity[3 * i + 2] = w.z;
  }
  if (with_contacts) {
    s.has_contacts = true;
    std::vector<ContactInfo> cs = world.contacts();
    std::size_t m = cs.size();
    s.id_a.resize(m);
    s.id_b.resize(m);
    s.index_a.resize(m);
    s.index_b.resize(m);
    s.overlap.resize(m);
    s.normal_force.resize(m);
    s.normal.resize(3 * m);
    s.point.resize(3 * m);
    s.shear_force.resize(3 * m);
    for (std::size_t k = 0; k < m; ++k) {
      const ContactInfo& c = cs[k];
      // Bulk reads are in id order, so the row of a particle is its id.
      s.index_a[k] = static_cast<std::int32_t>(c.id_a);
      s.index_b[k] = static_cast<std::int32_t>(c.id_b);
      s.id_a[k] = c.id_a + id_base;
      s.id_b[k] = c.id_b + id_base;
      s.overlap[k] = c.overlap;
      s.normal_force[k] = c.normal_force;
      for (int d = 0; d < 3; ++d) {
        s.normal[3 * k + d] = c.normal[d];
        s.point[3 * k + d] = c.point[d];
        s.shear_force[3 * k + d] = c.shear_force[d];
      }
    }
  }
  const std::vector<BondInfo> bonds = world.bonds();
  if (!bonds.empty()) {
    s.has_bonds = true;
    for (const BondInfo& b : bonds) {
      s.bond_index_a.push_back(static_cast<std::int32_t>(b.id_a));
      s.bond_index_b.push_back(static_cast<std::int32_t>(b.id_b));
      s.bond_id_a.push_back(b.id_a + id_base);
      s.bond_id_b.push_back(b.id_b + id_base);
      s.bond_normal_force.push_back(b.normal_force);
      s.bond_shear_force.insert(s.bond_shear_force.end(), {b.shear_force.x, b.shear_force.y, b.shear_force.z});
      s.bond_sigma.push_back(b.sigma);
      s.bond_tau.push_back(b.tau);
      s.bond_gap.push_back(b.gap);
      s.bond_holds.push_back((b.beam ? 1 : 0) + (b.contact_bond ? 2 : 0));
    }
  }
  return s;
}

void drop_particles(Snapshot& s, const std::vector<bool>& keep) {
  const std::size_t n = s.id.size();
  if (keep.size() != n) throw Error("drop_particles: the mask has the wrong length");
  std::vector<std::int32_t> row(n, -1);
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (keep[i]) row[i] = static_cast<std::int32_t>(m++);
  // Compacts a per-particle array of `width` values per row.
  auto compact = [&](auto& v, std::size_t width) {
    if (v.empty()) return;
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (keep[i])
        for (std::size_t d = 0; d < width; ++d) v[k++] = v[width * i + d];
    v.resize(k);
  };
  compact(s.id, 1);
  compact(s.position, 3);
  compact(s.velocity, 3);
  compact(s.radius, 1);
  compact(s.group, 1);
  compact(s.tag, 1);
  compact(s.force, 3);
  compact(s.angular_velocity, 3);
  compact(s.displacement, 3);
  // Pairs: kept when both ends are, their rows renumbered.
  auto pairs = [&](std::vector<std::int32_t>& a, std::vector<std::int32_t>& b, auto&& move_rest) {
    std::size_t k = 0;
    for (std::size_t e = 0; e < a.size(); ++e) {
      std::int32_t ra = row[static_cast<std::size_t>(a[e])], rb = row[static_cast<std::size_t>(b[e])];
      if (ra < 0 || rb < 0) continue;
      a[k] = ra;
      b[k] = rb;
      move_rest(k, e);
      ++k;
    }
    return k;
  };
  if (s.has_contacts) {
    std::size_t k = pairs(s.index_a, s.index_b, [&](std::size_t to, std::size_t from) {
      s.id_a[to] = s.id_a[from];
      s.id_b[to] = s.id_b[from];
      s.overlap[to] = s.overlap[from];
      s.normal_force[to] = s.normal_force[from];
      for (int d = 0; d < 3; ++d) {
        s.normal[3 * to + d] = s.normal[3 * from + d];
        s.point[3 * to + d] = s.point[3 * from + d];
        s.shear_force[3 * to + d] = s.shear_force[3 * from + d];
      }
    });
    for (auto* v : {&s.index_a, &s.index_b}) v->resize(k);
    for (auto* v : {&s.id_a, &s.id_b}) v->resize(k);
    for (auto* v : {&s.overlap, &s.normal_force}) v->resize(k);
    for (auto* v : {&s.normal, &s.point, &s.shear_force}) v->resize(3 * k);
  }
  if (s.has_bonds) {
    std::size_t k = pairs(s.bond_index_a, s.bond_index_b, [&](std::size_t to, std::size_t from) {
      s.bond_id_a[to] = s.bond_id_a[from];
      s.bond_id_b[to] = s.bond_id_b[from];
      s.bond_normal_force[to] = s.bond_normal_force[from];
      s.bond_sigma[to] = s.bond_sigma[from];
      s.bond_tau[to] = s.bond_tau[from];
      s.bond_gap[to] = s.bond_gap[from];
      s.bond_holds[to] = s.bond_holds[from];
      for (int d = 0; d < 3; ++d) s.bond_shear_force[3 * to + d] = s.bond_shear_force[3 * from + d];
    });
    for (auto* v : {&s.bond_index_a, &s.bond_index_b}) v->resize(k);
    for (auto* v : {&s.bond_id_a, &s.bond_id_b}) v->resize(k);
    s.bond_holds.resize(k);
    for (auto* v : {&s.bond_normal_force, &s.bond_sigma, &s.bond_tau, &s.bond_gap}) v->resize(k);
    s.bond_shear_force.resize(3 * k);
  }
}

namespace {
std::vector<std::int32_t> interleave(const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b) {
  std::vector<std::int32_t> out(2 * a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    out[2 * k] = a[k];
    out[2 * k + 1] = b[k];
  }
  return out;
}
}  // namespace

void write_snapshot_hdf5(const std::filesystem::path& path, const Snapshot& s) {
  const std::string name = path.string();
  std::size_t n = s.id.size();
  if (s.position.size() != 3 * n || s.velocity.size() != 3 * n || s.radius.size() != n ||
      s.group.size() != n)
    throw Error("snapshot for '" + name + "': particle arrays of unequal length");
  AtomicFile file(path);
  {
    h5::Handle f = h5::create_file(file.temp_path());
    h5::write_attribute(f, "step", static_cast<std::int64_t>(s.step), name);
    h5::write_attribute(f, "time", s.time, name);
    if (s.index_time) h5::write_attribute(f, "index_time", *s.index_time, name);
    h5::write_attribute(f, "id_base", s.id_base, name);
    h5::write_attributes(f, s.attributes, name);
    {
      h5::Handle g = h5::create_group(f, "particles", name);
      h5::write_int64(g, "id", s.id, 0, "", name);
      h5::write_doubles(g, "position", s.position, 3, "m", name);
      h5::write_doubles(g, "velocity", s.velocity, 3, "m/s", name);
      h5::write_doubles(g, "radius", s.radius, 0, "m", name);
      h5::write_int32(g, "group", s.group, 0, "", name);
      if (!s.tag.empty()) h5::write_int32(g, "tag", s.tag, 0, "", name);
      if (!s.force.empty()) h5::write_doubles(g, "force", s.force, 3, "N", name);
      if (!s.angular_velocity.empty())
        h5::write_doubles(g, "angular_velocity", s.angular_velocity, 3, "rad/s", name);
      if (!s.displacement.empty()) h5::write_doubles(g, "displacement", s.displacement, 3, "m", name);
      h5::write_attributes(g, s.particle_attributes, name);
      std::vector<std::int32_t> index(n);
      for (std::size_t i = 0; i < n; ++i) index[i] = static_cast<std::int32_t>(i);
      h5::write_int32(g, "index", index, 0, "", name);
    }
    if (s.has_contacts) {
      h5::Handle g = h5::create_group(f, "contacts", name);
      h5::write_int64(g, "id_a", s.id_a, 0, "", name);
      h5::write_int64(g, "id_b", s.id_b, 0, "", name);
      h5::write_int32(g, "pair", interleave(s.index_a, s.index_b), 2, "", name);
      h5::write_doubles(g, "normal", s.normal, 3, "", name);
      h5::write_doubles(g, "point", s.point, 3, "m", name);
      h5::write_doubles(g, "overlap", s.overlap, 0, "m", name);
      h5::write_doubles(g, "normal_force", s.normal_force, 0, "N", name);
      h5::write_doubles(g, "shear_force", s.shear_force, 3, "N", name);
    }
    if (s.has_bonds) {
      h5::Handle g = h5::create_group(f, "bonds", name);
      h5::write_int64(g, "id_a", s.bond_id_a, 0, "", name);
      h5::write_int64(g, "id_b", s.bond_id_b, 0, "", name);
      h5::write_int32(g, "pair", interleave(s.bond_index_a, s.bond_index_b), 2, "", name);
      h5::write_doubles(g, "normal_force", s.bond_normal_force, 0, "N", name);
      h5::write_doubles(g, "shear_force", s.bond_shear_force, 3, "N", name);
      h5::write_doubles(g, "sigma", s.bond_sigma, 0, "Pa", name);
      h5::write_doubles(g, "tau", s.bond_tau, 0, "Pa", name);
      h5::write_doubles(g, "gap", s.bond_gap, 0, "m", name);
      h5::write_int32(g, "holds", s.bond_holds, 0, "", name);
    }
    h5::write_image(f, file.temp_path(), name);
  }
  file.commit();
}

namespace {
// NAME_NNNNNN.h5 (six digits or more) or NAME.xdmf / NAME_contacts.xdmf / NAME_bonds.xdmf.
bool is_series_file(const std::string& file, const std::string& name) {
  if (file == name + ".xdmf" || file == name + "_contacts.xdmf" || file == name + "_bonds.xdmf") return true;
  if (file.size() < name.size() + 1 + 6 + 3 || file.compare(0, name.size() + 1, name + "_") != 0 ||
      file.compare(file.size() - 3, 3, ".h5") != 0)
    return false;
  for (std::size_t i = name.size() + 1; i < file.size() - 3; ++i)
    if (file[i] < '0' || file[i] > '9') return false;
  return true;
}
}  // namespace

SnapshotSeries::SnapshotSeries(std::filesystem::path directory, std::string name,
                               SnapshotSeriesOptions options)
    : directory_(std::move(directory)), name_(std::move(name)), options_(std::move(options)) {
  if (name_.empty() || name_.find('/') != std::string::npos)
    throw Error("snapshot series name '" + name_ + "' must be a plain file name");
  make_directories(directory_);
  for (std::size_t k = 0; k < options_.keep; ++k) {
    const std::string file = file_name(k);
    const std::filesystem::path path = directory_ / file;
    if (!std::filesystem::exists(path))
      throw Error("cannot continue the snapshot series '" + name_ + "': " + path.string() + " (snapshot " +
                  std::to_string(k + 1) + " of " + std::to_string(options_.keep) + ") is missing");
    auto number = [&](const char* attribute) -> std::optional<double> {
      auto a = read_hdf5_attribute(path, "/", attribute);
      if (!a) return std::nullopt;
      if (const auto* d = std::get_if<double>(&*a)) return *d;
      if (const auto* i = std::get_if<std::int64_t>(&*a)) return static_cast<double>(*i);
      return std::nullopt;
    };
    const auto step = number("step"), time = number("time");
    if (!step || !time) throw Error("cannot continue the snapshot series '" + name_ + "': " + path.string() +
                                    " is not one of its snapshots (no step or time)");
    const auto datasets = hdf5_datasets(path);
    auto has = [&](const char* d) { return std::find(datasets.begin(), datasets.end(), d) != datasets.end(); };
    auto rows = [&](const char* d) { return has(d) ? hdf5_shape(path, d).at(0) : std::size_t{0}; };
    entries_.push_back(Entry{file, static_cast<std::uint64_t>(*step), number("index_time").value_or(*time),
                             rows("/particles/id"), rows("/contacts/id_a"), rows("/bonds/id_a"),
                             has("/contacts/id_a"), has("/bonds/id_a")});
    // Each particle's displacement is measured from the first snapshot it appeared in.
    const std::vector<double> ids = read_hdf5(path, "/particles/id");
    const std::vector<double> x = read_hdf5(path, "/particles/position");
    for (std::size_t i = 0; i < ids.size() && 3 * i + 2 < x.size(); ++i)
      reference_.emplace(static_cast<std::int64_t>(ids[i]), std::array<double, 3>{x[3 * i], x[3 * i + 1], x[3 * i + 2]});
  }
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory_, ec)) {
    if (!entry.is_regular_file()) continue;
    const std::string file = entry.path().filename().string();
    if (!is_series_file(file, name_)) continue;
    const bool kept = std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.file == file; });
    if (!kept) std::filesystem::remove(entry.path(), ec);
  }
  if (!entries_.empty()) write_xdmf();
}

std::string SnapshotSeries::file_name(std::size_t index) const {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%06zu.h5", index);
  return name_ + buf;
}

std::filesystem::path SnapshotSeries::xdmf_path() const { return directory_ / (name_ + ".xdmf"); }
std::filesystem::path SnapshotSeries::contacts_xdmf_path() const {
  return directory_ / (name_ + "_contacts.xdmf");
}
std::filesystem::path SnapshotSeries::bonds_xdmf_path() const {
  return directory_ / (name_ + "_bonds.xdmf");
}

std::filesystem::path SnapshotSeries::write(Snapshot snapshot) {
  const std::string file = file_name(entries_.size());
  const std::size_t n = snapshot.id.size();
  snapshot.displacement.assign(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double* x = &snapshot.position[3 * i];
    auto [it, first_seen] = reference_.try_emplace(snapshot.id[i], std::array<double, 3>{x[0], x[1], x[2]});
    if (!first_seen)
      for (int d = 0; d < 3; ++d) snapshot.displacement[3 * i + d] = x[d] - it->second[d];
  }
  for (const auto& key : options_.keys) snapshot.particle_attributes.push_back(key);
  if (!options_.time_label.empty()) snapshot.attributes.emplace_back("index_time_label", options_.time_label);
  write_snapshot_hdf5(directory_ / file, snapshot);
  entries_.push_back(Entry{file, snapshot.step, snapshot.index_time.value_or(snapshot.time), snapshot.id.size(),
                           snapshot.id_a.size(), snapshot.bond_id_a.size(), snapshot.has_contacts,
                           snapshot.has_bonds});
  write_xdmf();
  return directory_ / file;
}

namespace {
std::string data_item(const std::string& file, const std::string& dataset, std::size_t rows,
                      std::size_t cols, const char* number_type, int precision) {
  std::ostringstream o;
  o << "<DataItem Dimensions=\"" << rows;
  if (cols) o << ' ' << cols;
  o << "\" NumberType=\"" << number_type << "\" Precision=\"" << precision
    << "\" Format=\"HDF\">" << file << ':' << dataset << "</DataItem>";
  return o.str();
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string time_text(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", t);
  return buf;
}
}  // namespace

void SnapshotSeries::write_xdmf() const {
  std::ostringstream p, c, b;
  const char* head = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n";
  p << head << "  <Grid Name=\"" << name_ << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  // What the time axis and the integer keys mean, for whoever opens the file.
  p << "   <Information Name=\"time\" Value=\""
    << xml_escape(options_.time_label.empty() ? "simulated time (s)" : options_.time_label) << "\"/>\n";
  for (const auto& [key, value] : options_.keys)
    if (const auto* text = std::get_if<std::string>(&value))
      p << "   <Information Name=\"" << xml_escape(key) << "\" Value=\"" << xml_escape(*text) << "\"/>\n";
  c << head << "  <Grid Name=\"" << name_ << "_contacts\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  b << head << "  <Grid Name=\"" << name_ << "_bonds\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  bool any_contacts = false, any_bonds = false;
  for (const Entry& e : entries_) {
    const std::string& f = e.file;
    std::size_t n = e.particles;
    std::string geometry = "    <Geometry GeometryType=\"XYZ\">" +
                           data_item(f, "/particles/position", n, 3, "Float", 8) + "</Geometry>\n";
    p << "   <Grid Name=\"step " << e.step << "\" GridType=\"Uniform\">\n"
      << "    <Time Value=\"" << time_text(e.time) << "\"/>\n"
      << "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n
      << "\" NodesPerElement=\"1\">" << data_item(f, "/particles/index", n, 0, "Int", 4)
      << "</Topology>\n"
      << geometry;
    auto attribute = [&](std::ostringstream& o, const char* name, const char* type,
                         const char* center, const std::string& item) {
      o << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\""
        << center << "\">" << item << "</Attribute>\n";
    };
    attribute(p, "id", "Scalar", "Node", data_item(f, "/particles/id", n, 0, "Int", 8));
    attribute(p, "radius", "Scalar", "Node", data_item(f, "/particles/radius", n, 0, "Float", 8));
    attribute(p, "velocity", "Vector", "Node",
              data_item(f, "/particles/velocity", n, 3, "Float", 8));
    attribute(p, "group", "Scalar", "Node", data_item(f, "/particles/group", n, 0, "Int", 4));
    attribute(p, "tag", "Scalar", "Node", data_item(f, "/particles/tag", n, 0, "Int", 4));
    attribute(p, "displacement", "Vector", "Node",
              data_item(f, "/particles/displacement", n, 3, "Float", 8));
    attribute(p, "force", "Vector", "Node", data_item(f, "/particles/force", n, 3, "Float", 8));
    attribute(p, "angular_velocity", "Vector", "Node",
              data_item(f, "/particles/angular_velocity", n, 3, "Float", 8));
    p << "   </Grid>\n";
    if (e.has_contacts) {
      any_contacts = true;
      std::size_t m = e.contacts;
      c << "   <Grid Name=\"step " << e.step << "\" GridType=\"Uniform\">\n"
        << "    <Time Value=\"" << time_text(e.time) << "\"/>\n"
        << "    <Topology TopologyType=\"Polyline\" NumberOfElements=\"" << m
        << "\" NodesPerElement=\"2\">" << data_item(f, "/contacts/pair", m, 2, "Int", 4)
        << "</Topology>\n"
        << geometry;
      attribute(c, "normal_force", "Scalar", "Cell",
                data_item(f, "/contacts/normal_force", m, 0, "Float", 8));
      attribute(c, "overlap", "Scalar", "Cell", data_item(f, "/contacts/overlap", m, 0, "Float", 8));
      attribute(c, "shear_force", "Vector", "Cell",
                data_item(f, "/contacts/shear_force", m, 3, "Float", 8));
      attribute(c, "normal", "Vector", "Cell", data_item(f, "/contacts/normal", m, 3, "Float", 8));
      c << "   </Grid>\n";
    }
    if (e.has_bonds) {
      any_bonds = true;
      std::size_t m = e.bonds;
      b << "   <Grid Name=\"step " << e.step << "\" GridType=\"Uniform\">\n"
        << "    <Time Value=\"" << time_text(e.time) << "\"/>\n"
        << "    <Topology TopologyType=\"Polyline\" NumberOfElements=\"" << m
        << "\" NodesPerElement=\"2\">" << data_item(f, "/bonds/pair", m, 2, "Int", 4)
        << "</Topology>\n"
        << geometry;
      attribute(b, "normal_force", "Scalar", "Cell", data_item(f, "/bonds/normal_force", m, 0, "Float", 8));
      attribute(b, "sigma", "Scalar", "Cell", data_item(f, "/bonds/sigma", m, 0, "Float", 8));
      attribute(b, "tau", "Scalar", "Cell", data_item(f, "/bonds/tau", m, 0, "Float", 8));
      attribute(b, "holds", "Scalar", "Cell", data_item(f, "/bonds/holds", m, 0, "Int", 4));
      attribute(b, "shear_force", "Vector", "Cell", data_item(f, "/bonds/shear_force", m, 3, "Float", 8));
      b << "   </Grid>\n";
    }
  }
  const char* tail = "  </Grid>\n </Domain>\n</Xdmf>\n";
  p << tail;
  c << tail;
  b << tail;
  write_text_file(xdmf_path(), p.str());
  if (any_contacts) write_text_file(contacts_xdmf_path(), c.str());
  if (any_bonds) write_text_file(bonds_xdmf_path(), b.str());
}

}  // namespace asperity::io
