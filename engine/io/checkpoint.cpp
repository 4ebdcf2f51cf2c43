// Checkpoints: the whole state of a World in one HDF5 file, so that a run restarted from it
// continues bit for bit (design.md "Outputs"). Used to cache generated joint halves and to resume
// long runs.
//
// Design note: one function, visit(), lists every field once; the writer and the reader are two
// "archives" passed through it, so the two directions cannot drift apart. Derived data (cell
// grid, incidence lists, bonded partners, mesh bins) is rebuilt after loading by the same
// deterministic code that built it in the first place.
#include <hdf5.h>

#include <cstring>
#include <string>
#include <type_traits>

#include "asperity/io.hpp"
#include "io/hdf5_file.hpp"
#include "state.hpp"

namespace asperity {

namespace {

using detail::State;
constexpr int kCheckpointVersion = 5;  // 2: servo integral and integral time, group damping;
                                       // 3: rest overlaps (stress-free bonds);
                                       // 4: meshes' candidates within half the skin;
                                       // 5: rotation_lock_bonds

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
    items.resize(n);
  }
};

void visit_material(auto& io, const std::string& at, ContactMaterial& m) {
  io.scalar(at + "/kn", m.kn);
  io.scalar(at + "/ks", m.ks);
  io.scalar(at + "/friction", m.friction);
}

template <class Io>
void visit(Io& io, State& s) {
  // Settings (threads and SIMD are the loader's choice: results do not depend on them).
  WorldSettings& ws = s.settings;
  visit_material(io, "settings/contact", ws.contact);
  io.scalar("settings/density", ws.density);
  io.scalar("settings/local_damping", ws.local_damping);
  io.vec("settings/gravity", ws.gravity);
  io.flag("settings/rotation", ws.rotation);
  io.scalar("settings/skin", ws.skin);
  io.scalar("settings/dt", ws.dt);
  io.scalar("settings/dt_safety", ws.dt_safety);
  io.flag("settings/allow_dt_above_estimate", ws.allow_dt_above_estimate);
  io.scalar("settings/dt_interval", ws.dt_interval);
  io.flag("settings/track_energy", ws.track_energy);
  io.scalar("settings/reorder_interval", ws.reorder_interval);
  io.flag("settings/lock_bonded_rotation", ws.lock_bonded_rotation);
  if (io.version >= 5) io.scalar("settings/rotation_lock_bonds", ws.rotation_lock_bonds);

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
  for (auto [name, col] : {std::pair{"x", &p.x}, {"y", &p.y}, {"z", &p.z}, {"vx", &p.vx},
                           {"vy", &p.vy}, {"vz", &p.vz}, {"wx", &p.wx}, {"wy", &p.wy},
                           {"wz", &p.wz}, {"radius", &p.radius}, {"mass", &p.mass},
                           {"inv_mass", &p.inv_mass}, {"inertia", &p.inertia},
                           {"inv_inertia", &p.inv_inertia}, {"fx", &p.fx}, {"fy", &p.fy},
                           {"fz", &p.fz}, {"tx", &p.tx}, {"ty", &p.ty}, {"tz", &p.tz},
                           {"x0", &p.x0}, {"y0", &p.y0}, {"z0", &p.z0}, {"ax", &p.ax},
                           {"ay", &p.ay}, {"az", &p.az}})
    io.column(std::string("particles/") + name, *col);
  io.column("particles/density", p.density);
  io.column("particles/rotation_locked", p.rotation_locked);
  io.column("particles/group", p.group);
  io.column("particles/tag", p.tag);
  io.column("particles/flags", p.flags);
  io.column("particles/inert", p.inert);
  io.column("particles/id", p.id);
  io.column("particles/index_of_id", p.index_of_id);
  io.column("particles/user_rotation_locked", s.user_rotation_locked);

  // Pairs with their history, and the contacts broken bonds left behind.
  for (auto [at, q] : {std::pair{std::string("pairs"), &s.pairs}, {std::string("inherited"), &s.inherited}}) {
    io.scalar(at + "/n", q->n);
    io.scalar(at + "/padded", q->padded);
    io.column(at + "/a", q->a);
    io.column(at + "/b", q->b);
    if constexpr (std::is_same_v<Io, Writer>) q->columns_from_records();  // fn and U of the last step
    for (auto [name, col] : {std::pair{"nx", &q->nx}, {"ny", &q->ny}, {"nz", &q->nz},
                             {"fsx", &q->fsx}, {"fsy", &q->fsy}, {"fsz", &q->fsz},
                             {"fn", &q->fn}, {"overlap", &q->overlap}})
      io.column(at + "/" + name, *col);
    // Rest overlaps (stress-free bonds) since version 3; older files had none: all 0.
    if (io.version >= 3) io.column(at + "/rest", q->rest);
    else q->rest.assign(q->padded, 0.0);
    q->size_outputs();
  }

  // Bonds: one list, active and frozen together (the first step after loading freezes the same
  // ones again: State::frozen_bonds).
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
  for (auto [name, col] : {std::pair{"beam_radius", &b.beam_radius}, {"nx", &b.nx}, {"ny", &b.ny},
                           {"nz", &b.nz}, {"fsx", &b.fsx}, {"fsy", &b.fsy}, {"fsz", &b.fsz},
                           {"fn", &b.fn}, {"overlap", &b.overlap}, {"fbn", &b.fbn},
                           {"fbsx", &b.fbsx}, {"fbsy", &b.fbsy}, {"fbsz", &b.fbsz},
                           {"mbn", &b.mbn}, {"mbsx", &b.mbsx}, {"mbsy", &b.mbsy},
                           {"mbsz", &b.mbsz}, {"broken", &b.broken}})
    io.column(std::string("bonds/") + name, *col);
  if (io.version >= 3) {
    io.column("bonds/rest", b.rest);
    io.flag("bonds/rest_overlaps", s.rest_overlaps);
  } else {
    b.rest.assign(b.padded, 0.0);
  }
  b.size_outputs();
  io.scalar("bonds/material/beam_kn", b.material.beam_kn);
  io.scalar("bonds/material/beam_ks", b.material.beam_ks);
  io.scalar("bonds/material/radius_factor", b.material.radius_factor);
  io.scalar("bonds/material/tensile_strength", b.material.tensile_strength);
  io.flag("bonds/material/breakable", b.material.breakable);
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
    std::vector<std::uint8_t> mode(ev.size());
    for (std::size_t k = 0; k < ev.size(); ++k) {
      step[k] = ev[k].step;
      const double v[7] = {ev[k].time, ev[k].position.x, ev[k].position.y, ev[k].position.z,
                           ev[k].sigma, ev[k].tau, ev[k].released_energy};
      std::memcpy(&num[7 * k], v, sizeof v);
      ids[2 * k] = ev[k].id_a;
      ids[2 * k + 1] = ev[k].id_b;
      mode[k] = static_cast<std::uint8_t>(ev[k].mode);
    }
    io.column("breaks/step", step);
    io.column("breaks/values", num);
    io.column("breaks/ids", ids);
    io.column("breaks/mode", mode);
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
    visit_material(io, at + "/material", wall.material);
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
  for (auto [name, col] : {std::pair{"nx", &wc.nx}, {"ny", &wc.ny}, {"nz", &wc.nz},
                           {"fsx", &wc.fsx}, {"fsy", &wc.fsy}, {"fsz", &wc.fsz},
                           {"fn", &wc.fn}, {"overlap", &wc.overlap}})
    io.column(std::string("wall_contacts/") + name, *col);

  // Rigid groups.
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
    GroupMotion& m = grp.motion;
    std::vector<std::uint8_t> modes{std::uint8_t(m.translation[0]), std::uint8_t(m.translation[1]),
                                    std::uint8_t(m.translation[2]), std::uint8_t(m.rotation)};
    io.column(at + "/modes", modes);
    for (int k = 0; k < 3; ++k) m.translation[k] = static_cast<Dof>(modes.at(k));
    m.rotation = static_cast<Dof>(modes.at(3));
    io.vec(at + "/motion_velocity", m.velocity);
    io.vec(at + "/motion_angular_velocity", m.angular_velocity);
    for (int k = 0; k < 3; ++k) {
      const std::string sv = at + "/servo" + std::to_string(k);
      io.scalar(sv + "/target_force", m.servo[k].target_force);
      io.scalar(sv + "/stiffness", m.servo[k].stiffness);
      io.scalar(sv + "/gain", m.servo[k].gain);
      io.scalar(sv + "/relaxation", m.servo[k].relaxation);
      io.scalar(sv + "/max_velocity", m.servo[k].max_velocity);
      if (io.version >= 2) io.scalar(sv + "/integral_time", m.servo[k].integral_time);
    }
    if (io.version >= 2) io.scalar(at + "/damping", m.damping);
  }
}

}  // namespace

void World::save(const std::string& path) const {
  io::h5::quiet_errors();
  io::AtomicFile file(path);
  {
    io::h5::Handle h(H5Fcreate(file.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (!h.valid()) throw Error("cannot write checkpoint '" + path + "'");
    Writer w{h, path};
    int version = kCheckpointVersion;
    w.scalar("asperity_checkpoint_version", version);
    detail::sync_lazy(const_cast<State&>(*state_));  // idle members to where they are (not observable)
    visit(w, const_cast<State&>(*state_));  // the writer only reads (and fills the fn and U columns from the records)
  }
  file.commit();
}

World World::load(const std::string& path, int threads, const std::string& simd) {
  io::h5::quiet_errors();
  if (H5Fis_hdf5(path.c_str()) <= 0) throw Error("cannot read checkpoint '" + path + "': not an HDF5 file");
  io::h5::Handle h(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!h.valid()) throw Error("cannot read checkpoint '" + path + "'");
  Reader r{h, path};
  int version = 0;
  r.scalar("asperity_checkpoint_version", version);
  if (version < 1 || version > kCheckpointVersion)
    throw Error("checkpoint '" + path + "' has version " + std::to_string(version) +
                ", this build reads versions 1 to " + std::to_string(kCheckpointVersion));
  r.version = version;
  World world;
  State& s = world.state();
  visit(r, s);
  s.settings.threads = threads;
  s.settings.simd = simd;
  s.kernels = &kernels::select_kernels(simd);
  // Derived data, rebuilt deterministically.
  s.p.capacity = s.p.x.size();
  for (auto& mesh : s.walls.meshes) detail::bin_mesh(mesh);
  detail::build_incidence(s.p.n, s.pairs.a.data(), s.pairs.b.data(), s.pairs.n, s.incidence);
  detail::refresh_bond_topology(s);
  return world;
}

}  // namespace asperity
