// Checkpoints: the whole state of a World in one HDF5 file, so that a run restarted from it
// continues bit for bit (design.md "Outputs"). Used to cache generated joint halves and to resume
// long runs.
//
// Design note: one function, visit(), lists every field once; the writer and the reader are two
// "archives" passed through it, so the two directions cannot drift apart. Derived data (cell
// grid, incidence lists, bonded partners, mesh bins) is rebuilt after loading by the same
// deterministic code that built it in the first place.
#include <hdf5.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <type_traits>

#include "asperity/io.hpp"
#include "bodies/groups.hpp"
#include "bodies/mesh.hpp"
#include "field_problems.hpp"
#include "io/hdf5_file.hpp"
#include "bond_list.hpp"
#include "neighbor/build.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"

namespace asperity {

namespace {

using detail::State;
constexpr int kCheckpointVersion = 14;  // 2: servo integral and integral time, group damping;
                                       // 3: rest overlaps (stress-free bonds);
                                       // 4: meshes' candidates within half the skin;
                                       // 5: a header with a checksum in the HDF5 user block;
                                       // 6: rotation_lock_bonds;
                                       // 7: bonds broken per particle;
                                       // 8: overlap_limit;
                                       // 9: contact bonds apart from the beam (what holds,
                                       //    contact_strength, the kind of a break);
                                       // 10: the groups' impulse (a resumed run's interval means);
                                       // 11: the lazy groups' idle split and pending shift, so that
                                       //     saving does not bring idle members up to date;
                                       // 12: rotation_lock_beams;
                                       // 13: the bond records' layout (4, 8 or 12 doubles), for
                                       //     the torque's terms World::torque adds;
                                       // 14: dead bonds (nothing holds, zero radius), kept until
                                       //     the next neighbour build (BondStore::dead)

// The file's kind in the header of its HDF5 user block (io::h5::file_image), whose checksum is
// verified before HDF5 parses the file: HDF5 does not survive every corruption of its metadata.
constexpr const char* kMagic = "asperity checkpoint\n";

template <class T>
hid_t native_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return H5T_NATIVE_UINT64;
  else if constexpr (std::is_same_v<T, std::int32_t>) return H5T_NATIVE_INT32;
  else if constexpr (std::is_same_v<T, std::uint8_t>) return H5T_NATIVE_UINT8;
  else static_assert(sizeof(T) == 0, "unsupported checkpoint column type");
}

struct Writer {
  hid_t file;
  std::string path;
  int version = kCheckpointVersion;
  template <class T>
  void raw(const std::string& name, const T* data, std::size_t n) {
    const hsize_t dims[1] = {n};
    io::h5::Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose);
    io::h5::Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(lcpl, 1);
    io::h5::Handle set(H5Dcreate2(file, name.c_str(), native_type<T>(), space, lcpl, H5P_DEFAULT,
                                  H5P_DEFAULT), H5Dclose);
    if (!set.valid() || (n > 0 && H5Dwrite(set, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
      throw Error("cannot write checkpoint '" + path + "': dataset " + name);
  }
  template <class V>
  void column(const std::string& name, V& v) { raw(name, v.data(), v.size()); }
  template <class T>
  void scalar(const std::string& name, T& v) { raw(name, &v, 1); }
  void flag(const std::string& name, bool& b) {
    std::uint8_t v = b;
    raw(name, &v, 1);
  }
  void vec(const std::string& name, Vec3& v) {
    double d[3] = {v.x, v.y, v.z};
    raw(name, d, 3);
  }
  void text(const std::string& name, std::string& s) {
    raw(name, reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
  }
  template <class T>
  void count(const std::string& name, std::vector<T>& items) {
    std::uint64_t n = items.size();
    raw(name, &n, 1);
  }
};

struct Reader {
  hid_t file;
  std::string path;
  int version = kCheckpointVersion;  // of the file: fields added later keep their defaults
  template <class T>
  std::vector<T> raw(const std::string& name) {
    if (H5Lexists(file, name.c_str(), H5P_DEFAULT) <= 0)
      throw Error("'" + path + "' is not an asperity checkpoint of this version: no " + name);
    io::h5::Handle set(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
    io::h5::Handle space(H5Dget_space(set), H5Sclose);
    hsize_t dims[1] = {0};
    H5Sget_simple_extent_dims(space, dims, nullptr);
    std::vector<T> out(dims[0]);
    if (dims[0] > 0 && H5Dread(set, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
      throw Error("cannot read checkpoint '" + path + "': dataset " + name);
    return out;
  }
  template <class V>
  void column(const std::string& name, V& v) {
    const auto data = raw<typename V::value_type>(name);
    v.assign(data.begin(), data.end());
  }
  template <class T>
  void scalar(const std::string& name, T& v) {
    const auto data = raw<T>(name);
    if (data.size() != 1) throw Error("checkpoint '" + path + "': " + name + " is not a scalar");
    v = data[0];
  }
  void flag(const std::string& name, bool& b) {
    std::uint8_t v;
    scalar(name, v);
    b = v != 0;
  }
  void vec(const std::string& name, Vec3& v) {
    const auto d = raw<double>(name);
    if (d.size() != 3) throw Error("checkpoint '" + path + "': " + name + " is not a vector");
    v = {d[0], d[1], d[2]};
  }
  void text(const std::string& name, std::string& s) {
    const auto d = raw<std::uint8_t>(name);
    s.assign(d.begin(), d.end());
  }
  template <class T>
  void count(const std::string& name, std::vector<T>& items) {
    std::uint64_t n;
    scalar(name, n);
    if (n > (std::uint64_t(1) << 31)) throw Error("checkpoint '" + path + "' is damaged: " + name + " = " + std::to_string(n));
    items.resize(n);
  }
};

// A store's column under `at` + its name; a file older than the column gives it `size` pads.
template <class Io, class V>
void visit_column(Io& io, const std::string& at, const detail::ColumnInfo& c, V& col, std::size_t size) {
  if (io.version >= c.since) io.column(at + c.name, col);
  else col.assign(size, static_cast<typename V::value_type>(c.pad));
}

// A field's value saved under `at`, by its type.
void visit_value(auto& io, const std::string& at, double& v) { io.scalar(at, v); }
void visit_value(auto& io, const std::string& at, int& v) { io.scalar(at, v); }
void visit_value(auto& io, const std::string& at, bool& v) { io.flag(at, v); }
void visit_value(auto& io, const std::string& at, Vec3& v) { io.vec(at, v); }
void visit_value(auto&, const std::string&, std::string&) {}  // no text setting is saved
void visit_value(auto&, const std::string&, Dof&) {}  // the modes: one column per group (visit)
void visit_value(auto&, const std::string&, std::array<Dof, 3>&) {}
// A struct with a field table: its stored fields under `at`, those newer than the file kept.
template <class Io, class Table>
  requires requires(Table& t) { for_each_field(t, [](const Field&, auto&) {}); }
void visit_value(Io& io, const std::string& at, Table& t) {
  for_each_field(t, [&](const Field& f, auto& v) {
    if (f.stored != nullptr && io.version >= f.since) visit_value(io, at + "/" + f.stored, v);
  });
}
// The three servos of a motion: at + "0", "1", "2".
template <class Io>
void visit_value(Io& io, const std::string& at, std::array<Servo, 3>& servos) {
  for (int k = 0; k < 3; ++k) visit_value(io, at + std::to_string(k), servos[k]);
}

template <class Io>
void visit(Io& io, State& s) {
  // Settings: every stored field of the table (world.hpp), those added after the file's version
  // keep their defaults.
  for_each_setting(s.settings, [&](const Field& f, auto& v) {
    if (f.stored != nullptr && io.version >= f.since) visit_value(io, std::string("settings/") + f.stored, v);
  });

  // Clock, time step, neighbour bookkeeping, ledgers.
  io.scalar("run/step", s.step);
  io.scalar("run/time", s.time);
  io.scalar("run/dt", s.dt);
  io.scalar("run/dt_estimate", s.dt_estimate);
  io.flag("run/dt_fixed", s.dt_fixed);
  io.scalar("run/last_estimate_step", s.last_estimate_step);
  io.scalar("run/skin", s.skin);
  io.flag("run/need_rebuild", s.need_rebuild);
  io.flag("run/force_reorder", s.force_reorder);
  io.scalar("run/rebuilds", s.rebuilds);
  io.scalar("run/reorders", s.reorders);
  io.scalar("run/rebuilds_since_reorder", s.rebuilds_since_reorder);
  io.scalar("run/reference_energy", s.reference_energy);
  io.scalar("run/reference_input", s.reference_input);
  io.scalar("run/kinetic_at_step", s.kinetic_at_step);
  io.flag("run/kinetic_valid", s.kinetic_valid);
  io.scalar("ledger/friction", s.ledger.friction);
  io.scalar("ledger/damping", s.ledger.damping);
  io.scalar("ledger/boundary", s.ledger.boundary);
  io.scalar("ledger/gravity", s.ledger.gravity);
  io.scalar("ledger/released", s.ledger.released);

  // Particles.
  auto& p = s.p;
  io.scalar("particles/n", p.n);
  io.flag("particles/has_applied", p.has_applied);
  detail::ParticleStore::slot_columns(
      [&](const detail::ColumnInfo& c, auto& col) { visit_column(io, "particles/", c, col, p.capacity); }, p);
  // Older files: no break counted (a damaged particle of theirs is locked again while bonded).
  detail::ParticleStore::particle_columns(
      [&](const detail::ColumnInfo& c, auto& col) { visit_column(io, "particles/", c, col, p.n); }, p);
  io.column("particles/index_of_id", p.index_of_id);

  // Pairs with their history, and the contacts broken bonds left behind.
  for (auto [at, q] : {std::pair{std::string("pairs"), &s.pairs}, {std::string("inherited"), &s.inherited}}) {
    io.scalar(at + "/n", q->n);
    io.scalar(at + "/padded", q->padded);
    io.column(at + "/a", q->a);
    io.column(at + "/b", q->b);
    if constexpr (std::is_same_v<Io, Writer>) q->columns_from_records();  // fn and U of the last step
    // Rest overlaps (stress-free bonds) since version 3; older files had none: all 0.
    detail::PairStore::history_columns(
        [&](const detail::ColumnInfo& c, auto& col) { visit_column(io, at + "/", c, col, q->padded); }, *q);
    q->size_outputs();
  }

  // Bonds: one list, active and frozen together (loading freezes the same ones again, or the
  // first step's split does: State::frozen_bonds).
  detail::BondStore every;
  if constexpr (std::is_same_v<Io, Writer>) {
    if (s.frozen_bonds.n > 0) every = detail::all_bonds(s);
  } else {
    s.frozen_bonds.resize(0);
  }
  auto& b = every.n > 0 ? every : s.bonds;
  io.scalar("bonds/n", b.n);
  io.scalar("bonds/padded", b.padded);
  io.column("bonds/a", b.a);
  io.column("bonds/b", b.b);
  detail::BondStore::columns(
      [&](const detail::ColumnInfo& c, auto& col) { visit_column(io, "bonds/", c, col, b.padded); }, b);
  if (io.version >= 3) io.flag("bonds/rest_overlaps", s.rest_overlaps);
  b.size_outputs();
  visit_value(io, "bonds/material", b.material);
  io.flag("bonds/any", b.any);
  if constexpr (!std::is_same_v<Io, Writer>) {
    s.frozen_bonds.material = b.material;
    s.frozen_bonds.any = b.any;
  }

  // Break events, as columns.
  auto& ev = s.break_events;
  io.count("breaks/n", ev);
  {
    std::vector<std::uint64_t> step(ev.size());
    std::vector<double> num(ev.size() * 7);
    std::vector<std::int64_t> ids(ev.size() * 2);
    std::vector<std::uint8_t> mode(ev.size()), kind(ev.size());
    for (std::size_t k = 0; k < ev.size(); ++k) {
      step[k] = ev[k].step;
      const double v[7] = {ev[k].time, ev[k].position.x, ev[k].position.y, ev[k].position.z,
                           ev[k].sigma, ev[k].tau, ev[k].released_energy};
      std::memcpy(&num[7 * k], v, sizeof v);
      ids[2 * k] = ev[k].id_a;
      ids[2 * k + 1] = ev[k].id_b;
      mode[k] = static_cast<std::uint8_t>(ev[k].mode);
      kind[k] = static_cast<std::uint8_t>(ev[k].kind);
    }
    io.column("breaks/step", step);
    io.column("breaks/values", num);
    io.column("breaks/ids", ids);
    io.column("breaks/mode", mode);
    if (io.version >= 9) io.column("breaks/kind", kind);  // older files: beams only
    for (std::size_t k = 0; k < ev.size(); ++k) {  // reader: put them back
      ev[k].step = step[k];
      ev[k].time = num[7 * k];
      ev[k].position = {num[7 * k + 1], num[7 * k + 2], num[7 * k + 3]};
      ev[k].sigma = num[7 * k + 4];
      ev[k].tau = num[7 * k + 5];
      ev[k].released_energy = num[7 * k + 6];
      ev[k].id_a = ids[2 * k];
      ev[k].id_b = ids[2 * k + 1];
      ev[k].mode = static_cast<BreakEvent::Mode>(mode[k]);
      ev[k].kind = static_cast<BreakEvent::Kind>(kind[k]);
    }
  }

  // Walls, meshes and ball-wall contacts.
  io.count("walls/n", s.walls.walls);
  for (std::size_t w = 0; w < s.walls.walls.size(); ++w) {
    auto& wall = s.walls.walls[w];
    const std::string at = "walls/" + std::to_string(w);
    std::uint8_t kind = static_cast<std::uint8_t>(wall.kind);
    io.scalar(at + "/kind", kind);
    wall.kind = static_cast<detail::Wall::Kind>(kind);
    visit_value(io, at + "/material", wall.material);
    io.vec(at + "/point", wall.point);
    io.vec(at + "/normal", wall.normal);
    io.scalar(at + "/mesh", wall.mesh);
    io.vec(at + "/velocity", wall.velocity);
    io.vec(at + "/displacement", wall.displacement);
    io.vec(at + "/displacement_at_build", wall.displacement_at_build);
    io.vec(at + "/force", wall.force);
    io.flag(at + "/removed", wall.removed);
    // Older files listed every candidate within the whole skin: false, which is what they hold.
    if (io.version >= 4) io.flag(at + "/candidates_within_half_skin", wall.candidates_within_half_skin);
  }
  io.count("meshes/n", s.walls.meshes);
  for (std::size_t m = 0; m < s.walls.meshes.size(); ++m) {
    auto& mesh = s.walls.meshes[m];
    const std::string at = "meshes/" + std::to_string(m);
    std::vector<double> v(mesh.vertices.size() * 3);
    std::vector<std::int32_t> t(mesh.triangles.size() * 3);
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
      v[3 * k] = mesh.vertices[k].x; v[3 * k + 1] = mesh.vertices[k].y; v[3 * k + 2] = mesh.vertices[k].z;
    }
    for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
      for (int c = 0; c < 3; ++c) t[3 * k + c] = mesh.triangles[k][c];
    io.column(at + "/vertices", v);
    io.column(at + "/triangles", t);
    mesh.vertices.resize(v.size() / 3);
    mesh.triangles.resize(t.size() / 3);
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) mesh.vertices[k] = {v[3 * k], v[3 * k + 1], v[3 * k + 2]};
    for (std::size_t k = 0; k < mesh.triangles.size(); ++k) mesh.triangles[k] = {t[3 * k], t[3 * k + 1], t[3 * k + 2]};
    io.column(at + "/owns", mesh.owns);
    io.column(at + "/vertex_start", mesh.vertex_start);
    io.column(at + "/vertex_triangles", mesh.vertex_triangles);
  }
  auto& wc = s.walls.contacts;
  io.scalar("wall_contacts/n", wc.n);
  io.column("wall_contacts/particle", wc.particle);
  io.column("wall_contacts/wall", wc.wall);
  io.column("wall_contacts/facet", wc.facet);
  io.column("wall_contacts/start", wc.start);
  detail::WallContacts::history_columns(
      [&](const detail::ColumnInfo& c, auto& col) { visit_column(io, "wall_contacts/", c, col, wc.n); }, wc);

  // Rigid groups, and the idle split of the lazy ones (bodies/groups.cpp, split_idle): saved as it
  // is, with the shift not yet applied to the idle members, because bringing them up to date at
  // the save would round their moves differently from the run that was not saved.
  if (io.version >= 11) {
    io.flag("run/idle_valid", s.cache.idle_valid);
    io.column("run/idle", s.cache.idle);
    // What the last step left for the next one's choice of kernels (State::spin_known ...): a
    // resumed run takes the kernels the unbroken one takes.
    io.flag("run/spin_known", s.cache.spin_known);
    io.scalar("run/spin_reachable", s.cache.spin_reachable);
    io.scalar("run/spin_bonded", s.cache.spin_bonded);
    io.flag("run/bond_moments_zero", s.cache.bond_moments_zero);
    // The layout the last bond stage wrote (Caches::bond_records); before version 13 a flag, with
    // the moment or without.
    if (io.version >= 13) {
      auto width = std::uint8_t(s.cache.bond_records);
      io.scalar("run/bond_records", width);
      if (width != 4 && width != 8 && width != 12)
        throw Error("checkpoint: run/bond_records is " + std::to_string(width) + ", not 4, 8 or 12");
      s.cache.bond_records = kernels::BondRecord(width);
    } else {
      bool moments = s.cache.bond_records == kernels::BondRecord::moments;
      io.flag("run/bond_records_with_moments", moments);
      s.cache.bond_records = moments ? kernels::BondRecord::moments : kernels::BondRecord::levers;
    }
    io.flag("run/pair_records_sparse", s.cache.pair_records_sparse);
  }
  io.count("groups/n", s.groups);
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    auto& grp = s.groups[g];
    const std::string at = "groups/" + std::to_string(g);
    io.column(at + "/members", grp.members);
    io.column(at + "/inert", grp.inert);
    io.vec(at + "/inert_shift", grp.inert_shift);
    io.scalar(at + "/inert_mass", grp.inert_mass);
    io.vec(at + "/servo_origin", grp.servo_origin);
    if (io.version >= 2) io.vec(at + "/servo_integral", grp.servo_integral);
    io.scalar(at + "/contact_stiffness", grp.contact_stiffness);
    io.scalar(at + "/mass", grp.mass);
    io.vec(at + "/centre", grp.centre);
    io.vec(at + "/velocity", grp.velocity);
    io.vec(at + "/angular_velocity", grp.angular_velocity);
    io.vec(at + "/applied", grp.applied);
    io.vec(at + "/force", grp.force);
    io.vec(at + "/torque", grp.torque);
    if (io.version >= 10) io.vec(at + "/impulse", grp.impulse);
    if (io.version >= 11) {
      io.flag(at + "/lazy", grp.lazy);
      io.column(at + "/busy", grp.busy);
      io.vec(at + "/idle_shift", grp.idle_shift);
      io.scalar(at + "/idle_mass", grp.idle_mass);
      io.scalar(at + "/idle_base", grp.idle_base);
    }
    GroupMotion& m = grp.motion;
    std::vector<std::uint8_t> modes{std::uint8_t(m.translation[0]), std::uint8_t(m.translation[1]),
                                    std::uint8_t(m.translation[2]), std::uint8_t(m.rotation)};
    io.column(at + "/modes", modes);
    for (int k = 0; k < 3; ++k) m.translation[k] = static_cast<Dof>(modes.at(k));
    m.rotation = static_cast<Dof>(modes.at(3));
    visit_value(io, at, m);  // the rest of the motion, by its table
  }
}

// Whether a stored value is one its field accepts (field_problems.hpp).
template <class T>
bool setting_valid(const Field& f, const T& v) {
  return detail::field_problem(f, v).empty();
}

// Everything a step or a reader relies on, checked after loading: sizes of the columns, indices
// in range, finite values. A file that passes the checksum was written by save(); these checks
// also cover older files without one, and a file whose checksum was forged.
void validate(const State& s, const std::string& path) {
  auto need = [&](bool ok, const std::string& what) {
    if (!ok) throw Error("checkpoint '" + path + "' is damaged: " + what);
  };
  auto finite = [](double v) { return std::isfinite(v); };
  auto finite3 = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  for_each_setting(s.settings, [&](const Field& f, const auto& v) {
    if (f.stored != nullptr) need(setting_valid(f, v), std::string("settings/") + f.stored);
  });
  need(finite(s.time) && s.dt >= 0 && finite(s.dt) && !std::isnan(s.dt_estimate) && s.skin >= 0 && finite(s.skin),
       "run/time, run/dt or run/skin");
  need(finite(s.reference_energy) && finite(s.reference_input) && finite(s.kinetic_at_step), "run energies");
  need(finite(s.ledger.friction) && finite(s.ledger.damping) && finite(s.ledger.boundary) &&
           finite(s.ledger.gravity) && finite(s.ledger.released),
       "ledger");

  // Particles: columns of `capacity` (n real ones, then null particles), ids a permutation.
  const auto& p = s.p;
  const std::size_t n = p.n, cap = p.x.size();
  need(n < (std::size_t(1) << 31) - 16 && cap >= n + 2 && cap % kMaxLanes == 0, "particles/n");
  using detail::ColumnInfo;
  using detail::ParticleStore;
  ParticleStore::slot_columns([&](const ColumnInfo& c, const auto& col) {
    if (!c.optional || p.has_applied) need(col.size() == cap, std::string("particles/") + c.name + ": length");
  }, p);
  ParticleStore::particle_columns([&](const ColumnInfo& c, const auto& col) {
    need(col.size() == n, std::string("particles/") + c.name + ": length");
  }, p);
  need(p.index_of_id.size() == n, "particles/index_of_id: length");
  for (std::size_t i = 0; i < n; ++i) need(p.bonds_broken[i] >= 0, "particles/bonds_broken");
  const auto groups = static_cast<std::int64_t>(s.groups.size());
  for (std::size_t i = 0; i < cap; ++i) {
    if (i < n) {
      need(p.id[i] >= 0 && p.id[i] < std::int64_t(n) && p.index_of_id[std::size_t(p.id[i])] == std::int64_t(i),
           "particles/id and index_of_id do not match");
      need(p.radius[i] > 0 && finite(p.radius[i]) && p.mass[i] > 0 && finite(p.mass[i]) &&
               p.inertia[i] > 0 && finite(p.inertia[i]) && p.inv_mass[i] > 0 && finite(p.inv_mass[i]) &&
               p.inv_inertia[i] > 0 && finite(p.inv_inertia[i]) && p.density[i] > 0 && finite(p.density[i]),
           "radius, mass or inertia of particle " + std::to_string(p.id[i]));
      ParticleStore::slot_columns([&](const ColumnInfo& c, const auto& col) {
        if constexpr (std::is_floating_point_v<typename std::decay_t<decltype(col)>::value_type>)
          if (!c.optional || p.has_applied)
            need(finite(col[i]), "non-finite state of particle " + std::to_string(p.id[i]) + " (" + c.name + ")");
      }, p);
      need(p.group[i] >= -1 && p.group[i] < groups, "particles/group");
      need(p.inert[i] <= 1 && (!p.inert[i] || p.group[i] >= 0), "particles/inert");
    } else {
      need(p.group[i] == -1 && p.inert[i] == 0, "null particles");
    }
  }

  // Pair and bond lists: n entries over real particles, padding over any particle slot.
  // `columns` walks the store's columns (store/pairs.hpp, store/bonds.hpp).
  auto pair_like = [&](const auto& q, const char* at, auto columns) {
    need(q.n <= q.padded && q.padded % kMaxLanes == 0 && q.a.size() == q.padded && q.b.size() == q.padded,
         std::string(at) + "/n or padded");
    columns([&](const ColumnInfo& c, const auto& col) {
      need(col.size() == q.padded, std::string(at) + "/" + c.name + ": length");
    }, q);
    for (std::size_t k = 0; k < q.padded; ++k) {
      const auto a = q.a[k], b = q.b[k];
      if (k < q.n) {
        need(a >= 0 && b >= 0 && std::size_t(a) < n && std::size_t(b) < n && a != b,
             std::string(at) + ": entry " + std::to_string(k) + " refers to no particle");
        columns([&](const ColumnInfo& c, const auto& col) {
          need(finite(col[k]), std::string(at) + ": non-finite " + c.name);
        }, q);
      } else {
        need(a >= 0 && b >= 0 && std::size_t(a) < cap && std::size_t(b) < cap, std::string(at) + ": padding");
      }
    }
  };
  const auto pair_columns = [](auto&& f, const detail::PairStore& q) { detail::PairStore::history_columns(f, q); };
  const auto bond_columns = [](auto&& f, const detail::BondStore& q) { detail::BondStore::columns(f, q); };
  for (const auto* q : {&s.pairs, &s.inherited}) pair_like(*q, q == &s.pairs ? "pairs" : "inherited", pair_columns);
  const auto& b = s.bonds;
  pair_like(b, "bonds", bond_columns);
  for (std::size_t k = 0; k < b.n; ++k) need(b.beam_radius[k] >= 0, "bonds/beam_radius");
  // 0: a dead bond (BondStore::dead), kept until the saved run's next neighbour build, with no radius.
  for (std::size_t k = 0; k < b.n; ++k)
    need(b.holds[k] == detail::kBeamHolds || b.holds[k] == detail::kContactBondHolds || b.holds[k] == detail::kBothHold ||
             (b.holds[k] == 0 && b.beam_radius[k] == 0),
         "bonds/holds");
  need(setting_valid(Field{"material"}, b.material), "bonds/material");
  for (const BreakEvent& e : s.break_events)
    need(e.id_a >= 0 && e.id_b >= 0 && e.id_a < std::int64_t(n) && e.id_b < std::int64_t(n) &&
             std::uint8_t(e.mode) <= 2 && std::uint8_t(e.kind) <= 1,
         "breaks");

  // Walls and meshes.
  const auto& wl = s.walls;
  for (const auto& mesh : wl.meshes) {
    const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
    for (const Vec3& v : mesh.vertices) need(finite3(v), "mesh vertex");
    for (const auto& t : mesh.triangles)
      for (int c : t) need(c >= 0 && std::size_t(c) < nv, "mesh triangle refers to no vertex");
    need(mesh.owns.size() == nt && mesh.vertex_start.size() == nv + 1, "mesh owns or vertex_start");
    need(mesh.vertex_start.front() == 0 && std::size_t(mesh.vertex_start.back()) == mesh.vertex_triangles.size(),
         "mesh vertex_start");
    for (std::size_t v = 0; v < nv; ++v) need(mesh.vertex_start[v] <= mesh.vertex_start[v + 1], "mesh vertex_start");
    for (auto t : mesh.vertex_triangles) need(t >= 0 && std::size_t(t) < nt, "mesh vertex_triangles");
  }
  for (const auto& w : wl.walls) {
    need(w.kind == detail::Wall::Kind::plane || w.kind == detail::Wall::Kind::mesh, "wall kind");
    need(w.kind != detail::Wall::Kind::mesh || (w.mesh >= 0 && std::size_t(w.mesh) < wl.meshes.size()), "wall mesh");
    need(finite3(w.point) && finite3(w.velocity) && finite3(w.displacement) && finite3(w.displacement_at_build) &&
             finite3(w.force),
         "wall state");
    need(w.kind != detail::Wall::Kind::plane || std::fabs(norm(w.normal) - 1) < 1e-6, "plane normal");
    const ContactMaterial& m = w.material;
    need(m.kn > 0 && finite(m.kn) && m.ks >= 0 && finite(m.ks) && m.friction >= 0 && finite(m.friction),
         "wall material");
  }
  const auto& wc = wl.contacts;
  for (const auto* c : {&wc.nx, &wc.ny, &wc.nz, &wc.fsx, &wc.fsy, &wc.fsz, &wc.fn, &wc.overlap})
    need(c->size() >= wc.n, "wall_contacts columns");
  need(wc.particle.size() >= wc.n && wc.wall.size() >= wc.n && wc.facet.size() >= wc.n, "wall_contacts columns");
  for (std::size_t k = 0; k < wc.n; ++k) {
    need(wc.particle[k] >= 0 && std::size_t(wc.particle[k]) < n, "wall contact refers to no particle");
    need(wc.wall[k] >= 0 && std::size_t(wc.wall[k]) < wl.walls.size(), "wall contact refers to no wall");
    const auto& w = wl.walls[std::size_t(wc.wall[k])];
    if (w.kind == detail::Wall::Kind::mesh)
      need(wc.facet[k] >= 0 && std::size_t(wc.facet[k]) < wl.meshes[std::size_t(w.mesh)].triangles.size(),
           "wall contact refers to no triangle");
    for (const auto* c : {&wc.nx, &wc.ny, &wc.nz, &wc.fsx, &wc.fsy, &wc.fsz, &wc.fn, &wc.overlap})
      need(finite((*c)[k]), "wall contact value");
  }
  for (std::size_t k = 0; k < wc.start.size(); ++k)
    need(wc.start[k] >= 0 && std::size_t(wc.start[k]) <= wc.n && (k == 0 || wc.start[k - 1] <= wc.start[k]),
         "wall_contacts/start");
  need(s.need_rebuild || wc.start.empty() || wc.start.size() == n + 1, "wall_contacts/start");

  need(!s.cache.idle_valid || s.cache.idle.size() == n, "run/idle");
  // Groups: members and inert members partition the particles that name the group.
  std::vector<std::size_t> named(s.groups.size(), 0);
  for (std::size_t i = 0; i < n; ++i)
    if (p.group[i] >= 0) ++named[std::size_t(p.group[i])];
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    const auto& grp = s.groups[g];
    for (const auto* list : {&grp.members, &grp.inert})
      for (std::size_t k = 0; k < list->size(); ++k) {
        const auto i = (*list)[k];
        need(i >= 0 && std::size_t(i) < n && p.group[std::size_t(i)] == std::int32_t(g) &&
                 (k == 0 || (*list)[k - 1] < i) && (list == &grp.inert) == (p.inert[std::size_t(i)] != 0),
             "group " + std::to_string(g) + " members");
      }
    need(grp.members.size() + grp.inert.size() == named[g], "group " + std::to_string(g) + " members");
    // The idle split: busy members are members, in order; the idle flags cover the particles.
    for (std::size_t k = 0; k < grp.busy.size(); ++k) {
      const auto i = grp.busy[k];
      need(i >= 0 && std::size_t(i) < n && p.group[std::size_t(i)] == std::int32_t(g) && (k == 0 || grp.busy[k - 1] < i),
           "group " + std::to_string(g) + " busy members");
    }
    need(finite3(grp.idle_shift) && finite(grp.idle_mass) && finite(grp.idle_base), "group " + std::to_string(g) + " idle state");
    need(grp.mass > 0 && finite(grp.mass) && finite(grp.inert_mass) && finite(grp.contact_stiffness) &&
             finite3(grp.centre) && finite3(grp.velocity) && finite3(grp.angular_velocity) &&
             finite3(grp.applied) && finite3(grp.force) && finite3(grp.torque) && finite3(grp.inert_shift) &&
             finite3(grp.servo_origin) && finite3(grp.servo_integral),
         "group " + std::to_string(g) + " state");
    const GroupMotion& m = grp.motion;
    for_each_field(m, [&](const Field& f, const auto& v) {
      need(setting_valid(f, v), "group " + std::to_string(g) + " motion: " + f.name);
    });
    for (const Servo& sv : m.servo)  // every axis's, used or not: the file holds all three
      need(setting_valid(Field{"servo"}, sv), "group " + std::to_string(g) + " motion: servo");
    need(m.rotation != Dof::servo, "group " + std::to_string(g) + " motion: rotation");
  }
}

}  // namespace

void World::save(const std::string& path) const {
  io::h5::quiet_errors();
  io::AtomicFile file(path);
  std::vector<unsigned char> image;
  {
    // Built in memory, then written by us: a full disk is reported here, before the rename, and
    // the previous file under `path` stays as it was (io::h5::create_file).
    const io::h5::Handle h = io::h5::create_file(file.temp_path());
    Writer w{h, path};
    int version = kCheckpointVersion;
    w.scalar("asperity_checkpoint_version", version);
    visit(w, const_cast<State&>(*state_));  // the writer only reads (and fills the fn and U columns from the records)
    image = io::h5::file_image(h, path, kMagic);
  }
  io::write_bytes(file.temp_path(), image, path, true);
  file.commit();
}

World World::load(const std::string& path, int threads, const std::string& simd) {
  io::h5::quiet_errors();
  if (threads < 0 || threads > kMaxThreads)
    throw Error("load: threads " + std::to_string(threads) + " outside 0.." + std::to_string(kMaxThreads));
  // The whole file, checked before HDF5 sees it (older checkpoints have no header: HDF5 and the
  // checks after loading are all they get), then opened from the bytes read.
  bool had_header = false;
  std::vector<unsigned char> bytes = io::h5::read_checked(path, kMagic, &had_header);
  io::h5::Handle h = io::h5::open_image(std::move(bytes), path);
  Reader r{h, path};
  int version = 0;
  r.scalar("asperity_checkpoint_version", version);
  if (version < 1 || version > kCheckpointVersion)
    throw Error("checkpoint '" + path + "' has version " + std::to_string(version) +
                ", this build reads versions 1 to " + std::to_string(kCheckpointVersion));
  if (version >= 5 && !had_header) throw Error("checkpoint '" + path + "' is damaged: its header is missing");
  r.version = version;
  World world;
  State& s = world.state();
  visit(r, s);
  validate(s, path);
  s.settings.threads = threads;
  s.settings.simd = simd;
  s.ctx.kernels = &kernels::select_kernels(simd);
  // Derived data, rebuilt deterministically.
  s.p.capacity = s.p.x.size();
  for (auto& mesh : s.walls.meshes) detail::bin_mesh(mesh);
  detail::build_incidence(s.p.n, s.pairs.a.data(), s.pairs.b.data(), s.pairs.n, s.incidence);
  {
    // The bond topology is derived; the kernel choices saved with it are kept (version 11).
    const auto c = s.cache;
    // With the idle split saved, the bonds inside the lazy groups leave the step now, as they had
    // in the saved run (the file holds one list; without a split the first step does this).
    if (s.cache.idle_valid) detail::settle_frozen_bonds(s);
    detail::refresh_bond_topology(s);
    if (version >= 11) {
      s.cache.spin_known = c.spin_known;
      s.cache.spin_reachable = c.spin_reachable;
      s.cache.spin_bonded = c.spin_bonded;
      s.cache.bond_moments_zero = c.bond_moments_zero;
      s.cache.bond_records = c.bond_records;
      s.cache.pair_records_sparse = c.pair_records_sparse;
    }
  }
  if (s.cache.idle_valid) detail::index_moved(s);  // the saved split's indexes
  return world;
}

}  // namespace asperity
