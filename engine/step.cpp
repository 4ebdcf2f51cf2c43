// One step, in named stages (design.md "One step"):
//   1 neighbors   rebuild the pair list when something moved more than skin/2 (history carried)
//   2 contacts    pair kernel -> per-pair normal, shear force, normal force, overlap
//   3 bonds       bond kernel -> per-bond forces, moments, break flags
//   4 walls       ball-wall kernel -> per-contact results, wall forces, wall work
//   5+7 gather and integrate (fused) -> particle forces; free particles advanced
//   6 groups      rigid groups advanced, members moved (in the same parallel region)
//   8 bookkeep    ledgers, health checks, rebuild criterion, breaks, time-step estimate
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "step.hpp"
// The stages, in the order a step runs them:
#include "neighbor/build.hpp"    // 1
#include "stages/pairs.hpp"     // 2
#include "kernels/bond_law.hpp"
#include "bond_list.hpp"
#include "stages/bonds.hpp"     // 3
#include "stages/walls.hpp"     // 4
#include "stages/integrate.hpp" // 5 + 7
#include "stages/groups.hpp"     // 6
#include "bodies/groups.hpp"

namespace asperity::detail {

namespace {

[[noreturn]] void health_error(const State& s, const std::string& what, std::int64_t index,
                               const std::string& quantity, double value) {
  const std::int64_t id = index >= 0 ? s.p.id[index] : -1;
  std::ostringstream m;
  m << "simulation unhealthy at step " << s.step << ": " << what;
  if (id >= 0) m << " (particle " << id << ")";
  m << "; " << quantity << " = " << value;
  throw HealthError(m.str(), s.step, id, quantity, value);
}

void check_dt(State& s) {
  s.dt_estimate = estimate_critical_dt(s);
  s.last_estimate_step = s.step;
  if (!s.dt_fixed) {
    s.dt = s.settings.dt_safety * s.dt_estimate;
    // The bounds of World's setters keep masses and stiffnesses such that this cannot happen;
    // a step of zero or infinite length would report success while nothing (or NaN) advanced.
    if (!(s.dt > 0 && std::isfinite(s.dt)))
      health_error(s, "the automatic time step is not a positive finite number (critical estimate " +
                          std::to_string(s.dt_estimate) + " s)", -1, "dt", s.dt);
  } else if (s.dt > s.dt_estimate && !s.settings.allow_dt_above_estimate) {
    std::ostringstream m;
    m << "time step " << s.dt << " s is above the critical estimate " << s.dt_estimate
      << " s [3-30..3-32]; lower dt, set dt = 0 for automatic, or allow_dt_above_estimate";
    health_error(s, m.str(), -1, "dt", s.dt);
  }
}

void bookkeep(State& s) {
  const ParticleStore& p = s.p;
  double max_disp2 = 0, worst = 0;
  std::int64_t worst_i = -1;
  for (const auto& r : s.ctx.particle_blocks) {
    s.kinetic_at_step += r.kinetic;
    if (s.settings.track_energy) {
      s.ledger.damping += r.damping;
      s.ledger.gravity += r.gravity;
      s.ledger.boundary += r.applied;
    }
    max_disp2 = std::max(max_disp2, r.max_disp2);
    if (!(r.max_disp2 == r.max_disp2)) max_disp2 = r.max_disp2;  // NaN wins
    if (r.worst >= 0 && !(r.worst_step <= worst)) {
      worst = r.worst_step;
      worst_i = r.worst;
    }
  }
  // What spins now (State::spin_known): the blocks' ORs, taken after each block moved, and the
  // moved group members, which took their group's new angular velocity after them (move_members).
  // A step that started from a known answer adds to it (integrate.cpp: only its blocks with
  // rotation were read); one that did not took every block's and starts it afresh.
  if (!s.any_rotating) {
    s.cache.spin_known = false;  // the blocks took no ORs
  } else {
    std::uint64_t reachable = 0, bonded = 0;
    for (const auto& r : s.ctx.particle_blocks) {
      reachable |= r.spin_reachable;
      bonded |= r.spin_bonded;
    }
    std::uint64_t members = 0;
    if (!s.groups.empty())
      for (const GroupStep& gs : s.ctx.group_steps)
        if (gs.moves)
          members |= std::bit_cast<std::uint64_t>(gs.angular_velocity.x) |
                     std::bit_cast<std::uint64_t>(gs.angular_velocity.y) |
                     std::bit_cast<std::uint64_t>(gs.angular_velocity.z);
    if (!s.cache.spin_known) s.cache.spin_reachable = s.cache.spin_bonded = 0;
    s.cache.spin_reachable |= reachable | members;
    s.cache.spin_bonded |= bonded | members;
    s.cache.spin_known = true;
  }
  // Group members were moved by the group stages: the largest displacement of each group (its idle
  // members have moved by at most idle_base + |idle_shift|, split_idle).
  double first = 0, second = 0;  // the two largest displacements of distinct bodies
  auto body = [&](double d) {
    if (d > first) second = first, first = d;
    else if (d > second) second = d;
  };
  const double free_move = max_disp2 > 0 ? std::sqrt(max_disp2) : 0.0;  // largest free-particle move
  if (!(max_disp2 == max_disp2)) first = max_disp2;  // NaN: rebuild, the health check reports it
  else if (max_disp2 > 0) body(free_move), body(free_move);  // two free particles
  for (std::size_t gi = 0; gi < s.groups.size(); ++gi) {
    const Group& g = s.groups[gi];
    double d2 = 0;
    // The moved members in member order, as the moves stage left them (stages/groups.cpp).
    for (std::size_t slot = s.ctx.moved_start[gi]; slot < s.ctx.moved_start[gi + 1]; ++slot) {
      d2 = std::max(d2, s.ctx.member_disp2[slot]);
      if (!s.ctx.member_finite[slot]) {
        const std::int32_t i = s.ctx.moved_particle[slot];
        health_error(s, "non-finite position", i, "x", p.x[i]);
      }
    }
    double d = std::sqrt(d2);
    if (g.lazy && g.busy.size() < g.members.size()) {
      d = std::max(d, g.idle_base + norm(g.idle_shift));
      if (!std::isfinite(d)) health_error(s, "non-finite group displacement", g.members.front(), "x", d);
    }
    body(d);
  }
  if (worst_i >= 0 && !std::isfinite(worst))
    health_error(s, "non-finite velocity or position", worst_i, "velocity", worst);
  // The step's kinetic energy sums m v^2 and I w^2 of every particle that moves or spins: one test
  // of the sum catches a non-finite angular velocity (or mass, or inertia), which the displacement
  // check above does not see. Only on failure are the particles searched for the culprit.
  if (!std::isfinite(s.kinetic_at_step)) {
    std::int64_t culprit = -1;
    double value = s.kinetic_at_step;
    for (std::size_t i = 0; i < p.n && culprit < 0; ++i)
      for (double v : {p.wx[i], p.wy[i], p.wz[i], p.vx[i], p.vy[i], p.vz[i], p.inertia[i], p.mass[i]})
        if (!std::isfinite(v)) {
          culprit = std::int64_t(i);
          value = v;
          break;
        }
    health_error(s, "non-finite kinetic energy (velocity, angular velocity, mass or inertia)",
                 culprit, "kinetic energy", value);
  }
  if (worst > 1.0)
    health_error(s, "a particle moved more than its radius (or turned more than 0.1 rad) in one "
                    "step: contacts are not resolved (time step too large, loading too fast, or "
                    "a runaway)",
                 worst_i, "step displacement / R", worst);

  // A pair missed by the last build (farther apart than Ra + Rb + skin) can touch only once its two
  // bodies have closed `skin` between them, which the two largest displacements of distinct bodies
  // bound (a free particle is a body of its own: two free particles count the free maximum twice,
  // the classic skin/2 rule; two rigid bodies of which one stands still may move a whole skin). A
  // wall contact likewise needs the particle and the wall to close `skin`, or skin/2 for the
  // free particles of a mesh that listed them within R + skin/2 (Wall::candidates_within_half_
  // skin; while the mesh stands still the pair rule already keeps free particles within skin/2).
  double wall_move = 0;
  for (const auto& w : s.walls.walls) {
    const double move = norm(w.displacement - w.displacement_at_build);
    wall_move = std::max(wall_move, move);
    if (w.candidates_within_half_skin && !(free_move + move <= 0.5 * s.skin)) s.need_rebuild = true;
  }
  if (!(first + second <= s.skin) || !(first + wall_move <= s.skin)) s.need_rebuild = true;
}

// Runaway energy: with every dissipation term non-negative, Ek + Es can never exceed what it was
// when the run started plus the work put in since. Far beyond that, the integration is creating
// energy. Checked every dt_interval steps (it costs a pass over particles and pairs).
void check_energy(State& s) {
  if (!s.settings.track_energy) return;
  const Energies e = compute_energies(s);
  const double now = e.kinetic + e.strain;
  const double input = s.ledger.boundary + s.ledger.gravity;
  if (s.reference_energy < 0) {
    s.reference_energy = now;
    s.reference_input = input;
    return;
  }
  // A velocity-prescribed degree of freedom of a rigid group is driven from outside: its kinetic
  // energy (1/2 M v^2 per such axis, members moved lazily or not) is put in, not created.
  double driven = 0;
  for (const auto& g : s.groups)
    for (int k = 0; k < 3; ++k)
      if (g.motion.translation[k] == Dof::velocity) driven += 0.5 * g.mass * g.motion.velocity[k] * g.motion.velocity[k];
  const double allowed = s.reference_energy + std::max(0.0, input - s.reference_input) + driven;
  if (now > 2.0 * allowed && now > 1e-300) {
    std::ostringstream m;
    m << "kinetic + strain energy " << now << " J exceeds twice the initial energy plus the work "
         "put in (" << allowed << " J): energy is being created, the integration is unstable";
    health_error(s, m.str(), -1, "kinetic + strain energy", now);
  }
}

// Contacts too soft for the load: an overlap as deep as the smaller radius means one centre is
// (nearly) inside the other particle, where the linear contact law [3-5] and the contact point
// [3-11] mean nothing for a deformable body. A rigid block's surface particles may be pushed that
// deep past one another (settings.overlap_limit, below 2 radii: beyond, the centres may meet).
// Checked every dt_interval steps with the time-step estimate.
void check_overlaps(State& s) {
  const OverlapRatio worst = deepest_overlap(s);
  if (worst.ratio > s.settings.overlap_limit) {
    std::ostringstream m;
    m << "a contact overlap exceeds " << s.settings.overlap_limit
      << " x the particle's radius (overlap_limit): the contacts are too soft for the load (raise kn, "
         "or lower the load or the loading rate)";
    health_error(s, m.str(), worst.particle, "overlap / R", worst.ratio);
  }
}

}  // namespace

Vec3 bond_torque_left_out(const State& s, std::size_t i) {
  if (s.cache.bond_records != kernels::BondRecord::forces) return {};
  const Incidence& inc = s.cache.bond_incidence;
  const BondStore& q = s.bonds;
  Vec3 t{0, 0, 0};
  // The gather's terms -(R - U/2) n x (fs + fbs) (gather_loop.hpp), from the record's values as
  // the bond kernel stored them.
  for (std::int32_t e = inc.start[i]; e < inc.start[i + 1]; ++e) {
    const auto k = std::size_t(inc.entry[std::size_t(e)] >> 1);
    if (k >= q.n) continue;  // a dead bond's (BondStore::zero_record)
    const Vec3 n{q.nx[k], q.ny[k], q.nz[k]};
    const Vec3 shear{q.fsx[k] + q.fbsx[k], q.fsy[k] + q.fbsy[k], q.fsz[k] + q.fbsz[k]};
    t -= cross(n, shear) * (s.p.radius[i] - 0.5 * q.overlap[k]);
  }
  return t;
}

OverlapRatio deepest_overlap(const State& s, bool turning_only) {
  const ParticleStore& p = s.p;
  OverlapRatio worst;
  // A particle that does not turn feels neither the contact point nor the moment of its forces.
  auto turns = [&](std::int64_t i) { return i >= 0 && particle_turns(s, std::size_t(i)); };  // i < 0: a wall
  auto consider = [&](double U, std::int64_t a, std::int64_t b) {
    if (!(U > 0)) return;
    if (turning_only && !turns(a) && !turns(b)) return;
    const std::int64_t smaller = b < 0 || p.radius[a] <= p.radius[b] ? a : b;
    const double r = U / p.radius[smaller];
    if (r > worst.ratio) worst.ratio = r, worst.particle = smaller;
  };
  for (std::size_t k = 0; k < s.pairs.n; ++k) consider(s.pairs.overlap_at(k), s.pairs.a[k], s.pairs.b[k]);
  const WallContacts& wc = s.walls.contacts;
  for (std::size_t k = 0; k < wc.n; ++k) consider(wc.overlap[k], wc.particle[k], -1);
  // A bond's contact spring is a contact too: a bonded pair pressed a radius deep is as
  // meaningless (broken bonds leave the bonds in process_breaks: BondStore::dead).
  for_each_bond(s, [&](const BondStore& q, std::size_t k) { consider(q.overlap[k], q.a[k], q.b[k]); });
  return worst;
}

double estimate_critical_dt(const State& s) {
  // [3-30..3-32]: per body and degree of freedom sqrt(m / k_tran), sqrt(I / k_rot), with the
  // stiffness summed over the body's touching contacts. A body without contacts counts as having
  // one, so the estimate stays finite (and sane) before the first contact forms.
  const ParticleStore& p = s.p;
  const std::size_t n = p.n;
  const ContactMaterial& m = s.settings.contact;
  const double kc = std::max(m.kn, m.ks);
  std::vector<double> ktran(n, 0.0), krot(n, 0.0);
  for (std::size_t k = 0; k < s.pairs.n; ++k) {
    const double U = s.pairs.overlap_at(k);
    if (!(U > 0)) continue;
    const auto a = s.pairs.a[k], b = s.pairs.b[k];
    ktran[a] += kc;
    ktran[b] += kc;
    const double la = p.radius[a] - 0.5 * U, lb = p.radius[b] - 0.5 * U;
    krot[a] += m.ks * la * la;
    krot[b] += m.ks * lb * lb;
  }
  // Bonds [3-31, 3-32]: contact springs plus the beam, k_rot += kbn I + kbs J.
  // Frozen bonds too (State::frozen_bonds): the estimate does not depend on which groups turn.
  const BondMaterial& bm = s.bonds.material;
  for_each_bond(s, [&](const BondStore& bq, std::size_t k) {
    const auto a = bq.a[k], b = bq.b[k];
    const double kt = kc + std::max(bm.beam_kn, bm.beam_ks);
    ktran[a] += kt;
    ktran[b] += kt;
    const double r2 = bq.beam_radius[k] * bq.beam_radius[k];
    const double beam_rot = bm.beam_kn * 0.25 * r2 + bm.beam_ks * 0.5 * r2;
    const double U = bq.overlap[k];
    const double la = p.radius[a] - 0.5 * U, lb = p.radius[b] - 0.5 * U;
    krot[a] += (m.ks + bm.beam_ks) * la * la + beam_rot;
    krot[b] += (m.ks + bm.beam_ks) * lb * lb + beam_rot;
  });
  const WallContacts& wc = s.walls.contacts;
  for (std::size_t k = 0; k < wc.n; ++k) {
    const double U = wc.overlap[k];
    if (!(U > 0)) continue;
    const ContactMaterial& wm = s.walls.walls[wc.wall[k]].material;
    const auto i = wc.particle[k];
    ktran[i] += std::max(wm.kn, wm.ks);
    const double l = p.radius[i] - 0.5 * U;
    krot[i] += wm.ks * l * l;
  }
  double best = std::numeric_limits<double>::infinity();
  for (const Group& g : s.groups) {  // a group is one body
    double k = 0;
    for (std::int32_t i : g.members) k += ktran[i];
    if (g.mass > 0) best = std::min(best, std::sqrt(g.mass / (k > 0 ? k : kc)));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (p.group[i] >= 0) continue;
    const double kt = ktran[i] > 0 ? ktran[i] : kc;
    best = std::min(best, std::sqrt(p.mass[i] / kt));
    if (!p.rotation_locked[i]) {
      const double kr = krot[i] > 0 ? krot[i] : m.ks * p.radius[i] * p.radius[i];
      best = std::min(best, std::sqrt(p.inertia[i] / kr));
    }
  }
  return best;
}

Energies compute_energies(const State& s) {
  Energies e;
  const ParticleStore& p = s.p;
  if (s.kinetic_valid) {
    e.kinetic = s.kinetic_at_step;
  } else {
    for (std::size_t i = 0; i < p.n; ++i)
      e.kinetic += 0.5 * p.mass[i] * (p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i] + p.vz[i] * p.vz[i]) +
                   0.5 * p.inertia[i] * (p.wx[i] * p.wx[i] + p.wy[i] * p.wy[i] + p.wz[i] * p.wz[i]);
  }
  const ContactMaterial& m = s.settings.contact;
  const PairStore& q = s.pairs;
  for (std::size_t k = 0; k < q.n; ++k) {
    if (!(q.overlap_at(k) > 0)) continue;
    e.strain += kernels::contact_spring_energy(
        q.normal_force(k), q.fsx[k] * q.fsx[k] + q.fsy[k] * q.fsy[k] + q.fsz[k] * q.fsz[k], m.kn, m.ks);
  }
  const WallContacts& wc = s.walls.contacts;
  for (std::size_t k = 0; k < wc.n; ++k) {
    if (!(wc.overlap[k] > 0)) continue;
    const ContactMaterial& wm = s.walls.walls[wc.wall[k]].material;
    e.strain += kernels::contact_spring_energy(
        wc.fn[k], wc.fsx[k] * wc.fsx[k] + wc.fsy[k] * wc.fsy[k] + wc.fsz[k] * wc.fsz[k], wm.kn, wm.ks);
  }
  const BondMaterial& bm = s.bonds.material;
  for_each_bond(s, [&](const BondStore& bq, std::size_t k) {  // a frozen bond keeps its energy
    e.strain += kernels::spring_energy(bq, k, m) + kernels::beam_energy(bq, k, bm);
  });
  e.released = s.ledger.released;
  e.friction = s.ledger.friction;
  e.damping = s.ledger.damping;
  e.boundary_work = s.ledger.boundary;
  e.gravity_work = s.ledger.gravity;
  return e;
}

namespace {

// A stage's blocks still to run on one thread's share: [next, end) packed in one word, so that the
// owner taking from the front and a thief taking from the back agree by compare-and-swap. One
// cache line each: the owner's takes do not disturb the other thread.
struct alignas(64) BlockRange {
  std::atomic<std::uint64_t> word{0};
  void set(std::uint32_t next, std::uint32_t end) {
    word.store(std::uint64_t(end) << 32 | next, std::memory_order_relaxed);
  }
  template <bool Back>
  bool take(std::size_t& blk) {
    std::uint64_t cur = word.load(std::memory_order_relaxed);
    for (;;) {
      const std::uint32_t next = std::uint32_t(cur), end = std::uint32_t(cur >> 32);
      if (next >= end) return false;
      const std::uint64_t want = Back ? (std::uint64_t(end - 1) << 32 | next)
                                      : (std::uint64_t(end) << 32 | (next + 1));
      if (word.compare_exchange_weak(cur, want, std::memory_order_acq_rel, std::memory_order_relaxed)) {
        blk = Back ? end - 1 : next;
        return true;
      }
    }
  }
};

// Every block of each stage in order on the calling thread, then the finishes: run_stages on one
// thread, and step_once's group stages where too few members move to pay for their barriers.
void run_stages_serially(std::initializer_list<StageLoop*> stages) {
  for (StageLoop* st : stages)
    for (std::size_t blk = 0; blk < st->blocks; ++blk) st->run(blk);
  for (StageLoop* st : stages)
    if (st->finish) st->finish();
}

}  // namespace

void run_stages(State& s, std::initializer_list<StageLoop*> stages) {
  // Every block writes only its own slots and `finish` sums them in block order, so which thread
  // runs a block changes no result; the split only decides the speed. Each thread owns the same
  // contiguous share of every stage's blocks in every step (so a block's data, its pairs'
  // history among it, stays in that core's cache from step to step), runs it from the front,
  // and then takes what is left of the other shares from their backs: a thread that a busy core
  // or a costlier share holds back is helped by its last blocks, not made to wait for at a
  // barrier. The force stages do not wait for each other (they read the particles and
  // write their own lists only); a stage after_barrier does.
  const int threads = thread_count(s);
  if (threads == 1) {  // no parallel region: on one thread its fork and barriers are pure cost
    run_stages_serially(stages);
    return;
  }
  const std::size_t count = stages.size() * std::size_t(threads);
  static thread_local std::unique_ptr<BlockRange[]> ranges;
  static thread_local std::size_t capacity = 0;
  if (capacity < count) {
    ranges = std::make_unique<BlockRange[]>(count);
    capacity = count;
  }
  std::size_t si = 0;
  for (StageLoop* st : stages) {
    for (int t = 0; t < threads; ++t)
      ranges[si * threads + t].set(std::uint32_t(st->blocks * t / threads),
                                   std::uint32_t(st->blocks * (t + 1) / threads));
    ++si;
  }
  BlockRange* const r = ranges.get();
#pragma omp parallel num_threads(threads)
  {
    // The runtime may give fewer threads than asked: the shares of the missing ones are taken
    // by the others.
    const int t = omp_get_thread_num();
    std::size_t base = 0;
    for (StageLoop* st : stages) {
      if (st->after_barrier) {
#pragma omp barrier
      }
      BlockRange* share = r + base;
      base += std::size_t(threads);
      std::size_t blk;
      while (share[t].take<false>(blk)) st->run(blk);
      for (int k = 1; k < threads; ++k)
        while (share[(t + k) % threads].take<true>(blk)) st->run(blk);
    }
  }
  for (StageLoop* st : stages)
    if (st->finish) st->finish();
}

void watch_load(State& s) {
  if (s.settings.threads > 0 || s.ctx.max_threads <= 1) return;  // fixed, or nothing to choose
  s.ctx.load_limit = s.ctx.load->limit(LoadWatch::now());             // a clock read; a sample each 0.5 s
}

// Moved group members from which the group stages run in the step's parallel region.
constexpr std::size_t kParallelMoves = 512;

namespace {
Ledger* ledger_if_tracked(State& s) { return s.settings.track_energy ? &s.ledger : nullptr; }
}  // namespace

PairStageView pair_view(State& s) {
  return {s.p, s.pairs, s.settings.contact, s.dt, s.step, s.any_rotating, s.rest_overlaps,
          thread_count(s), s.cache.spin_known, s.cache.spin_reachable,
          s.cache.pair_records_sparse, s.ctx, ledger_if_tracked(s)};
}

BondStageView bond_view(State& s) {
  return {s.p, s.bonds, s.settings.contact, s.dt, s.any_rotating, s.rest_overlaps,
          s.cache.spin_known, s.cache.spin_bonded, s.cache.bonded_particles,
          s.cache.bonds_partial, s.cache.bond_moments_zero, s.cache.bond_ends_turn,
          s.cache.bond_records, s.ctx, ledger_if_tracked(s)};
}

WallStageView wall_view(State& s) {
  return {s.p, s.walls, s.dt, s.any_rotating, s.ctx, ledger_if_tracked(s)};
}

GroupStageView group_view(State& s) {
  return {s.p, s.groups, s.pairs, s.bonds, s.walls, s.cache.servo, s.rebuilds, s.bond_version,
          s.settings.contact, s.settings.gravity, s.settings.local_damping, s.dt,
          s.kinetic_at_step, s.ctx, ledger_if_tracked(s)};
}

IntegrateStageView integrate_view(State& s) {
  return {s.p, s.pairs, s.incidence, s.walls.contacts, s.bonds, s.cache.bond_incidence,
          s.cache.bond_held, s.cache.bond_records, s.cache.idle, s.cache.block_free,
          s.cache.block_busy, s.cache.spin_known, s.cache.spin_reachable, s.cache.spin_bonded,
          s.settings.gravity, s.settings.local_damping, s.dt, s.any_rotating, s.ctx};
}

void step_once(State& s) {
  watch_load(s);
  const bool rebuilt = s.need_rebuild;
  if (rebuilt) build_neighbors(s);
  const bool estimate_due = s.step >= s.last_estimate_step + std::uint64_t(s.settings.dt_interval);
  if (!s.cache.idle_valid) split_idle(s);
  if (!s.cache.bond_ends_turn_known) {
    s.cache.bond_ends_turn = std::any_of(s.cache.bonded_particles.begin(), s.cache.bonded_particles.end(),
                                         [&](std::int32_t i) { return particle_turns(s, std::size_t(i)); });
    s.cache.bond_ends_turn_known = true;
  }
  if (rebuilt || estimate_due || s.dt <= 0) check_dt(s);
  // The three force stages, then gather + integrate, in one parallel region (step_context.hpp,
  // StageLoop); the ledgers and wall forces are summed after it.
  StageLoop pairs = pair_stage(pair_view(s)), bonds = bond_stage(bond_view(s)),
            walls = wall_stage(wall_view(s)), particles = integrate_stage(integrate_view(s));
  if (s.groups.empty()) {
    run_stages(s, {&pairs, &bonds, &walls, &particles});
    s.kinetic_at_step = 0;  // the particles' share is added in bookkeeping
  } else {
    // The rigid groups in the same region where many members move (a platen of the elastic
    // joint), so that no thread waits while another moves them. Where few move, their two more
    // barriers would cost more than they save, so those stages run after the region.
    GroupStages g = group_stages(group_view(s));
    if (s.ctx.moved_particle.size() >= kParallelMoves) {
      run_stages(s, {&pairs, &bonds, &walls, &particles, &g.servo, &g.motion, &g.moves});
    } else {  // on one thread, the same sums in the same order as the call above
      run_stages(s, {&pairs, &bonds, &walls, &particles});
      run_stages_serially({&g.servo, &g.motion, &g.moves});
    }
  }
  for (auto& w : s.walls.walls) {
    w.displacement += w.velocity * s.dt;
    // A prescribed velocity near the largest double overflows here; nothing else would see it
    // until a particle touched the wall.
    if (!std::isfinite(w.displacement.x + w.displacement.y + w.displacement.z))
      health_error(s, "non-finite wall displacement (wall velocity too large)", -1, "wall displacement",
                   norm(w.displacement));
  }
  ++s.step;
  s.time += s.dt;
  // A fixed dt near the largest double (allowed above the estimate) overflows the clock.
  if (!std::isfinite(s.time)) health_error(s, "the simulated time overflowed (time step too large)", -1, "time", s.time);
  bookkeep(s);
  process_breaks(s);  // after the step: broken bonds acted with the forces of their last state
  s.kinetic_valid = true;
  if (estimate_due) {
    check_overlaps(s);
    check_energy(s);
  }
}

}  // namespace asperity::detail
