// World: the public API over the stores and the step driver. Every function checks its input
// and says what was wrong; ids are stable, indices are internal.
#include "asperity/world.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "bodies/groups.hpp"
#include "bodies/mesh.hpp"
#include "neighbor/build.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"
#include "step.hpp"
#include "world_checks.hpp"

namespace asperity {

using detail::Change;
using detail::changed;
using detail::State;

using namespace world_checks;

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
    auto which = [&] { return radii.size() > 1 ? " of particle " + std::to_string(k + 1) : std::string(); };
    require_radius(radii[k], [&] { return "add_particle: radius" + which(); });
    require_position(Vec3{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]},
                     [&] { return "add_particle: position" + which(); });
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
  return ASPERITY_VEC(t) + detail::bond_torque_left_out(*state_, i);
}
#undef ASPERITY_VEC
double World::radius(std::int64_t id) const { return state_->p.radius[index_of(*state_, id)]; }
double World::mass(std::int64_t id) const { return state_->p.mass[index_of(*state_, id)]; }
double World::density(std::int64_t id) const { return state_->p.density[index_of(*state_, id)]; }
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
  require_radius(r, [] { return "set_radius: radius"; });
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  p.radius[i] = r;
  set_mass(p, i);
  for (auto& g : state_->groups) recompute_group(*state_, g);
  changed(*state_, Change::particles);
}
void World::set_density(std::int64_t id, double rho) {
  check_setting("set_density", "density", rho);
  auto& p = state_->p;
  const auto i = index_of(*state_, id);
  p.density[i] = rho;
  set_mass(p, i);
  if (p.group[i] >= 0) recompute_group(*state_, state_->groups[p.group[i]]);
  changed(*state_, Change::particles);
}
void World::scale_radii(double factor) {
  require(factor > 0 && std::isfinite(factor), "scale_radii: factor must be > 0, got " + num(factor));
  auto& p = state_->p;
  // Every new radius within bounds before any changes (a failed call leaves the world as it was).
  for (std::size_t i = 0; i < p.n; ++i)
    require_radius(p.radius[i] * factor, [&] {
      return "scale_radii: factor " + num(factor) + " makes the radius of particle " + std::to_string(p.id[i] + 1);
    });
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

}  // namespace asperity
