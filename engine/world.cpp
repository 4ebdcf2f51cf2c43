// World: the public API over the stores and the step driver. Every function checks its input
// and says what was wrong; ids are stable, indices are internal.
#include "asperity/world.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "bodies/groups.hpp"
#include "field_problems.hpp"
#include "bodies/mesh.hpp"
#include "kernels/bond_law.hpp"
#include "stages/bonds.hpp"
#include "neighbor/build.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"
#include "step.hpp"

namespace asperity {

using detail::Change;
using detail::changed;
using detail::State;

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

std::string num(double v) { return short_number_text(v); }

std::string vec_text(const Vec3& v) {
  return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}

// A value against its field (field_problems.hpp): `where` names the call, e.g. "set_dt_safety: ".
template <class T>
void check_value(const std::string& where, const Field& f, const T& v) {
  const std::string problem = detail::field_problem(f, v);
  require(problem.empty(), where + problem);
}

void require_finite(const Vec3& v, const char* what) { check_value("", Field{what}, v); }

// Positions (particles, plane points, mesh vertices) within kMaxCoordinate of the origin: the
// cell grids take differences of coordinates, which must not overflow.
void require_position(const Vec3& v, const char* what) {
  require_finite(v, what);
  require(std::fabs(v.x) <= kMaxCoordinate && std::fabs(v.y) <= kMaxCoordinate &&
              std::fabs(v.z) <= kMaxCoordinate,
          std::string(what) + " " + vec_text(v) + " outside [-" + num(kMaxCoordinate) + ", " +
              num(kMaxCoordinate) + "] m on some axis");
}

void require_radius(double r, const std::string& what) {
  require(r >= kMinRadius && r <= kMaxRadius,
          what + " " + num(r) + " outside [" + num(kMinRadius) + ", " + num(kMaxRadius) + "] m");
}

void check_material(const ContactMaterial& m, const std::string& where) {
  check_value("", Field{where.c_str()}, m);
}
// The field of WorldSettings called `name`.
Field setting_field(const char* name) {
  WorldSettings defaults;
  Field found{nullptr};
  for_each_setting(defaults, [&](const Field& f, const auto&) {
    if (std::string_view(f.name) == name) found = f;
  });
  return found;
}
void check_setting(const char* where, const char* name, double v) {
  check_value(std::string(where) + ": ", setting_field(name), v);
}

void set_mass(detail::ParticleStore& p, std::size_t i) {
  const double r = p.radius[i];
  p.mass[i] = p.density[i] * 4.0 / 3.0 * std::numbers::pi * r * r * r;  // [3-4]
  p.inertia[i] = 0.4 * p.mass[i] * r * r;
  p.inv_mass[i] = 1.0 / p.mass[i];
  p.inv_inertia[i] = 1.0 / p.inertia[i];
}

void recompute_group(State& s, detail::Group& g) {
  detail::sync_lazy(s);
  const auto& p = s.p;
  g.mass = 0;
  g.inert_mass = 0;
  Vec3 c{0, 0, 0};
  for (auto i : g.members) {
    g.mass += p.mass[i];
    c += Vec3{p.x[i], p.y[i], p.z[i]} * p.mass[i];
  }
  for (auto i : g.inert) {
    g.mass += p.mass[i];
    g.inert_mass += p.mass[i];
    c += Vec3{p.x[i], p.y[i], p.z[i]} * p.mass[i];
  }
  g.centre = g.mass > 0 ? c / g.mass : Vec3{};
}

// Inert and idle group members are moved lazily; reads bring them up to date first. This changes no
// observable state, so const readers may do it.
const State& synced(const State& s) {
  bool pending = false;
  for (const auto& g : s.groups) pending = pending || !(g.inert_shift == Vec3{}) || !(g.idle_shift == Vec3{});
  if (pending) detail::sync_lazy(const_cast<State&>(s));
  return s;
}

}  // namespace

double Energies::balance_error(const Energies& initial) const {
  const double input = (boundary_work - initial.boundary_work) + (gravity_work - initial.gravity_work);
  const double out = (kinetic - initial.kinetic) + (strain - initial.strain) +
                     (friction - initial.friction) + (damping - initial.damping) +
                     (released - initial.released);
  return input - out;
}

World::World(WorldSettings settings) : state_(std::make_unique<State>()) {
  State& s = *state_;
  for_each_setting(settings, [](const Field& f, const auto& v) { check_value("", f, v); });
  s.ctx.kernels = &kernels::select_kernels(settings.simd);
  s.ctx.max_threads = omp_get_max_threads();
  s.settings = settings;
  // The first reading of the machine's load, so that the automatic thread count knows it by the
  // time the scene is built and stepping starts (core/load.hpp).
  detail::watch_load(s);
  s.dt_fixed = settings.dt > 0;
  s.dt = settings.dt;
  s.p.resize(0);
  s.pairs.resize(0);
  s.pairs.fill_padding(s.p.null_a(), s.p.null_b());
  s.bonds.resize(0);
  s.bonds.fill_padding(s.p.null_a(), s.p.null_b());
  s.cache.partner_start.assign(1, 0);
  s.any_rotating = settings.rotation;
}

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

const WorldSettings& World::settings() const { return state_->settings; }

namespace {
std::size_t index_of(const State& s, std::int64_t id) {
  if (id < 0 || id >= static_cast<std::int64_t>(s.p.index_of_id.size()))
    throw Error("no particle with id " + std::to_string(id) + " (valid ids: 0.." +
                std::to_string(static_cast<std::int64_t>(s.p.index_of_id.size()) - 1) + ")");
  return static_cast<std::size_t>(s.p.index_of_id[id]);
}
int check_wall(const State& s, int wall) {
  if (wall < 0 || wall >= int(s.walls.walls.size()))
    throw Error("no wall " + std::to_string(wall) + " (walls: 0.." +
                std::to_string(int(s.walls.walls.size()) - 1) + ")");
  return wall;
}
int check_group(const State& s, int group) {
  if (group < 0 || group >= int(s.groups.size()))
    throw Error("no group " + std::to_string(group) + " (groups: 0.." +
                std::to_string(int(s.groups.size()) - 1) + ")");
  return group;
}
}  // namespace

std::int64_t World::add_particle(Vec3 position, double radius, double density) {
  const double xyz[3] = {position.x, position.y, position.z};
  return add_particles(std::span<const double>(xyz, 3), std::span<const double>(&radius, 1), density);
}

std::int64_t World::add_particles(std::span<const double> xyz, std::span<const double> radii,
                                  double density) {
  State& s = *state_;
  require(xyz.size() == 3 * radii.size(), "add_particles: " + std::to_string(xyz.size()) +
                                              " coordinates for " + std::to_string(radii.size()) +
                                              " radii (expected 3 per particle)");
  // density <= 0 means the default; NaN is not "<= 0" and is refused with the rest.
  const double rho = density <= 0 ? s.settings.density : density;
  check_setting("add_particle", "density", rho);
  for (std::size_t k = 0; k < radii.size(); ++k) {
    const std::string which = radii.size() > 1 ? " of particle " + std::to_string(k + 1) : "";
    require_radius(radii[k], "add_particle: radius" + which);
    require_position({xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]},
                     ("add_particle: position" + which).c_str());
  }
  auto& p = s.p;
  const std::size_t first = p.n;
  const std::int64_t first_id = static_cast<std::int64_t>(p.index_of_id.size());
  p.resize(p.n + radii.size());
  for (std::size_t k = 0; k < radii.size(); ++k) {
    const std::size_t i = first + k;
    p.x[i] = xyz[3 * k];
    p.y[i] = xyz[3 * k + 1];
    p.z[i] = xyz[3 * k + 2];
    p.vx[i] = p.vy[i] = p.vz[i] = p.wx[i] = p.wy[i] = p.wz[i] = 0;
    p.fx[i] = p.fy[i] = p.fz[i] = p.tx[i] = p.ty[i] = p.tz[i] = 0;
    p.radius[i] = radii[k];
    p.density[i] = rho;
    set_mass(p, i);
    p.rotation_locked[i] = s.settings.rotation ? 0 : 1;
    p.group[i] = -1;
    p.id[i] = first_id + std::int64_t(k);
    p.index_of_id.push_back(std::int64_t(i));
  }
  s.cache.partner_start.resize(p.n + 1, s.cache.partner_start.empty() ? 0 : s.cache.partner_start.back());
  s.any_rotating = s.any_rotating || s.settings.rotation;
  // Bond and pair padding point at null particles, whose indices moved with the new count.
  s.bonds.fill_padding(p.null_a(), p.null_b());
  changed(s, Change::added);
  changed(s, Change::particles);
  return first_id;
}

std::size_t World::particle_count() const { return state_->p.n; }

#define ASPERITY_VEC(col) \
  Vec3 { p.col##x[i], p.col##y[i], p.col##z[i] }

Vec3 World::position(std::int64_t id) const {
  const auto& p = synced(*state_).p;
  const auto i = index_of(*state_, id);
  return {p.x[i], p.y[i], p.z[i]};
}
Vec3 World::velocity(std::int64_t id) const {
  const auto& p = synced(*state_).p;
  const auto i = index_of(*state_, id);
  return ASPERITY_VEC(v);
}
Vec3 World::angular_velocity(std::int64_t id) const {
  const auto& p = state_->p;
  const auto i = index_of(*state_, id);
  return ASPERITY_VEC(w);
}
Vec3 World::force(std::int64_t id) const {
  const auto& p = state_->p;
  const auto i = index_of(*state_, id);
  return ASPERITY_VEC(f);
}
Vec3 World::torque(std::int64_t id) const {
  const auto& p = state_->p;
  const auto i = index_of(*state_, id);
  return ASPERITY_VEC(t);
}
#undef ASPERITY_VEC
double World::radius(std::int64_t id) const { return state_->p.radius[index_of(*state_, id)]; }
double World::mass(std::int64_t id) const { return state_->p.mass[index_of(*state_, id)]; }
int World::group_of(std::int64_t id) const { return state_->p.group[index_of(*state_, id)]; }

void World::set_position(std::int64_t id, Vec3 x) {
  require_position(x, "set_position: position");
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  require(p.group[i] < 0, "particle " + std::to_string(id) + " belongs to group " +
                              std::to_string(p.group[i]) + ": move the group, not the member");
  p.x[i] = x.x;
  p.y[i] = x.y;
  p.z[i] = x.z;
  changed(*state_, Change::particles);
}
void World::set_velocity(std::int64_t id, Vec3 v) {
  require_finite(v, "velocity");
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  require(p.group[i] < 0, "particle " + std::to_string(id) + " belongs to group " +
                              std::to_string(p.group[i]) + ": set the group's motion instead");
  p.vx[i] = v.x;
  p.vy[i] = v.y;
  p.vz[i] = v.z;
  changed(*state_, Change::velocities);
}
void World::set_angular_velocity(std::int64_t id, Vec3 w) {
  require_finite(w, "angular velocity");
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  require(!p.rotation_locked[i], "particle " + std::to_string(id) +
                                     " cannot rotate (rotation locked or disabled in the world)");
  p.wx[i] = w.x;
  p.wy[i] = w.y;
  p.wz[i] = w.z;
  changed(*state_, Change::spins);
}
void World::set_radius(std::int64_t id, double r) {
  require_radius(r, "set_radius: radius");
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  p.radius[i] = r;
  set_mass(p, i);
  for (auto& g : state_->groups) recompute_group(*state_, g);
  changed(*state_, Change::particles);
}
void World::scale_radii(double factor) {
  require(factor > 0 && std::isfinite(factor), "scale_radii: factor must be > 0, got " + num(factor));
  auto& p = state_->p;
  // Every new radius within bounds before any changes (a failed call leaves the world as it was).
  for (std::size_t i = 0; i < p.n; ++i)
    require_radius(p.radius[i] * factor, "scale_radii: factor " + num(factor) + " makes the radius of particle " +
                                             std::to_string(p.id[i] + 1));
  for (std::size_t i = 0; i < p.n; ++i) {
    p.radius[i] *= factor;
    set_mass(p, i);
  }
  for (auto& g : state_->groups) recompute_group(*state_, g);
  state_->skin = 0;  // re-derive an automatic skin from the new radii
  changed(*state_, Change::particles);
}
void World::set_applied_force(std::int64_t id, Vec3 f) {
  require_finite(f, "applied force");
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  if (!p.has_applied) {
    p.has_applied = true;
    for (auto* c : {&p.ax, &p.ay, &p.az}) c->assign(p.capacity, 0.0);
  }
  p.ax[i] = f.x;
  p.ay[i] = f.y;
  p.az[i] = f.z;
  changed(*state_, Change::applied_forces);
}
void World::set_rotation_locked(std::int64_t id, bool locked) {
  const auto i = index_of(*state_, id);
  require(state_->settings.rotation || locked,
          "rotation is disabled in this world (settings.rotation = false)");
  state_->p.user_rotation_locked[i] = locked ? 1 : 0;
  detail::refresh_bond_topology(*state_);
}

namespace {
std::vector<double> by_id(const State& s, const AVec<double>& a,
                          const AVec<double>* b = nullptr,
                          const AVec<double>* c = nullptr) {
  const auto& p = s.p;
  const std::size_t per = b ? 3 : 1;
  std::vector<double> out(p.n * per);
  for (std::size_t id = 0; id < p.n; ++id) {
    const auto i = p.index_of_id[id];
    out[per * id] = a[i];
    if (b) {
      out[per * id + 1] = (*b)[i];
      out[per * id + 2] = (*c)[i];
    }
  }
  return out;
}
}  // namespace

std::vector<double> World::positions() const { const auto& p = synced(*state_).p; return by_id(*state_, p.x, &p.y, &p.z); }
std::vector<double> World::velocities() const { const auto& p = synced(*state_).p; return by_id(*state_, p.vx, &p.vy, &p.vz); }
std::vector<double> World::forces() const { const auto& p = state_->p; return by_id(*state_, p.fx, &p.fy, &p.fz); }
std::vector<double> World::radii() const { return by_id(*state_, state_->p.radius); }

// --- walls ---------------------------------------------------------------------------------

int World::add_plane(Vec3 point, Vec3 normal, ContactMaterial material) {
  require_position(point, "add_plane: point");
  require_finite(normal, "add_plane: normal");
  const double big = std::max({std::fabs(normal.x), std::fabs(normal.y), std::fabs(normal.z)});
  require(big > 0, "add_plane: normal must be non-zero, got " + vec_text(normal));
  double len = norm(normal);
  if (!(len > 0 && std::isfinite(len))) {
    // |n|^2 of {0, 0, 1e200} overflows (of {1e-200, 0, 0} underflows): scaled by its largest
    // component first. Only then: the division would round every other normal differently.
    normal = normal / big;
    len = norm(normal);
  }
  check_material(material, "plane material");
  detail::Wall w;
  w.kind = detail::Wall::Kind::plane;
  w.point = point;
  w.normal = normal / len;
  w.material = material;
  state_->walls.walls.push_back(w);
  changed(*state_, Change::particles);
  return int(state_->walls.walls.size()) - 1;
}

int World::add_mesh(std::span<const Vec3> vertices, std::span<const std::array<int, 3>> triangles,
                    ContactMaterial material) {
  check_material(material, "mesh material");
  require(!triangles.empty(), "add_mesh: no triangles");
  for (const auto& v : vertices) require_position(v, "add_mesh: vertex");
  detail::Mesh mesh;
  mesh.vertices.assign(vertices.begin(), vertices.end());
  mesh.triangles.assign(triangles.begin(), triangles.end());
  const int nv = int(vertices.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      require(triangles[t][k] >= 0 && triangles[t][k] < nv,
              "add_mesh: triangle " + std::to_string(t) + " refers to vertex " +
                  std::to_string(triangles[t][k]) + " (vertices: 0.." + std::to_string(nv - 1) + ")");
  // A triangle without area has no normal: the contact kernel would divide by zero.
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 &a = vertices[triangles[t][0]], &b = vertices[triangles[t][1]], &c = vertices[triangles[t][2]];
    const Vec3 u = b - a, v = c - a;
    const double scale = std::max({norm(u), norm(v), norm(c - b)});
    require(scale > 0 && norm(cross(u, v)) > 1e-12 * scale * scale,
            "add_mesh: triangle " + std::to_string(t) + " is degenerate (its corners are on one line)");
  }
  // Ownership of shared edges and vertices: the lowest-numbered triangle owns them.
  std::map<std::pair<int, int>, int> edge_owner;
  std::vector<int> vertex_owner(vertices.size(), -1);
  for (int t = 0; t < int(triangles.size()); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      edge_owner.try_emplace({std::min(a, b), std::max(a, b)}, t);
      if (vertex_owner[a] < 0) vertex_owner[a] = t;
    }
  }
  mesh.owns.assign(triangles.size(), 0);
  for (int t = 0; t < int(triangles.size()); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      if (edge_owner[{std::min(a, b), std::max(a, b)}] == t) mesh.owns[t] |= std::uint8_t(1 << k);
      if (vertex_owner[a] == t) mesh.owns[t] |= std::uint8_t(1 << (3 + k));
    }
  }
  mesh.vertex_start.assign(vertices.size() + 1, 0);
  for (const auto& tri : triangles)
    for (int k = 0; k < 3; ++k) ++mesh.vertex_start[tri[k] + 1];
  for (std::size_t v = 0; v < vertices.size(); ++v) mesh.vertex_start[v + 1] += mesh.vertex_start[v];
  mesh.vertex_triangles.resize(mesh.vertex_start.back());
  {
    std::vector<std::int32_t> fill(mesh.vertex_start.begin(), mesh.vertex_start.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) mesh.vertex_triangles[fill[triangles[t][k]]++] = std::int32_t(t);
  }
  detail::bin_mesh(mesh);
  state_->walls.meshes.push_back(std::move(mesh));
  detail::Wall w;
  w.kind = detail::Wall::Kind::mesh;
  w.mesh = int(state_->walls.meshes.size()) - 1;
  w.material = material;
  state_->walls.walls.push_back(w);
  changed(*state_, Change::particles);
  return int(state_->walls.walls.size()) - 1;
}

void World::set_wall_velocity(int wall, Vec3 v) {
  require_finite(v, "wall velocity");
  state_->walls.walls[check_wall(*state_, wall)].velocity = v;
}
Vec3 World::wall_velocity(int wall) const { return state_->walls.walls[check_wall(*state_, wall)].velocity; }
Vec3 World::wall_displacement(int wall) const { return state_->walls.walls[check_wall(*state_, wall)].displacement; }
Vec3 World::wall_force(int wall) const { return state_->walls.walls[check_wall(*state_, wall)].force; }
void World::remove_wall(int wall) {
  auto& w = state_->walls.walls[check_wall(*state_, wall)];
  w.removed = true;
  w.velocity = {0, 0, 0};
  w.force = {0, 0, 0};
  changed(*state_, Change::particles);
}
std::size_t World::wall_count() const { return state_->walls.walls.size(); }

// --- groups --------------------------------------------------------------------------------

namespace {
// Every check of set_group_motion, so that add_group can make them before it changes anything.
void check_motion(const State& s, const GroupMotion& motion, bool has_inert, const std::string& who) {
  const std::string at = who + ": ";
  for_each_field(motion, [&](const Field& f, const auto& v) { check_value(at, f, v); });
  require(s.settings.rotation || motion.rotation == Dof::fixed,
          at + "group rotation needs a world with rotation enabled");
  require(motion.rotation != Dof::servo, at + "rotation cannot be servo-controlled (translation only)");
  require(!has_inert || motion.rotation == Dof::fixed,
          at + "the group has inert members: its rotation must stay fixed");
  const char* axis[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (motion.translation[k] != Dof::servo) continue;
    const Servo& sv = motion.servo[k];
    const std::string where = at + "servo on " + axis[k] + ": ";
    for_each_field(sv, [&](const Field& f, double v) { check_value(where, f, v); });
  }
}
}  // namespace

int World::add_group(std::span<const std::int64_t> ids, GroupMotion motion) {
  State& s = *state_;
  require(!ids.empty(), "add_group: no particles given");
  // Everything is checked before the world changes: a failed call leaves no half-made group.
  check_motion(s, motion, false, "add_group");
  const int g = int(s.groups.size());
  detail::Group grp;
  for (auto id : ids) {
    const auto i = index_of(s, id);
    require(s.p.group[i] < 0, "add_group: particle " + std::to_string(id) +
                                  " already belongs to group " + std::to_string(s.p.group[i]));
    grp.members.push_back(std::int32_t(i));
  }
  std::sort(grp.members.begin(), grp.members.end());
  require(std::adjacent_find(grp.members.begin(), grp.members.end()) == grp.members.end(),
          "add_group: a particle id is listed twice");
  for (auto i : grp.members) s.p.group[i] = g;
  recompute_group(s, grp);
  grp.velocity = {0, 0, 0};
  s.groups.push_back(std::move(grp));
  set_group_motion(g, motion);
  changed(s, Change::particles);
  return g;
}

void World::set_group_motion(int group, const GroupMotion& motion) {
  auto& g = state_->groups[check_group(*state_, group)];
  check_motion(*state_, motion, !g.inert.empty(), "set_group_motion");
  // An axis whose servo stays as it was (same target, stiffness and integral time; e.g. only the
  // shear velocity of another axis changes) keeps its CNS origin and its integral: a reset would
  // kick the platen at every change of the other axes.
  for (int k = 0; k < 3; ++k) {
    const Servo &a = g.motion.servo[k], &b = motion.servo[k];
    const bool same = g.motion.translation[k] == Dof::servo && motion.translation[k] == Dof::servo &&
                      a.target_force == b.target_force && a.stiffness == b.stiffness &&
                      a.integral_time == b.integral_time;
    if (!same) {
      g.servo_origin[k] = g.centre[k];
      g.servo_integral[k] = 0;
    }
  }
  g.motion = motion;
  changed(*state_, Change::group_motion);
}
const GroupMotion& World::group_motion(int group) const { return state_->groups[check_group(*state_, group)].motion; }
void World::set_group_applied_force(int group, Vec3 f) {
  require_finite(f, "group applied force");
  state_->groups[check_group(*state_, group)].applied = f;
}
Vec3 World::group_force(int group) const { return state_->groups[check_group(*state_, group)].force; }
Vec3 World::group_torque(int group) const { return state_->groups[check_group(*state_, group)].torque; }
Vec3 World::group_position(int group) const { return state_->groups[check_group(*state_, group)].centre; }
Vec3 World::group_impulse(int group) const { return state_->groups[check_group(*state_, group)].impulse; }
Vec3 World::group_velocity(int group) const { return state_->groups[check_group(*state_, group)].velocity; }
double World::group_mass(int group) const { return state_->groups[check_group(*state_, group)].mass; }
std::vector<std::int64_t> World::group_members(int group) const {
  std::vector<std::int64_t> out;
  const detail::Group& g = state_->groups[check_group(*state_, group)];
  // Every member, the inert ones too (they move with the group, only lazily).
  for (const auto* list : {&g.members, &g.inert})
    for (auto i : *list) out.push_back(state_->p.id[i]);
  std::sort(out.begin(), out.end());
  return out;
}
std::size_t World::group_count() const { return state_->groups.size(); }

void World::set_inert(std::span<const std::int64_t> ids, bool inert) {
  State& s = *state_;
  detail::sync_lazy(s);
  std::vector<std::size_t> idx;
  for (auto id : ids) {
    const auto i = index_of(s, id);
    require(s.p.group[i] >= 0, "set_inert: particle " + std::to_string(id) +
                                   " is not in a rigid group (only group members can be inert)");
    require(s.groups[s.p.group[i]].motion.rotation == Dof::fixed,
            "set_inert: group " + std::to_string(s.p.group[i]) + " rotates; inert members need a "
            "group whose rotation is fixed");
    idx.push_back(i);
  }
  for (auto i : idx) s.p.inert[i] = inert ? 1 : 0;
  for (auto& g : s.groups) {
    std::vector<std::int32_t> all(g.members);
    all.insert(all.end(), g.inert.begin(), g.inert.end());
    std::sort(all.begin(), all.end());
    g.members.clear();
    g.inert.clear();
    for (auto i : all) (s.p.inert[i] ? g.inert : g.members).push_back(i);
    recompute_group(s, g);
  }
  changed(s, Change::particles);
}

std::size_t World::inert_count() const {
  std::size_t n = 0;
  for (const auto& g : state_->groups) n += g.inert.size();
  return n;
}

// --- labels --------------------------------------------------------------------------------

void World::set_tag(std::span<const std::int64_t> ids, int tag) {
  for (auto id : ids) state_->p.tag[index_of(*state_, id)] = tag;
}
int World::tag(std::int64_t id) const { return state_->p.tag[index_of(*state_, id)]; }
void World::set_flags(std::span<const std::int64_t> ids, std::uint8_t flags) {
  for (auto id : ids) state_->p.flags[index_of(*state_, id)] = flags;
}
std::uint8_t World::flags(std::int64_t id) const { return state_->p.flags[index_of(*state_, id)]; }

ContactSummary World::contact_summary(int tag_a, int tag_b, std::uint8_t flag_mask) const {
  const State& s = *state_;
  const auto& p = s.p;
  const auto& q = s.pairs;
  ContactSummary out;
  for (std::size_t k = 0; k < q.n; ++k) {
    const double U = q.overlap_at(k);
    if (!(U > 0)) continue;
    const auto a = q.a[k], b = q.b[k];
    double sign;  // force on the tag_b particle is sign * (force on b)
    if (p.tag[a] == tag_a && p.tag[b] == tag_b) sign = 1;
    else if (p.tag[a] == tag_b && p.tag[b] == tag_a) sign = -1;
    else continue;
    const Vec3 f = (Vec3{q.nx[k], q.ny[k], q.nz[k]} * q.normal_force(k) + Vec3{q.fsx[k], q.fsy[k], q.fsz[k]}) * sign;
    const double Rm = 0.5 * (p.radius[a] + p.radius[b]);
    ++out.count;
    out.area += 3.14159265358979323846 * (Rm * U - 0.25 * U * U);  // [4-1, 4-2]
    out.force += f;
    if (flag_mask && ((p.flags[a] | p.flags[b]) & flag_mask)) {
      ++out.flagged_count;
      out.flagged_force += f;
    }
  }
  return out;
}

World::ContactStress World::contact_stress(int tag, double volume) const {
  require(volume > 0 && std::isfinite(volume), "contact_stress: volume must be > 0 (m^3), got " + num(volume));
  const State& s = *state_;
  const auto& p = s.p;
  const auto& q = s.pairs;
  ContactStress out;
  const double kn = s.settings.contact.kn;
  for (std::size_t k = 0; k < q.n; ++k) {
    const double U = q.overlap_at(k);
    if (!(U > 0)) continue;
    const auto a = q.a[k], b = q.b[k];
    if (p.tag[a] != tag || p.tag[b] != tag) continue;
    const double reach = p.radius[a] + p.radius[b];
    out.stress += q.normal_force(k) * (reach - U);
    out.stiffness += kn * reach * (reach - U);
    ++out.contacts;
  }
  out.stress /= 3 * volume;
  out.stiffness /= 3 * volume;
  return out;
}

// --- bonds ---------------------------------------------------------------------------------

std::size_t World::install_bonds(const BondMaterial& given, double tolerance,
                                 std::span<const std::int64_t> ids, bool stress_free) {
  State& s = *state_;
  check_value("install_bonds: ", Field{"bond material"}, given);
  BondMaterial material = given;  // the beam's stiffness left at 0: the contact springs' (model.md 5)
  if (material.beam_kn == 0) material.beam_kn = s.settings.contact.kn;
  if (material.beam_ks == 0) material.beam_ks = material.beam_kn / 10;
  const std::string problem = detail::bond_material_problem(material);
  require(problem.empty(), "install_bonds: " + problem);
  if (s.bonds.n + s.frozen_bonds.n > 0)
    require(s.bonds.material == material,
            "install_bonds: the world already holds bonds of another material (one bond material "
            "per world)");
  auto& p = s.p;
  require(p.n > 0, "install_bonds: the world has no particles");
  if (tolerance < 0) {
    double mean = 0;
    for (std::size_t i = 0; i < p.n; ++i) mean += p.radius[i];
    tolerance = 1e-3 * mean / double(p.n);
  }
  for (auto id : ids) index_of(s, id);  // every id valid before anything changes
  const std::size_t installed = detail::install_bonds(s, material, tolerance, ids, stress_free);
  changed(s, Change::particles);  // bonded pairs leave the contact list
  return installed;
}

std::size_t World::bond_count() const {
  std::size_t n = 0;  // the parallel bonds that hold (a pair held by its contact bond alone is not one)
  detail::for_each_bond(*state_, [&](const detail::BondStore& q, std::size_t k) { n += q.holds[k] != detail::kContactBondHolds; });
  return n;
}

void World::set_bond_strength(double tensile_strength, bool breakable, std::optional<double> contact_strength,
                              std::optional<double> contact_shear_strength,
                              std::optional<double> contact_bond_friction) {
  BondMaterial m = state_->bonds.material;
  m.tensile_strength = breakable ? tensile_strength : 0.0;
  m.breakable = breakable;
  if (contact_strength) m.contact_strength = *contact_strength;
  if (contact_shear_strength) m.contact_shear_strength = *contact_shear_strength;
  if (contact_bond_friction) m.contact_bond_friction = *contact_bond_friction;
  check_value("set_bond_strength: ", Field{"bond material"}, m);
  const std::string problem = detail::bond_material_problem(m);
  require(problem.empty(), "set_bond_strength: " + problem);
  for (detail::BondStore* q : {&state_->bonds, &state_->frozen_bonds}) q->material = m;
}

void World::remove_bonds() {
  detail::remove_bonds(*state_);
  changed(*state_, Change::particles);  // the freed pairs enter the contact list at the next rebuild
}

double World::bond_criterion(double sigma, double tau, double tensile_strength) {
  return kernels::elliptic_criterion(sigma, tau, tensile_strength);
}

std::vector<BondInfo> World::bonds() const {
  const State& s = *state_;
  const auto& p = s.p;
  std::vector<BondInfo> out;
  out.reserve(s.bonds.n + s.frozen_bonds.n);
  detail::for_each_bond(s, [&](const detail::BondStore& q, std::size_t k) {
    BondInfo b;
    const auto ia = q.a[k], ib = q.b[k];
    b.id_a = p.id[ia];
    b.id_b = p.id[ib];
    b.normal = {q.nx[k], q.ny[k], q.nz[k]};
    b.point = Vec3{p.x[ia], p.y[ia], p.z[ia]} + b.normal * (p.radius[ia] - 0.5 * q.overlap[k]);
    b.gap = -q.overlap[k];
    b.beam_radius = q.beam_radius[k];
    b.normal_force = q.fn[k] + q.fbn[k];
    b.shear_force = {q.fsx[k] + q.fbsx[k], q.fsy[k] + q.fbsy[k], q.fsz[k] + q.fbsz[k]};
    b.twisting_moment = q.mbn[k];
    b.bending_moment = {q.mbsx[k], q.mbsy[k], q.mbsz[k]};
    kernels::beam_stresses(q, k, b.sigma, b.tau);
    b.beam = q.holds[k] != detail::kContactBondHolds;
    b.contact_bond = q.holds[k] != detail::kBeamHolds;
    if (b.id_a > b.id_b) {
      std::swap(b.id_a, b.id_b);
      b.normal = -b.normal;
      b.shear_force = -b.shear_force;
      b.twisting_moment = -b.twisting_moment;
      b.bending_moment = -b.bending_moment;
    }
    out.push_back(b);
  });
  std::sort(out.begin(), out.end(), [](const BondInfo& u, const BondInfo& v) {
    return u.id_a != v.id_a ? u.id_a < v.id_a : u.id_b < v.id_b;
  });
  return out;
}

const std::vector<BreakEvent>& World::break_events() const { return state_->break_events; }

// --- running -------------------------------------------------------------------------------

namespace {
// After a stopped step: the first non-finite value of the particles or groups, if any is left.
void recheck_health(State& s) {
  const auto& p = s.p;
  auto bad = [](const Vec3& v) { return !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z); };
  synced(s);
  for (std::size_t i = 0; i < p.n; ++i)
    for (const Vec3& v : {Vec3{p.x[i], p.y[i], p.z[i]}, Vec3{p.vx[i], p.vy[i], p.vz[i]}, Vec3{p.wx[i], p.wy[i], p.wz[i]}})
      if (bad(v))
        throw HealthError("simulation unhealthy at step " + std::to_string(s.step) + ": particle " +
                              std::to_string(p.id[i]) + " still holds the non-finite values of the step "
                              "that stopped (set its position and velocity, or load a checkpoint)",
                          s.step, p.id[i], "position or velocity", std::nan(""));
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    const auto& grp = s.groups[g];
    if (bad(grp.centre) || bad(grp.velocity) || bad(grp.angular_velocity))
      throw HealthError("simulation unhealthy at step " + std::to_string(s.step) + ": group " + std::to_string(g) +
                            " still holds the non-finite values of the step that stopped",
                        s.step, -1, "group position or velocity", std::nan(""));
  }
  s.unhealthy = false;
}
}  // namespace

std::uint64_t World::cycle(std::uint64_t n) {
  State& s = *state_;
  require(s.p.n > 0, "cycle: the world has no particles");
  if (s.unhealthy) recheck_health(s);
  try {
    for (std::uint64_t k = 0; k < n; ++k) {
      if (s.stop_requested.exchange(false)) return k;
      detail::step_once(s);
    }
  } catch (const HealthError&) {
    s.unhealthy = true;
    throw;
  }
  return n;
}
RunResult World::run(const RunPlan& plan) {
  require(plan.steps > 0 || plan.until_equilibrium || plan.stop_when,
          "run: give steps and/or a stop condition (stop_when or equilibrium)");
  require(plan.every >= 1, "run: every must be >= 1");
  require(plan.ratio > 0, "run: ratio " + num(plan.ratio) + " must be > 0");
  require(!plan.sample == (plan.sample_every == 0), "run: a sample hook needs sample_every >= 1, and sample_every a hook");
  // A stop request outlives neither the run it ended nor one that failed in a hook.
  struct ForgetStop {
    State& s;
    ~ForgetStop() { s.stop_requested.store(false); }
  } forget{*state_};
  using Clock = std::chrono::steady_clock;
  const std::uint64_t limit = plan.steps > 0 ? plan.steps : std::numeric_limits<std::uint64_t>::max();
  const bool checks = plan.until_equilibrium || plan.stop_when || plan.callback;
  const std::uint64_t every = plan.every;
  require(plan.steps_done < limit, "run: steps_done " + std::to_string(plan.steps_done) +
                                       " must be below the step limit " + std::to_string(limit));
  RunResult r;
  r.steps = plan.steps_done;
  std::uint64_t chunk = 1;
  while (r.steps < limit) {
    // Chunks of ~50 ms keep progress reports and interruptions responsive at no measurable cost
    // per call; they end at every check.
    std::uint64_t n = std::min(chunk, limit - r.steps);
    if (checks) n = std::min(n, every - r.steps % every);
    if (plan.sample) n = std::min(n, plan.sample_every - r.steps % plan.sample_every);
    const auto t0 = Clock::now();
    const std::uint64_t done = cycle(n);
    r.steps += done;
    if (done < n || (plan.interrupted && plan.interrupted())) {
      r.end = RunResult::End::interrupted;
      return r;
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (seconds < 0.02 && chunk < (1u << 20)) chunk *= 2;
    else if (seconds > 0.1 && chunk > 1) chunk /= 2;
    if (plan.sample && r.steps % plan.sample_every == 0) plan.sample();
    if (checks && r.steps % every == 0) {
      if (plan.callback) plan.callback();
      if (plan.until_equilibrium) {
        r.ratio = unbalanced_force_ratio();
        if (r.ratio <= plan.ratio) {
          r.end = RunResult::End::equilibrium;
          break;
        }
      } else if (plan.stop_when && plan.stop_when()) {
        r.end = RunResult::End::stop_when;
        break;
      }
    }
    if (plan.on_chunk) plan.on_chunk(r.steps, r.ratio);
  }
  return r;
}
void World::request_stop() { state_->stop_requested.store(true); }
double World::dt() const { return state_->dt; }
void World::set_dt(double dt) {
  check_setting("set_dt", "dt", dt);
  state_->dt_fixed = dt > 0;
  state_->dt = dt;
  changed(*state_, Change::time_step);
}
void World::set_dt_safety(double f) {
  check_setting("set_dt_safety", "dt_safety", f);
  state_->settings.dt_safety = f;
  changed(*state_, Change::time_step);
}
void World::set_friction(double mu) {
  ContactMaterial m = state_->settings.contact;
  m.friction = mu;
  check_material(m, "set_friction");
  // Only the slip limit [3-22] changes: a shear force above mu Fn slips at the next step.
  state_->settings.contact = m;
}
void World::set_rotation_lock_bonds(double k) {
  check_setting("set_rotation_lock_bonds", "rotation_lock_bonds", k);
  require(k == std::floor(k), "set_rotation_lock_bonds: rotation_lock_bonds must be a whole number, got " + num(k));
  state_->settings.rotation_lock_bonds = int(k);
  detail::refresh_bond_topology(*state_);  // the locks by the new rule
}
void World::set_overlap_limit(double r) {
  check_setting("set_overlap_limit", "overlap_limit", r);
  state_->settings.overlap_limit = r;
}
void World::set_skin(double skin) {
  // 0 (automatic) is the first build's choice: a running world keeps a skin.
  require(skin != 0, "set_skin: skin must be > 0 (0, automatic, is only for a new world)");
  check_setting("set_skin", "skin", skin);
  state_->settings.skin = skin;
  state_->skin = skin;
  changed(*state_, Change::skin);
}
double World::critical_dt() {
  State& s = *state_;
  if (s.need_rebuild && s.p.n > 0) detail::build_neighbors(s);
  return detail::estimate_critical_dt(s);
}
std::uint64_t World::step_count() const { return state_->step; }
double World::time() const { return state_->time; }
void World::set_threads(int threads) {
  check_setting("set_threads", "threads", threads);
  state_->settings.threads = threads;
}
std::string World::simd_architecture() const { return state_->ctx.kernels->name; }
StepStats World::stats() const {
  const State& s = *state_;
  StepStats st;
  st.rebuilds = s.rebuilds;
  st.reorders = s.reorders;
  st.pairs = s.pairs.n;
  st.frozen_bonds = s.frozen_bonds.n;
  st.contacts = contact_count();
  for (std::size_t k = 0; k < s.walls.contacts.n; ++k) st.wall_contacts += s.walls.contacts.overlap[k] > 0;
  st.threads = detail::thread_count(s);
  st.busy_elsewhere = s.settings.threads > 0 ? -1.0 : s.ctx.load->others();
  return st;
}
void World::rebuild_neighbors() {
  if (state_->p.n > 0) detail::build_neighbors(*state_);
}

// --- measurements --------------------------------------------------------------------------

// After a step nothing the energies need waits in the lazily moved members (the kinetic energy
// was summed by the step, the rest is in the stores and the ledger): reading them does not bring
// the members up to date, which would change how their moves are rounded, and so the run.
Energies World::energies() const {
  return detail::compute_energies(state_->kinetic_valid ? *state_ : synced(*state_));
}

double World::unbalanced_force_ratio() const {
  const State& s = *state_;
  const auto& p = s.p;
  const Vec3 g = s.settings.gravity;
  double unbalanced = 0;
  std::size_t bodies = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.group[i] >= 0) continue;
    const double fx = p.fx[i] + p.mass[i] * g.x, fy = p.fy[i] + p.mass[i] * g.y,
                 fz = p.fz[i] + p.mass[i] * g.z;
    unbalanced += std::sqrt(fx * fx + fy * fy + fz * fz);
    ++bodies;
  }
  double contact = 0;
  std::size_t contacts = 0;
  for (std::size_t k = 0; k < s.pairs.n; ++k)
    if (s.pairs.overlap_at(k) > 0) { contact += s.pairs.normal_force(k); ++contacts; }
  for (std::size_t k = 0; k < s.walls.contacts.n; ++k)
    if (s.walls.contacts.overlap[k] > 0) { contact += s.walls.contacts.fn[k]; ++contacts; }
  // Intact bonds carry contact force too, in tension as well: |contact bond + parallel bond|.
  for (std::size_t k = 0; k < s.bonds.n; ++k) {
    contact += std::abs(s.bonds.fn[k] + s.bonds.fbn[k]);
    ++contacts;
  }
  if (bodies == 0) return 0;
  // Nothing pushes and nothing is unbalanced (a specimen bonded stress-free): at rest.
  if (contacts == 0 || contact == 0) return unbalanced == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  return (unbalanced / double(bodies)) / (contact / double(contacts));
}

std::vector<ContactInfo> World::contacts() const {
  const State& s = *state_;
  const auto& p = s.p;
  const auto& q = s.pairs;
  std::vector<ContactInfo> out;
  for (std::size_t k = 0; k < q.n; ++k) {
    if (!(q.overlap_at(k) > 0)) continue;
    const auto a = q.a[k], b = q.b[k];
    ContactInfo c;
    c.id_a = p.id[a];
    c.id_b = p.id[b];
    c.normal = {q.nx[k], q.ny[k], q.nz[k]};
    c.overlap = q.overlap_at(k);
    c.point = Vec3{p.x[a], p.y[a], p.z[a]} + c.normal * (p.radius[a] - 0.5 * c.overlap);  // [3-11]
    c.normal_force = q.normal_force(k);
    c.shear_force = {q.fsx[k], q.fsy[k], q.fsz[k]};
    if (c.id_a > c.id_b) {  // report with id_a < id_b: flip the roles
      std::swap(c.id_a, c.id_b);
      c.normal = -c.normal;
      c.shear_force = -c.shear_force;
    }
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const ContactInfo& u, const ContactInfo& v) {
    return u.id_a != v.id_a ? u.id_a < v.id_a : u.id_b < v.id_b;
  });
  return out;
}

double World::max_overlap_ratio() const { return detail::deepest_overlap(*state_).ratio; }

std::size_t World::contact_count() const {
  const auto& q = state_->pairs;
  std::size_t c = 0;
  for (std::size_t k = 0; k < q.n; ++k) c += q.overlap_at(k) > 0;
  return c;
}

}  // namespace asperity
