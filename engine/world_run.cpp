// World: running (cycle, run with its checks and hooks, the time step and the run's settings).
// Every function checks its input and says what was wrong (world_checks.hpp).
#include "asperity/world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

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
void World::set_damping(double alpha) {
  check_setting("set_damping", "damping", alpha);
  // Read by the integration at every step: nothing cached depends on it.
  state_->settings.local_damping = alpha;
}
void World::set_rotation_lock_bonds(double k) {
  check_setting("set_rotation_lock_bonds", "rotation_lock_bonds", k);
  require(k == std::floor(k), "set_rotation_lock_bonds: rotation_lock_bonds must be a whole number, got " + num(k));
  state_->settings.rotation_lock_bonds = int(k);
  detail::refresh_bond_topology(*state_);  // the locks by the new rule
}
void World::set_rotation_lock_beams(bool beams_only) {
  state_->settings.rotation_lock_beams = beams_only;
  detail::refresh_bond_topology(*state_);  // the locks by the new rule
}
void World::set_overlap_limit(double r) {
  check_setting("set_overlap_limit", "overlap_limit", r);
  state_->settings.overlap_limit = r;
}
void World::set_skin(double skin) {
  // 0: automatic again, derived from the radii at the next build (as scale_radii does).
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

}  // namespace asperity
