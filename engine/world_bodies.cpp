// World: walls (planes, triangle meshes) and rigid groups (translation and rotation modes, servo).
// Every function checks its input and says what was wrong (world_checks.hpp).
#include "asperity/world.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "bodies/groups.hpp"
#include "bodies/mesh.hpp"
#include "state.hpp"
#include "step.hpp"

#include "world_checks.hpp"

namespace asperity {

using detail::Change;
using detail::changed;
using detail::State;

using namespace world_checks;

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
Vec3 World::group_torque(int group) const {
  const auto& grp = state_->groups[check_group(*state_, group)];
  Vec3 t = grp.torque;
  for (const std::int32_t i : grp.members) t += detail::bond_torque_left_out(*state_, std::size_t(i));
  return t;
}
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

}  // namespace asperity
