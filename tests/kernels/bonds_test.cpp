// Bonds (model.md 5) against closed forms: beam stresses [3-27], the elliptic criterion
// [3-46..3-49], the released energy, the bonded oscillator, and the SIMD kernel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <tuple>

#include "core/aligned.hpp"
#include "kernels/kernels.hpp"
#include "scenes.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"

using namespace asperity;

namespace {
constexpr double kR = 5e-4;

struct Pair {
  World w;
  std::int64_t a, b;
  int ga, gb;
};

// Two touching spheres along z, bonded; a is held fixed, b is driven by `motion`.
Pair bonded_pair(BondMaterial bm, GroupMotion motion, bool lock_rotation = true) {
  WorldSettings ws;
  ws.lock_bonded_rotation = lock_rotation;
  ws.local_damping = 0;
  Pair p{World(ws), 0, 0, 0, 0};
  p.a = p.w.add_particle({0, 0, 0}, kR);
  p.b = p.w.add_particle({0, 0, 2 * kR}, kR);
  EXPECT_EQ(p.w.install_bonds(bm), 1u);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  p.ga = p.w.add_group(std::vector<std::int64_t>{p.a}, fixed);
  p.gb = p.w.add_group(std::vector<std::int64_t>{p.b}, motion);
  p.w.set_dt(1e-4);
  return p;
}

GroupMotion moving(Vec3 v, Vec3 w = {}) {
  GroupMotion m;
  m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
  m.velocity = v;
  m.rotation = (w == Vec3{}) ? Dof::fixed : Dof::velocity;
  m.angular_velocity = w;
  return m;
}

// A particle whose rotation is locked refuses an angular velocity.
bool locked(World& world, std::int64_t id) {
  try {
    world.set_angular_velocity(id, {0, 0, 0});
    return false;
  } catch (const Error&) {
    return true;
  }
}

const double kArea = std::numbers::pi * kR * kR;
}  // namespace

TEST(Bonds, EllipticCriterionFailsExactlyAtTheThreeAnchors) {
  const double st = 3.0;
  EXPECT_NEAR(World::bond_criterion(st, 0, st), 1.0, 1e-14) << "pure tension at sigma = st";
  EXPECT_NEAR(World::bond_criterion(-10 * st, 0, st), 1.0, 1e-14) << "compression at -10 st";
  EXPECT_NEAR(World::bond_criterion(0, 5 * st, st), 1.0, 1e-14) << "pure shear at tau = 5 st";
  EXPECT_LT(World::bond_criterion(0.999 * st, 0, st), 1.0);
  EXPECT_GT(World::bond_criterion(1.001 * st, 0, st), 1.0);
  EXPECT_LT(World::bond_criterion(-9.99 * st, 0, st), 1.0);
  EXPECT_LT(World::bond_criterion(0, 4.99 * st, st), 1.0);
  EXPECT_LT(World::bond_criterion(-5 * st, 0, st), 1.0) << "compression far below failure";
}

TEST(Bonds, PureTensionStressIsForceOverArea) {
  BondMaterial bm;
  bm.breakable = false;
  const double v = 1e-6;
  Pair p = bonded_pair(bm, moving({0, 0, v}));
  p.w.cycle(1000);
  // The forces of the last step were computed at the positions before its update (leapfrog).
  const double delta = p.w.group_position(p.gb).z - 2 * kR - v * p.w.dt();
  const auto info = p.w.bonds();
  ASSERT_EQ(info.size(), 1u);
  // Beam force -beam_kn delta (tension), contact bond kn U = -kn delta, both acting on b.
  EXPECT_NEAR(info[0].normal_force, -(0.1 + 0.1) * delta, 1e-9 * 0.2 * delta);
  EXPECT_NEAR(info[0].sigma, 0.1 * delta / kArea, 1e-9 * 0.1 * delta / kArea) << "sigma = F/A";
  EXPECT_NEAR(info[0].tau, 0.0, 1e-20);
  EXPECT_NEAR(p.w.group_force(p.gb).z, -0.2 * delta, 1e-9 * 0.2 * delta) << "b is pulled back";
}

TEST(Bonds, BendingStressIsFourMOverPiRCubed) {
  BondMaterial bm;
  bm.breakable = false;
  const double omega = 1e-3;  // about x, perpendicular to the bond axis z
  Pair p = bonded_pair(bm, moving({0, 0, 0}, {omega, 0, 0}), false);
  p.w.cycle(1000);
  const auto info = p.w.bonds();
  ASSERT_EQ(info.size(), 1u);
  const double theta = omega * (p.w.time() - p.w.dt());  // at the last force evaluation
  const double M = 0.1 * kR * kR / 4 * theta;  // kbn I theta with kbn A = beam_kn
  EXPECT_NEAR(norm(info[0].bending_moment), M, 1e-9 * M);
  EXPECT_NEAR(info[0].sigma, 4 * M / (std::numbers::pi * std::pow(kR, 3)), 1e-9 * info[0].sigma);
  // The moment reaches the particles through the gather (store/bonds.hpp records):
  // on a, -(Mbn n + Mbs) - (Ra - U/2) n x Fs.
  const BondInfo& b = info[0];
  const Vec3 expected = -(b.normal * b.twisting_moment + b.bending_moment) -
                        (kR + 0.5 * b.gap) * cross(b.normal, b.shear_force);
  const Vec3 got = p.w.torque(p.a);
  EXPECT_GT(norm(b.bending_moment), 0.5 * norm(expected)) << "the moment dominates the torque";
  EXPECT_NEAR(norm(got - expected), 0.0, 1e-9 * norm(expected));
}

// While no bonded particle turns and every beam moment is zero, the bond stage takes the kernel
// that leaves the moments alone (stages/bonds.cpp). Once a turn has bent the beam, a step without
// spin must still carry the moment and pass it to the particles.
TEST(Bonds, BeamMomentStillActsAfterTheTurningStops) {
  BondMaterial bm;
  bm.breakable = false;
  const double omega = 1e-3;
  Pair p = bonded_pair(bm, moving({0, 0, 0}, {omega, 0, 0}), false);
  p.w.cycle(1000);
  p.w.set_group_motion(p.gb, moving({0, 0, 0}));  // held: no turn from here on
  p.w.cycle(1);  // whose forces still saw the last turn
  const double M = norm(p.w.bonds()[0].bending_moment);
  ASSERT_GT(M, 0.0);
  p.w.cycle(20);
  for (std::int64_t id : {p.a, p.b}) {
    const Vec3 w = p.w.angular_velocity(id);
    ASSERT_TRUE(w.x == 0 && w.y == 0 && w.z == 0 && !std::signbit(w.x) && !std::signbit(w.y) &&
                !std::signbit(w.z))
        << "both at +0: the steps ran the kernel without spin";
  }
  const BondInfo b = p.w.bonds()[0];
  EXPECT_NEAR(norm(b.bending_moment), M, 1e-12 * M) << "the beam stays bent";
  const Vec3 expected = -(b.normal * b.twisting_moment + b.bending_moment) -
                        (kR + 0.5 * b.gap) * cross(b.normal, b.shear_force);
  EXPECT_GT(norm(b.bending_moment), 0.5 * norm(expected));
  EXPECT_NEAR(norm(p.w.torque(p.a) - expected), 0.0, 1e-9 * norm(expected)) << "and still acts";
}

TEST(Bonds, TwistingStressIsTwoTOverPiRCubed) {
  BondMaterial bm;
  bm.breakable = false;
  const double omega = 1e-3;  // about the bond axis
  Pair p = bonded_pair(bm, moving({0, 0, 0}, {0, 0, omega}), false);
  p.w.cycle(1000);
  const auto info = p.w.bonds();
  ASSERT_EQ(info.size(), 1u);
  const double T = 0.01 * kR * kR / 2 * omega * (p.w.time() - p.w.dt());  // kbs J theta
  EXPECT_NEAR(std::fabs(info[0].twisting_moment), T, 1e-9 * T);
  EXPECT_NEAR(info[0].tau, 2 * T / (std::numbers::pi * std::pow(kR, 3)), 1e-9 * info[0].tau);
  EXPECT_NEAR(info[0].sigma, 0.0, 1e-12 * info[0].tau);
}

TEST(Bonds, TensionBreaksAtTheStrengthAndReleasesTheStoredEnergy) {
  BondMaterial bm;
  bm.tensile_strength = 2.0;  // Pa
  const double v = 1e-6;
  Pair p = bonded_pair(bm, moving({0, 0, v}));
  const Energies e0 = p.w.energies();
  while (p.w.bond_count() == 1 && p.w.step_count() < 1000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 1u);
  const BreakEvent& ev = p.w.break_events()[0];
  const double per_step = 0.1 * v * p.w.dt() / kArea;  // sigma gained per step
  EXPECT_GE(ev.sigma, 2.0);
  EXPECT_LT(ev.sigma, 2.0 + 1.0001 * per_step) << "breaks in the first step past st";
  EXPECT_EQ(ev.mode, BreakEvent::Mode::tension);
  // The stored energy at the break: springs kn (contact bond) and beam_kn, stretched by delta.
  const double delta = ev.sigma * kArea / 0.1;
  const double stored = 0.5 * (0.1 + 0.1) * delta * delta;
  EXPECT_NEAR(ev.released_energy, stored, 1e-9 * stored);
  const Energies e = p.w.energies();
  EXPECT_NEAR(e.released - e0.released, stored, 1e-9 * stored);
  EXPECT_EQ(e.strain, 0.0) << "nothing stays stored: the spheres are apart";
  EXPECT_LT(std::fabs(e.balance_error(e0)), 1e-3 * (e.boundary_work - e0.boundary_work));
  EXPECT_EQ(p.w.contact_count(), 0u);
}

TEST(Bonds, CompressedBondFailsOnlyAtTenTimesTheStrength) {
  BondMaterial bm;
  bm.tensile_strength = 0.2;
  const double v = -1e-6;
  Pair p = bonded_pair(bm, moving({0, 0, v}));
  // At -5 st (half-way to failure in compression) it holds; a criterion using |Fbn| would have
  // broken it at +st already.
  while (p.w.bond_count() == 1 && p.w.bonds()[0].sigma > -5 * 0.2) p.w.cycle(1);
  EXPECT_EQ(p.w.bond_count(), 1u);
  while (p.w.bond_count() == 1 && p.w.step_count() < 1000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 1u);
  const auto& ev = p.w.break_events()[0];
  EXPECT_EQ(ev.mode, BreakEvent::Mode::compression);
  EXPECT_NEAR(ev.sigma, -10 * 0.2, 1e-3 * 2);
  // Still overlapping: the pair goes on as an ordinary contact.
  p.w.cycle(1);
  EXPECT_EQ(p.w.contact_count(), 1u);
}

// A broken bond's pair enters the contact list in the step that breaks it, without a neighbour
// rebuild (a fracture run breaks bonds on most of its steps; bond_list.cpp, process_breaks),
// and the contact it leaves acts from the next step on with the contact law's force.
TEST(Bonds, ABreakListsTheFreedPairWithoutARebuild) {
  BondMaterial bm;
  bm.tensile_strength = 0.2;
  Pair p = bonded_pair(bm, moving({0, 0, -1e-6}));
  p.w.cycle(1);
  ASSERT_EQ(p.w.stats().pairs, 0u) << "a bonded pair is not in the contact list";
  std::uint64_t rebuilds = 0;
  while (p.w.bond_count() == 1 && p.w.step_count() < 1000000) {
    rebuilds = p.w.stats().rebuilds;
    p.w.cycle(1);
  }
  ASSERT_EQ(p.w.break_events().size(), 1u);
  EXPECT_EQ(p.w.stats().rebuilds, rebuilds) << "the breaking step rebuilt nothing";
  EXPECT_EQ(p.w.stats().pairs, 1u) << "the freed pair is listed at once";
  p.w.cycle(1);
  EXPECT_EQ(p.w.stats().rebuilds, rebuilds);
  const auto c = p.w.contacts();
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].normal_force, 0.1 * c[0].overlap, 1e-12 * c[0].normal_force) << "Fn = kn U";
  EXPECT_NEAR(p.w.group_force(p.gb).z, c[0].normal_force, 1e-12 * c[0].normal_force) << "on b, along +z";
}

// The bond kernel writes a break flag only where a bond breaks, and process_breaks removes those
// bonds, so the flags are all 0 between steps. A step that stopped before process_breaks (a
// health check) leaves its flags behind: the next bond stage clears them instead of carrying
// them into a later break.
TEST(Bonds, FlagsOfUnprocessedBreaksAreClearedNotCarried) {
  BondMaterial bm;
  bm.tensile_strength = 0.2;
  Pair p = bonded_pair(bm, moving({0, 0, 0}));
  p.w.cycle(1);
  detail::State& s = p.w.state();
  ASSERT_EQ(s.bonds.n, 1u);
  EXPECT_EQ(s.bonds.broken[0], 0.0);
  s.bonds.broken[0] = 1;              // as a kernel would have flagged it ...
  s.ctx.bond_block_breaks.assign(1, 1.0);  // ... in a step whose breaks were never processed
  p.w.cycle(1);
  EXPECT_EQ(p.w.bond_count(), 1u) << "the bond holds: nothing pulls on it";
  EXPECT_EQ(s.bonds.broken[0], 0.0) << "the stale flag is gone";
  EXPECT_TRUE(p.w.break_events().empty());
}

TEST(Bonds, ShearBreaksAtFiveTimesTheStrength) {
  // Sliding b sideways by dx also turns the bond and stretches it, giving a tension
  // sigma ~ 5 (dx / d) tau; with a strength this small, dx / d ~ 2e-4 at failure, so
  // sigma ~ 0.005 st. Through the steep normal term of the ellipse that lowers the failure shear
  // stress by 1 - sqrt(1 - 2 (4.5)(0.005) / 5.5^2 / (1 - (4.5/5.5)^2)) = 0.22 %.
  BondMaterial bm;
  bm.tensile_strength = 5e-4;
  Pair p = bonded_pair(bm, moving({1e-6, 0, 0}));
  while (p.w.bond_count() == 1 && p.w.step_count() < 2000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 1u);
  const auto& ev = p.w.break_events()[0];
  EXPECT_EQ(ev.mode, BreakEvent::Mode::shear);
  EXPECT_NEAR(ev.tau, 5 * 5e-4 * (1 - 0.0022), 0.0005 * 5 * 5e-4);
  EXPECT_LT(std::fabs(ev.sigma), 1e-3 * ev.tau);
  const double per_step = 0.01 * 1e-6 * p.w.dt() / kArea;  // tau gained per step
  EXPECT_GE(World::bond_criterion(ev.sigma, ev.tau, 5e-4), 1.0);
  EXPECT_LT(World::bond_criterion(ev.sigma, ev.tau - 1.0001 * per_step, 5e-4), 1.0);
}

// --- the contact bond, which breaks apart from the beam (model.md 5: Fcn = Fcs = c st A) -------

std::size_t breaks_of(const World& w, BreakEvent::Kind kind) {
  return std::size_t(std::count_if(w.break_events().begin(), w.break_events().end(),
                                   [&](const BreakEvent& e) { return e.kind == kind; }));
}

// Two spheres pressed u0 into each other along z and bonded there (the contact bond keeps the
// compression kn u0, the beam starts at zero); a held, b driven along x at v, dt 1e-4 s.
World pressed_pair(const BondMaterial& bm, double u0, double v) {
  WorldSettings ws;
  ws.local_damping = 0;
  World w(ws);
  const auto a = w.add_particle({0, 0, 0}, kR);
  const auto b = w.add_particle({0, 0, 2 * kR - u0}, kR);
  EXPECT_EQ(w.install_bonds(bm), 1u);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  w.add_group(std::vector<std::int64_t>{a}, fixed);
  w.add_group(std::vector<std::int64_t>{b}, moving({v, 0, 0}));
  w.set_dt(1e-4);
  return w;
}

// Pulled apart: the beam breaks at sigma = st (its force beam_kn delta = st A), the contact bond
// then holds alone, in tension, to kn delta = c st A; each break releases its own part's energy.
TEST(ContactBonds, PulledApartTheBeamBreaksAtStAndTheContactBondAtCStA) {
  BondMaterial bm;
  bm.tensile_strength = 2.0;  // Pa
  bm.contact_strength = 3.0;  // c
  const double v = 1e-6;
  Pair p = bonded_pair(bm, moving({0, 0, v}));
  const Energies e0 = p.w.energies();
  while (p.w.break_events().empty() && p.w.step_count() < 1000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 1u);
  const BreakEvent beam = p.w.break_events()[0];
  EXPECT_EQ(beam.kind, BreakEvent::Kind::beam);
  EXPECT_EQ(beam.mode, BreakEvent::Mode::tension);
  const double per_step = 0.1 * v * p.w.dt() / kArea;  // sigma gained per step
  EXPECT_GE(beam.sigma, 2.0);
  EXPECT_LT(beam.sigma, 2.0 + 1.0001 * per_step);
  const double fbn = beam.sigma * kArea;
  EXPECT_NEAR(beam.released_energy, fbn * fbn / (2 * 0.1), 1e-9 * beam.released_energy)
      << "the beam's energy only: the contact bond keeps its own";
  EXPECT_EQ(p.w.bond_count(), 0u) << "no parallel bond holds";
  ASSERT_EQ(p.w.bonds().size(), 1u) << "the contact bond still ties the pair";
  EXPECT_FALSE(p.w.bonds()[0].beam);
  EXPECT_TRUE(p.w.bonds()[0].contact_bond);
  // The contact bond alone: Fn = kn U in tension, nothing from the beam.
  p.w.cycle(100);
  const BondInfo held = p.w.bonds()[0];
  EXPECT_NEAR(held.normal_force, 0.1 * -held.gap, 1e-9 * std::fabs(held.normal_force));
  EXPECT_LT(held.normal_force, 0.0);
  while (p.w.break_events().size() == 1 && p.w.step_count() < 2000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 2u);
  const BreakEvent contact = p.w.break_events()[1];
  EXPECT_EQ(contact.kind, BreakEvent::Kind::contact_bond);
  EXPECT_EQ(contact.mode, BreakEvent::Mode::tension);
  EXPECT_GE(contact.sigma, 3.0 * 2.0) << "-Fn / A reaches c st";
  EXPECT_LT(contact.sigma, 3.0 * 2.0 + 1.0001 * per_step);
  const double fn = contact.sigma * kArea;
  EXPECT_NEAR(contact.released_energy, fn * fn / (2 * 0.1), 1e-9 * contact.released_energy)
      << "apart: the contact keeps nothing";
  EXPECT_TRUE(p.w.bonds().empty());
  const Energies e = p.w.energies();
  EXPECT_NEAR(e.released - e0.released, beam.released_energy + contact.released_energy,
              1e-12 * e.released);
  EXPECT_EQ(e.strain, 0.0);
  EXPECT_LT(std::fabs(e.balance_error(e0)), 1e-3 * (e.boundary_work - e0.boundary_work));
  EXPECT_EQ(p.w.contact_count(), 0u);
}

// However hard it is pressed, a contact bond does not break (its beam does, at -10 st); pulled
// back it breaks in tension at c st A. With c = inf it never breaks.
TEST(ContactBonds, CompressionNeverBreaksAContactBond) {
  for (const double c : {0.01, std::numeric_limits<double>::infinity()}) {
    BondMaterial bm;
    bm.tensile_strength = 0.2;
    bm.contact_strength = c;
    const double v = 1e-6;
    Pair p = bonded_pair(bm, moving({0, 0, -v}));
    while (p.w.break_events().empty() && p.w.step_count() < 1000000) p.w.cycle(1);
    ASSERT_EQ(p.w.break_events().size(), 1u);
    EXPECT_EQ(p.w.break_events()[0].kind, BreakEvent::Kind::beam);
    EXPECT_EQ(p.w.break_events()[0].mode, BreakEvent::Mode::compression);
    // Pressed on to twice the beam's failure strain: Fn = kn U, 2000 times c st A for c = 0.01.
    const std::uint64_t at = p.w.step_count();
    p.w.cycle(at);
    ASSERT_EQ(p.w.bonds().size(), 1u);
    EXPECT_GT(p.w.bonds()[0].normal_force, 1000 * 0.01 * 0.2 * kArea);
    EXPECT_EQ(breaks_of(p.w, BreakEvent::Kind::contact_bond), 0u) << "compression never breaks it";
    // Pulled back until the spheres are 10 % of a radius apart.
    p.w.set_group_motion(p.gb, moving({0, 0, 20 * v}));
    while (p.w.position(p.b).z < 2.1 * kR && p.w.step_count() < 10000000) p.w.cycle(1);
    if (std::isinf(c)) {
      EXPECT_EQ(breaks_of(p.w, BreakEvent::Kind::contact_bond), 0u) << "c = inf: never";
      ASSERT_EQ(p.w.bonds().size(), 1u);
      EXPECT_NEAR(p.w.bonds()[0].normal_force, -0.1 * p.w.bonds()[0].gap, 1e-9 * 0.01 * kR)
          << "still pulling with kn U";
    } else {
      ASSERT_EQ(breaks_of(p.w, BreakEvent::Kind::contact_bond), 1u);
      const BreakEvent& ev = p.w.break_events()[1];
      EXPECT_EQ(ev.mode, BreakEvent::Mode::tension);
      EXPECT_GE(ev.sigma, c * 0.2);
      EXPECT_LT(ev.sigma, c * 0.2 + 1.0001 * 0.1 * 20 * v * p.w.dt() / kArea);
      EXPECT_TRUE(p.w.bonds().empty());
    }
  }
}

// Sheared under a small compression: the contact bond breaks when its shear force reaches
// c st A (the beam, at tau = st then, holds), and the contact springs carry on as an ordinary
// contact, their shear force capped at mu Fn, the slip dissipated booked as friction.
TEST(ContactBonds, ShearBreaksTheContactBondAtCStAAndLeavesFriction) {
  const double st = 0.02, c = 1.0, u0 = 1e-4 * kR, v = 1e-6;
  BondMaterial bm;
  bm.tensile_strength = st;
  bm.contact_strength = c;
  World w = pressed_pair(bm, u0, v);
  const Energies e0 = w.energies();
  while (w.break_events().empty() && w.step_count() < 1000000) w.cycle(1);
  ASSERT_EQ(w.break_events().size(), 1u);
  const BreakEvent& ev = w.break_events()[0];
  EXPECT_EQ(ev.kind, BreakEvent::Kind::contact_bond);
  EXPECT_EQ(ev.mode, BreakEvent::Mode::shear);
  const double per_step = 0.01 * v * w.dt() / kArea;  // |Fs| / A gained per step
  EXPECT_GE(ev.tau, c * st);
  EXPECT_LT(ev.tau, c * st + 1.0001 * per_step);
  EXPECT_EQ(w.energies().friction, e0.friction) << "no slip while the contact bond held";
  w.cycle(1000);
  ASSERT_EQ(w.bonds().size(), 1u);
  EXPECT_TRUE(w.bonds()[0].beam) << "the beam holds: tau = st is far from 5 st";
  EXPECT_FALSE(w.bonds()[0].contact_bond);
  const detail::State& s = w.state();
  const double fn = s.bonds.fn[0];
  const double fs = std::sqrt(s.bonds.fsx[0] * s.bonds.fsx[0] + s.bonds.fsy[0] * s.bonds.fsy[0] +
                              s.bonds.fsz[0] * s.bonds.fsz[0]);
  EXPECT_NEAR(fn, 0.1 * s.bonds.overlap[0], 1e-9 * fn) << "Fn = kn U: still pressed";
  EXPECT_GT(fn, 0.0);
  EXPECT_NEAR(fs, 0.5 * fn, 1e-9 * fs) << "slipping at mu Fn";
  // Slip per step: mu Fn (|Fs_trial| - mu Fn) / ks with |Fs_trial| - mu Fn = ks v dt.
  const double friction = w.energies().friction - e0.friction;
  EXPECT_NEAR(friction, 1000 * 0.5 * fn * v * w.dt(), 0.01 * friction);
  const Energies e = w.energies();
  EXPECT_LT(std::fabs(e.balance_error(e0)), 1e-3 * (e.boundary_work - e0.boundary_work));
}

// With its own shear strength cs (contact_shear_strength), the contact bond breaks in shear at
// cs st A instead; with cs = inf never, whatever the shear.
TEST(ContactBonds, AShearStrengthOfItsOwn) {
  const double st = 0.02, u0 = 1e-4 * kR, v = 1e-6;
  for (const double cs : {2.5, std::numeric_limits<double>::infinity()}) {
    BondMaterial bm;
    bm.tensile_strength = st;
    bm.contact_strength = 1.0;
    bm.contact_shear_strength = cs;
    bm.beam_ks = 1e-4;  // a soft beam in shear: it holds past 2.5 st A of contact shear
    World w = pressed_pair(bm, u0, v);
    // Sheared to three times c st A of contact shear force (ks dx).
    const std::uint64_t steps = std::uint64_t(3 * st * kArea / (0.01 * v * 1e-4));
    while (w.break_events().empty() && w.step_count() < steps) w.cycle(1);
    if (std::isinf(cs)) {
      EXPECT_TRUE(w.break_events().empty()) << "cs = inf: no shear breaks it";
    } else {
      ASSERT_EQ(w.break_events().size(), 1u);
      const BreakEvent& ev = w.break_events()[0];
      EXPECT_EQ(ev.kind, BreakEvent::Kind::contact_bond);
      EXPECT_EQ(ev.mode, BreakEvent::Mode::shear);
      EXPECT_GE(ev.tau, cs * st);
      EXPECT_LT(ev.tau, cs * st + 1.0001 * 0.01 * v * w.dt() / kArea);
    }
  }
}

// With a friction mu_b, the contact bond's shear strength grows with the compression it carries:
// Fcs = cs st A + mu_b Fn (Mohr-Coulomb), Fn = kn u0 here.
TEST(ContactBonds, CompressionRaisesTheShearStrengthByItsFriction) {
  const double st = 0.02, u0 = 1e-3 * kR, v = 1e-6, mu_b = 0.5;
  BondMaterial bm;
  bm.tensile_strength = st;
  bm.contact_strength = 1.0;
  bm.contact_bond_friction = mu_b;
  bm.beam_ks = 1e-4;  // a soft beam in shear: it holds
  World w = pressed_pair(bm, u0, v);
  while (w.break_events().empty() && w.step_count() < 1000000) w.cycle(1);
  ASSERT_EQ(w.break_events().size(), 1u);
  const BreakEvent& ev = w.break_events()[0];
  EXPECT_EQ(ev.kind, BreakEvent::Kind::contact_bond);
  EXPECT_EQ(ev.mode, BreakEvent::Mode::shear);
  const double fn = -ev.sigma * kArea;  // the contact bond's normal force at the break (> 0)
  // Still pressed, by a little less than kn u0: sliding b by dx stretches the pair by dx^2 / 2d.
  EXPECT_GT(fn, 0.95 * 0.1 * u0);
  EXPECT_LT(fn, 0.1 * u0);
  const double strength = st * kArea + mu_b * fn;
  EXPECT_GE(ev.tau * kArea, strength);
  EXPECT_LT(ev.tau * kArea, strength + 1.0001 * 0.01 * v * w.dt());
}

// A checkpoint keeps what of each bond holds and the kind of each break: the loaded world goes
// on bit for bit.
TEST(ContactBonds, ACheckpointKeepsWhatHolds) {
  BondMaterial bm;
  bm.tensile_strength = 2.0;
  bm.contact_strength = 3.0;
  Pair p = bonded_pair(bm, moving({0, 0, 1e-6}));
  while (p.w.break_events().empty() && p.w.step_count() < 1000000) p.w.cycle(1);
  const std::string path = ::testing::TempDir() + "/contact_bond_only.h5";
  p.w.save(path);
  World loaded = World::load(path, 1, "auto");
  ASSERT_EQ(loaded.bonds().size(), 1u);
  EXPECT_FALSE(loaded.bonds()[0].beam);
  EXPECT_TRUE(loaded.bonds()[0].contact_bond);
  EXPECT_EQ(loaded.break_events()[0].kind, BreakEvent::Kind::beam);
  for (World* w : {&p.w, &loaded})
    while (w->break_events().size() == 1 && w->step_count() < 2000000) w->cycle(1);
  ASSERT_EQ(loaded.break_events().size(), 2u);
  EXPECT_EQ(loaded.break_events()[1].kind, BreakEvent::Kind::contact_bond);
  EXPECT_EQ(loaded.break_events()[1].step, p.w.break_events()[1].step);
  EXPECT_EQ(loaded.break_events()[1].sigma, p.w.break_events()[1].sigma);
}

// c = 0 is the earlier model: the contact bond breaks with the beam, one event, the pair an
// ordinary contact at once.
TEST(ContactBonds, ZeroBreaksTheContactBondWithTheBeam) {
  BondMaterial bm;
  bm.tensile_strength = 0.2;
  bm.contact_strength = 0;
  Pair p = bonded_pair(bm, moving({0, 0, -1e-6}));
  while (p.w.break_events().empty() && p.w.step_count() < 1000000) p.w.cycle(1);
  ASSERT_EQ(p.w.break_events().size(), 1u);
  EXPECT_EQ(p.w.break_events()[0].kind, BreakEvent::Kind::beam);
  EXPECT_TRUE(p.w.bonds().empty());
  EXPECT_EQ(p.w.stats().pairs, 1u) << "an ordinary contact now";
}

TEST(Bonds, BondedOscillatorHasThePeriodOfTheCombinedStiffness) {
  WorldSettings ws;
  ws.local_damping = 0;
  World w(ws);
  const auto a = w.add_particle({0, 0, 0}, kR);
  const auto b = w.add_particle({0, 0, 2 * kR}, kR);
  BondMaterial bm;
  bm.breakable = false;
  bm.beam_kn = 0.3;
  w.install_bonds(bm);
  w.set_velocity(b, {0, 0, 1e-5});
  const double m_eff = w.mass(a) / 2;
  const double period = 2 * std::numbers::pi * std::sqrt(m_eff / (0.1 + 0.3));
  w.set_dt(period / 2000);
  // Times when the gap crosses zero upwards.
  std::vector<double> crossings;
  double prev = 0;
  for (int k = 0; k < 2000 * 5; ++k) {
    w.cycle(1);
    const double gap = w.position(b).z - w.position(a).z - 2 * kR;
    if (prev < 0 && gap >= 0) crossings.push_back(w.time() - w.dt() * gap / (gap - prev));
    prev = gap;
  }
  ASSERT_GE(crossings.size(), 3u);
  const double measured = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  EXPECT_NEAR(measured, period, 1e-4 * period);
}

TEST(Bonds, CriticalStepIncludesTheBondAndBondedRotationIsLocked) {
  WorldSettings ws;
  World w(ws);
  const auto a = w.add_particle({0, 0, 0}, kR);
  w.add_particle({0, 0, 2 * kR}, kR);
  BondMaterial bm;
  bm.breakable = false;
  bm.beam_kn = 0.3;
  w.install_bonds(bm);
  EXPECT_NEAR(w.critical_dt(), std::sqrt(w.mass(a) / (0.1 + 0.3)), 1e-15);
  EXPECT_THROW(w.set_angular_velocity(a, {1, 0, 0}), Error) << "locked while bonded";
}

// The rotation lock under damage (model.md 2, neighbor/topology.cpp refresh_bond_topology): a particle
// none of whose bonds broke is locked however few it holds; a damaged one while it holds
// rotation_lock_bonds. A star (centre with four bonds) and an arm (two bonds) lose bonds to
// neighbours pulled away.
TEST(Bonds, AnIntactParticleStaysLockedAndADamagedOneWhileItHoldsTheThreshold) {
  WorldSettings ws;
  ws.rotation_lock_bonds = 3;
  World w(ws);
  // The pulled neighbours are smaller: their bonds' beams are thinner, so theirs break first.
  const double r = 0.8 * kR;
  const auto centre = w.add_particle({0, 0, 0}, kR);
  const auto arm = w.add_particle({2 * kR, 0, 0}, kR);     // bonded to the centre and the tip
  const auto back = w.add_particle({-2 * kR, 0, 0}, kR);
  const auto north = w.add_particle({0, kR + r, 0}, r);
  const auto south = w.add_particle({0, -kR - r, 0}, r);
  const auto tip = w.add_particle({3 * kR + r, 0, 0}, r);
  BondMaterial bm;
  bm.tensile_strength = 2.0;  // Pa
  ASSERT_EQ(w.install_bonds(bm), 5u);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  w.add_group(std::vector<std::int64_t>{back}, fixed);
  const int gn = w.add_group(std::vector<std::int64_t>{north}, fixed);
  const int gs = w.add_group(std::vector<std::int64_t>{south}, fixed);
  const int gt = w.add_group(std::vector<std::int64_t>{tip}, fixed);
  auto pull = [&](int group, Vec3 v) {
    GroupMotion m;
    m.translation = {Dof::velocity, Dof::velocity, Dof::velocity};
    m.velocity = v;
    w.set_group_motion(group, m);
    const std::size_t before = w.bond_count();
    while (w.bond_count() == before && w.step_count() < 2000000) w.cycle(1);
    ASSERT_EQ(w.bond_count(), before - 1);
    w.set_group_motion(group, fixed);
  };
  EXPECT_TRUE(locked(w, centre));
  EXPECT_TRUE(locked(w, arm)) << "two bonds, none broken: locked although fewer than rotation_lock_bonds";
  pull(gt, {1e-6, 0, 0});
  EXPECT_FALSE(locked(w, arm)) << "damaged, and its one bond is below min(3, 2 installed)";
  pull(gn, {0, 1e-6, 0});
  EXPECT_TRUE(locked(w, centre)) << "three of four bonds left: still the threshold";
  pull(gs, {0, -1e-6, 0});
  EXPECT_FALSE(locked(w, centre)) << "two of four left: below the threshold";
  EXPECT_TRUE(locked(w, back)) << "intact: locked";
  // A checkpoint keeps the count of broken bonds, so the loaded world locks the same particles.
  const std::string path = ::testing::TempDir() + "/damaged_locks.h5";
  w.save(path);
  World loaded = World::load(path, 1, "auto");
  EXPECT_FALSE(locked(loaded, arm)) << "the arm's broken bond is remembered (without it, its one bond would lock it)";
  EXPECT_TRUE(locked(loaded, back));
}

// rotation_lock_beams (model.md 5's alternative): only bonds whose parallel bond holds lock a
// particle. A free particle between two anchors pulled apart: both beams break, the contact bonds
// (c = inf) hold; by default it stays locked, counting beams only it turns, and a checkpoint keeps
// the rule.
TEST(Bonds, CountingBeamsOnlyAParticleHeldByContactBondsAloneTurns) {
  World w;
  const auto free = w.add_particle({0, 0, 0}, kR);
  const auto above = w.add_particle({0, 0, 2 * kR}, kR);
  const auto below = w.add_particle({0, 0, -2 * kR}, kR);
  BondMaterial bm;
  bm.tensile_strength = 2.0;  // Pa
  bm.contact_strength = std::numeric_limits<double>::infinity();
  ASSERT_EQ(w.install_bonds(bm), 2u);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  const int ga = w.add_group(std::vector<std::int64_t>{above}, moving({0, 0, 1e-6}));
  const int gb = w.add_group(std::vector<std::int64_t>{below}, moving({0, 0, -1e-6}));
  while (w.bond_count() > 0 && w.step_count() < 2000000) w.cycle(1);
  w.set_group_motion(ga, fixed);
  w.set_group_motion(gb, fixed);
  ASSERT_EQ(w.bond_count(), 0u) << "both beams broke";
  ASSERT_EQ(w.bonds().size(), 2u) << "the contact bonds hold";
  EXPECT_FALSE(w.settings().rotation_lock_beams);
  EXPECT_TRUE(locked(w, free)) << "by default a contact bond alone locks";
  w.set_rotation_lock_beams(true);
  EXPECT_FALSE(locked(w, free)) << "no parallel bond holds: it turns";
  w.cycle(10);
  EXPECT_FALSE(locked(w, free));
  const std::string path = ::testing::TempDir() + "/beam_locks.h5";
  w.save(path);
  World loaded = World::load(path, 1, "auto");
  EXPECT_TRUE(loaded.settings().rotation_lock_beams);
  EXPECT_FALSE(locked(loaded, free));
  w.set_rotation_lock_beams(false);
  EXPECT_TRUE(locked(w, free)) << "the default rule back";
}

TEST(Bonds, InstallationBondsEveryTouchingPairOnce) {
  World w;
  const int n = 5;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) w.add_particle({i * 2 * kR, j * 2 * kR, k * 2.0005 * kR}, kR);
  BondMaterial bm;
  bm.tensile_strength = 1;
  // Gaps: 0 along x and y, 1e-4 R along z; tolerance 1e-3 x mean radius bonds all of them.
  EXPECT_EQ(w.install_bonds(bm), std::size_t(3 * n * n * (n - 1)));
  EXPECT_EQ(w.install_bonds(bm), 0u) << "already bonded";
  EXPECT_EQ(w.contact_count(), 0u) << "bonded pairs are not contacts";
  BondMaterial other = bm;
  other.tensile_strength = 2;
  EXPECT_THROW(w.install_bonds(other), Error);
  BondMaterial bad;
  bad.tensile_strength = 0;
  EXPECT_THROW(w.install_bonds(bad), Error) << "breakable without a strength";
}

// Bonds for a subset of particles join only particles of that subset, even when the neighbour
// build inside install_bonds reorders the store (it did: the subset was marked by index before
// the build, and a reorder there bonded other particles, e.g. across the 4 cm joint's mould).
TEST(Bonds, InstallationForSomeIdsBondsOnlyThoseWhenTheBuildReorders) {
  WorldSettings ws;
  ws.reorder_interval = 1;  // every build after the first reorders
  World w(ws);
  const int n = 6;
  std::vector<Vec3> at;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) at.push_back({i * 2 * kR, j * 2 * kR, k * 2 * kR});
  std::vector<std::int64_t> ids;
  for (const Vec3& x : at) ids.push_back(w.add_particle(x, kR));
  w.rebuild_neighbors();  // the store in cell order
  // The particles change places (as a packing moves them), so the next build's reorder permutes
  // the store.
  std::mt19937_64 rng(3);
  std::shuffle(at.begin(), at.end(), rng);
  std::vector<std::int64_t> lower;
  std::vector<bool> is_lower(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    w.set_position(ids[k], at[k]);
    is_lower[std::size_t(ids[k])] = at[k].z < (n / 2) * 2 * kR - kR;
    if (is_lower[std::size_t(ids[k])]) lower.push_back(ids[k]);
  }
  const auto reorders = w.stats().reorders;
  BondMaterial bm;
  bm.breakable = false;
  const std::size_t made = w.install_bonds(bm, -1, lower);
  EXPECT_GT(w.stats().reorders, reorders) << "the build inside install_bonds must reorder";
  // The lower half is the n/2 bottom layers: n (n - 1) touching pairs along x and as many along y
  // in each layer, n^2 between consecutive layers.
  const std::size_t layers = n / 2;
  EXPECT_EQ(made, layers * 2 * n * (n - 1) + (layers - 1) * n * n);
  for (const BondInfo& b : w.bonds()) {
    EXPECT_TRUE(is_lower[std::size_t(b.id_a)]) << b.id_a;
    EXPECT_TRUE(is_lower[std::size_t(b.id_b)]) << b.id_b;
  }
}

// A neighbour build writes the list into the spare pair store and swaps it in. Where builds
// come seldom (here a still block, a build after a thousand steps without one) the previous list
// stays as the next spare only where bonds can break (break steps merge freed pairs through it);
// elsewhere it is released, or every run would hold a second pair list resident
// (neighbor/build.cpp, keep_spares).
TEST(Bonds, AfterRareBuildsTheSparePairListIsKeptOnlyWhereBondsCanBreak) {
  for (const bool breakable : {false, true}) {
    World w;
    const int n = 4;
    std::vector<std::int64_t> lower;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const std::int64_t id = w.add_particle({i * 2 * kR, j * 2 * kR, k * 2 * kR}, kR);
          if (k < n / 2) lower.push_back(id);
        }
    BondMaterial bm;
    bm.breakable = breakable;
    bm.tensile_strength = 1;
    ASSERT_GT(w.install_bonds(bm, -1, lower), 0u);
    w.rebuild_neighbors();
    const detail::State& s = w.state();
    const std::uint64_t builds = s.rebuilds;
    w.cycle(1000);
    ASSERT_EQ(s.rebuilds, builds) << "the block stays still";
    w.rebuild_neighbors();
    ASSERT_GT(s.pairs.n, 0u) << "the upper half's pairs are listed";
    if (breakable) {
      EXPECT_EQ(s.cache.spare_pairs.n, s.pairs.n) << "the previous list (nothing moved) kept as the spare";
    } else {
      EXPECT_EQ(s.cache.spare_pairs.a.capacity(), 0u) << "unbreakable bonds: the previous list released";
      EXPECT_EQ(s.cache.spare_pairs.fn.capacity(), 0u);
    }
  }
}

// Bonds installed in a world that never ran keep the world's skin (the search for bonded pairs
// needs only 2 x tolerance; once, that became the skin, and the list was rebuilt every step).
TEST(Bonds, InstallingBeforeTheFirstStepKeepsTheSkin) {
  WorldSettings ws;
  ws.skin = 0.2 * kR;
  World w(ws);
  const int n = 4;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) w.add_particle({i * 1.99 * kR, j * 1.99 * kR, k * 1.99 * kR}, kR);
  BondMaterial bm;
  bm.breakable = false;
  ASSERT_EQ(w.install_bonds(bm), std::size_t(3 * n * n * (n - 1)));
  const auto before = w.stats().rebuilds;
  w.cycle(200);  // the block relaxes its 0.5 % overlaps: moves of order 1e-3 R
  EXPECT_LE(w.stats().rebuilds - before, 2u);
}

namespace {
// Two spheres along z overlapping by u0, both free, no damping; bonded (stress-free or keeping the
// contact force kn u0).
World overlapping_bonded_pair(double u0, bool stress_free, double strength = 0) {
  WorldSettings ws;
  ws.local_damping = 0;
  ws.dt = 1e-4;
  World w(ws);
  w.add_particle({0, 0, 0}, kR);
  w.add_particle({0, 0, 2 * kR - u0}, kR);
  BondMaterial bm;
  bm.breakable = strength > 0;
  bm.tensile_strength = strength;
  EXPECT_EQ(w.install_bonds(bm, -1, {}, stress_free), 1u);
  return w;
}
}  // namespace

TEST(Bonds, StressFreeInstallationLeavesAnOverlappingPairAtRest) {
  const double u0 = 0.02 * kR;
  World kept = overlapping_bonded_pair(u0, false), free = overlapping_bonded_pair(u0, true);
  const auto x0 = free.positions();
  kept.cycle(50);  // 0.44 of the pair's period: b has moved by nearly u0 / 2
  free.cycle(50);
  // Kept (model.md 5): the contact bond pushes with kn u0 and the pair oscillates about the
  // distance where the contact bond's push equals the beam's pull.
  EXPECT_GT(kept.positions()[5] - x0[5], 0.25 * u0) << "the kept contact force pushes b away";
  // Stress-free: no force at the installed distance, so nothing moves and nothing is stored.
  EXPECT_EQ(free.positions(), x0);
  EXPECT_EQ(free.energies().strain, 0.0);
  // And the equilibrium ratio says so (no force at all), where the kept pair is out of balance.
  EXPECT_EQ(free.unbalanced_force_ratio(), 0.0);
  EXPECT_GT(kept.unbalanced_force_ratio(), 0.1);
  const auto info = free.bonds();
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].normal_force, 0.0);
}

TEST(Bonds, StressFreeBondResistsFromTheInstalledDistanceAndItsContactKeepsTheRestOverlap) {
  // b driven along z; a held. The bond is stiff kn + beam_kn about the installed distance; it
  // breaks in tension at sigma = st, i.e. a stretch delta = st A / beam_kn, while the spheres
  // still overlap (u0 > delta): the contact left behind is unloaded until b comes back past the
  // installed overlap, then pushes with kn (U - u0). Once the spheres part it is an ordinary
  // contact again (Fn = kn U).
  const double u0 = 0.02 * kR, st = 0.5, kn = 0.1;
  World w = overlapping_bonded_pair(u0, true, st);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  w.add_group(std::vector<std::int64_t>{0}, fixed);
  const double v = 1e-5;
  const int gb = w.add_group(std::vector<std::int64_t>{1}, moving({0, 0, v}));
  const double z0 = w.group_position(gb).z;
  // Stretch from the installed distance where the last step's forces were evaluated: the
  // position before that step's move (leapfrog).
  auto stretch = [&] { return w.group_position(gb).z - w.group_velocity(gb).z * w.dt() - z0; };
  w.cycle(100);
  EXPECT_NEAR(w.group_force(gb).z, -2 * kn * stretch(), 1e-9 * 2 * kn * stretch())
      << "contact bond and beam, both from the installed distance";
  const double delta = st * kArea / kn;
  ASSERT_LT(delta, u0) << "the test needs the break while the spheres overlap";
  while (w.bond_count() == 1 && w.step_count() < 1000000) w.cycle(1);
  ASSERT_EQ(w.break_events().size(), 1u);
  EXPECT_NEAR(w.break_events()[0].sigma, st, 1e-3 * st);
  w.cycle(10);
  ASSERT_EQ(w.contact_count(), 1u) << "the spheres still overlap";
  EXPECT_EQ(w.group_force(gb).z, 0.0) << "0 < U < u0: the contact is unloaded";
  // Back: push b in until it is 0.5 u0 past the installed distance.
  w.set_group_motion(gb, moving({0, 0, -v}));
  while (stretch() > -0.5 * u0) w.cycle(1);
  w.cycle(1);
  const double u_beyond = -stretch();  // U - u0 at the last force evaluation
  ASSERT_GT(u_beyond, 0.0);
  EXPECT_NEAR(w.group_force(gb).z, kn * u_beyond, 1e-6 * kn * u_beyond) << "Fn = kn (U - u0)";
  // Apart: pull b until the spheres no longer touch, then back into a small overlap.
  w.set_group_motion(gb, moving({0, 0, 20 * v}));
  while (stretch() < u0 + 0.01 * kR) w.cycle(1);
  w.cycle(5);
  EXPECT_EQ(w.contact_count(), 0u);
  w.set_group_motion(gb, moving({0, 0, -20 * v}));
  while (stretch() > u0 - 0.005 * kR) w.cycle(1);
  w.cycle(1);
  const double U = u0 - stretch();
  ASSERT_GT(U, 0.0);
  EXPECT_NEAR(w.group_force(gb).z, kn * U, 1e-6 * kn * U) << "forgotten: Fn = kn U again";
}

// Param: the shared layout of test::kernel_test_pair (else separate).
class SimdBondKernel : public ::testing::TestWithParam<bool> {};

TEST_P(SimdBondKernel, EqualsTheScalarReferenceBitwise) {
  const bool shared = GetParam();
  const std::size_t bonds = 2048, n = 2 * bonds;  // enough for either layout
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  AVec<double> x(n), y(n), z(n), vx(n), vy(n), vz(n), wx(n), wy(n), wz(n), r(n);
  AVec<std::int64_t> a(bonds), b(bonds);
  AVec<double> rb(bonds);
  std::vector<AVec<double>> hist(29, AVec<double>(bonds));  // 27: rest overlaps, 28: what holds; 16, 18..26 unused
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = kR * (1 + 0.3 * u(rng));
    vx[i] = 1e-3 * u(rng); vy[i] = 1e-3 * u(rng); vz[i] = 1e-3 * u(rng);
    wx[i] = u(rng); wy[i] = u(rng); wz[i] = u(rng);
    x[i] = u(rng); y[i] = u(rng); z[i] = u(rng);
  }
  for (std::size_t k = 0; k < bonds; ++k) {
    std::tie(a[k], b[k]) = test::kernel_test_pair(k, bonds, shared);
    const auto ia = std::size_t(a[k]), ib = std::size_t(b[k]);
    Vec3 dir{u(rng), u(rng), u(rng)};
    dir = dir / norm(dir);
    const double d = (r[ia] + r[ib]) * (1 + 0.01 * u(rng));
    x[ib] = x[ia] + d * dir.x; y[ib] = y[ia] + d * dir.y; z[ib] = z[ia] + d * dir.z;
    rb[k] = std::min(r[ia], r[ib]);
    hist[0][k] = dir.x; hist[1][k] = dir.y; hist[2][k] = dir.z;
    // Forces ~1e-6 N and moments ~1e-10 N m give stresses ~1 Pa, around the strength of 1 Pa.
    for (int c = 3; c < 12; ++c) hist[c][k] = 1e-6 * u(rng);
    for (int c = 12; c < 16; ++c) hist[c][k] = 1e-10 * u(rng);
    hist[27][k] = (k % 3 == 0) ? 0.01 * r[ia] * u(rng) : 0.0;  // rest overlaps, stress-free bonds
    hist[28][k] = double(1 + k % 3);  // beam only, contact bond only, both (BondStore::holds)
  }
  // kernel: 0 the full law, 1 without spin, 2 without spin and beam moments, 3 the same for bonds
  // no end of which turns (records of the forces only). partial: bonds that
  // lost their beam or their contact bond, contact bonds of strength 2 st A (else every bond
  // holds both, and the contact bond breaks with the beam).
  auto run = [&](const kernels::KernelSet& ks, std::vector<AVec<double>> h, bool rest,
                 int kernel = 0, bool partial = false) {
    kernels::BondKernelArgs args{x.data(), y.data(), z.data(), vx.data(), vy.data(), vz.data(),
                                 wx.data(), wy.data(), wz.data(), r.data(), a.data(), b.data(),
                                 rb.data(), h[0].data(), h[1].data(), h[2].data(), h[3].data(),
                                 h[4].data(), h[5].data(), h[6].data(), h[7].data(), h[8].data(),
                                 h[9].data(), h[10].data(), h[11].data(), h[12].data(),
                                 h[13].data(), h[14].data(), h[15].data(), h[17].data(),
                                 nullptr, 0.1, 0.01, 0.1, 0.01, 1e-3, 1.0, n,
                                 rest ? h[27].data() : nullptr};
    if (partial) {
      args.holds = h[28].data();
      args.friction = 0.5;
      args.contact_strength = 2.0;
      args.contact_shear_strength = 3.0;
      args.contact_bond_friction = 0.3;
    }
    // The gather's records (store/bonds.hpp): every slot written, the pads with 0; records of 8
    // (no moment) from the kernel without moments and of 4 (force and overlap) from the one for
    // bonds whose ends do not turn, whose slots beyond them stay untouched.
    const std::size_t width = kernel == 3 ? 4 : kernel == 2 ? 8 : 12;
    AVec<double> records(12 * bonds, -7.0);
    args.out = records.data();
    const kernels::BondKernel kernels[] = {ks.bond, ks.bond_norot, ks.bond_no_moment, ks.bond_forces};
    const kernels::BondSums broken = kernels[kernel](args, 0, bonds);
    // Record column j as a column of its own (18 + j for the force, overlap and n x Fs, then
    // the moment: -1 where the record has none), so the comparisons below see them.
    for (std::size_t k = 0; k < bonds; ++k) {
      for (std::size_t j = 0; j < 7; ++j) h[18 + j][k] = j < width ? records[width * k + j] : -1.0;
      if (width > 4) {
        EXPECT_EQ(records[width * k + 7], 0.0);
      }
      if (width == 12) {
        h[25][k] = records[12 * k + 8];
        h[26][k] = records[12 * k + 10];
        h[16][k] = records[12 * k + 9];
        EXPECT_EQ(records[12 * k + 11], 0.0);
      } else {
        h[25][k] = h[26][k] = h[16][k] = -1.0;
      }
    }
    if (width < 12) {
      EXPECT_EQ(records[width * bonds], -7.0) << "records of " << width << ": nothing written beyond them";
    }
    return std::make_pair(broken, h);
  };
  for (int variant = 0; variant < 4; ++variant) {
    const bool rest = variant % 2 == 1, partial = variant >= 2;
    const auto ref = run(kernels::scalar_kernels(), hist, rest, 0, partial);
    ASSERT_GT(ref.first.breaks, 0.0) << "some random bonds must break";
    ASSERT_LT(ref.first.breaks, double(bonds)) << "and some must hold";
    if (partial) {
      EXPECT_GT(ref.first.slip, 0.0) << "contact springs without their contact bond slip";
      bool contact_breaks = false;
      for (std::size_t k = 0; k < bonds; ++k) contact_breaks = contact_breaks || ref.second[17][k] >= 2;
      EXPECT_TRUE(contact_breaks) << "some contact bonds break on their own";
    } else {
      EXPECT_EQ(ref.first.slip, 0.0) << "intact contact bonds do not slip";
    }
    if (rest) {
      const auto without = run(kernels::scalar_kernels(), hist, false);
      EXPECT_NE(0, std::memcmp(without.second[6].data(), ref.second[6].data(), bonds * sizeof(double)))
          << "the rest overlaps change the contact bond's normal force";
    }
    for (const auto& arch : available_simd_architectures()) {
      const auto got = run(kernels::select_kernels(arch), hist, rest, 0, partial);
      EXPECT_EQ(got.first.breaks, ref.first.breaks) << arch;
      // The slip energy is summed per lane first: equal to rounding (like the pair kernel's).
      EXPECT_NEAR(got.first.slip, ref.first.slip, 1e-12 * ref.first.slip) << arch;
      for (int c = 0; c < 29; ++c)
        EXPECT_EQ(0, std::memcmp(got.second[c].data(), ref.second[c].data(), bonds * sizeof(double)))
            << arch << " column " << c << (rest ? " rest" : "") << (partial ? " partial" : "");
    }
  }
  // With every angular velocity +0 (bonded particles do not rotate), the kernel that does not
  // read them gives the same values bit for bit: the bond stage takes it then (bonds.cpp).
  for (auto* c : {&wx, &wy, &wz}) std::fill(c->begin(), c->end(), 0.0);
  for (const auto& arch : available_simd_architectures()) {
    const auto& ks = kernels::select_kernels(arch);
    const auto full = run(ks, hist, true, 0), shortcut = run(ks, hist, true, 1);
    EXPECT_EQ(full.first.breaks, shortcut.first.breaks) << arch;
    for (int c = 0; c < 28; ++c)
      EXPECT_EQ(0, std::memcmp(full.second[c].data(), shortcut.second[c].data(), bonds * sizeof(double)))
          << arch << " column " << c;
  }
  // And with every beam moment +-0 as well (a specimen whose bonded particles never turned), the
  // kernel that neither carries nor stores the moments: the same bits in every other column and
  // in the criterion (the breaks), the moment columns left as they were, records of 8 without the
  // moment (the kernel without spin gives +-0 there). Its SIMD forms equal its scalar reference.
  for (int c = 12; c < 16; ++c)
    for (std::size_t k = 0; k < bonds; ++k) hist[c][k] = (k + std::size_t(c)) % 3 == 0 ? -0.0 : 0.0;
  const auto no_moment_ref = run(kernels::scalar_kernels(), hist, true, 2);
  for (const auto& arch : available_simd_architectures()) {
    const auto& ks = kernels::select_kernels(arch);
    const auto carried = run(ks, hist, true, 1), unmoved = run(ks, hist, true, 2);
    EXPECT_EQ(carried.first.breaks, unmoved.first.breaks) << arch;
    EXPECT_GT(unmoved.first.breaks, 0.0) << "the criterion still breaks bonds";
    for (int c = 0; c < 28; ++c) {
      const auto& got = unmoved.second[c];
      EXPECT_EQ(0, std::memcmp(got.data(), no_moment_ref.second[c].data(), bonds * sizeof(double)))
          << arch << " column " << c << " against the scalar reference";
      if (c >= 12 && c <= 15) {
        EXPECT_EQ(0, std::memcmp(got.data(), hist[c].data(), bonds * sizeof(double)))
            << arch << " moment column " << c << " is not written";
      } else if (c == 16 || c == 25 || c == 26) {  // the record's moment: none in records of 8
        for (std::size_t k = 0; k < bonds; ++k)
          ASSERT_EQ(carried.second[c][k], 0.0) << arch << " column " << c << " bond " << k;
      } else {
        EXPECT_EQ(0, std::memcmp(got.data(), carried.second[c].data(), bonds * sizeof(double)))
            << arch << " column " << c;
      }
    }
  }
  // Where besides no end of a bond turns (BondRecord::forces): the same bits as the kernel
  // without moments in every column and in the criterion, the records' n x Fs left out. Its SIMD
  // forms equal its scalar reference.
  const auto forces_ref = run(kernels::scalar_kernels(), hist, true, 3);
  for (const auto& arch : available_simd_architectures()) {
    const auto& ks = kernels::select_kernels(arch);
    const auto levers = run(ks, hist, true, 2), forces = run(ks, hist, true, 3);
    EXPECT_EQ(levers.first.breaks, forces.first.breaks) << arch;
    for (int c = 0; c < 29; ++c) {
      EXPECT_EQ(0, std::memcmp(forces.second[c].data(), forces_ref.second[c].data(), bonds * sizeof(double)))
          << arch << " column " << c << " against the scalar reference";
      if (c >= 22 && c <= 24) {  // n x Fs: none in records of 4
        for (std::size_t k = 0; k < bonds; ++k) ASSERT_EQ(forces.second[c][k], -1.0) << arch << " column " << c;
      } else {
        EXPECT_EQ(0, std::memcmp(forces.second[c].data(), levers.second[c].data(), bonds * sizeof(double)))
            << arch << " column " << c;
      }
    }
  }
}
INSTANTIATE_TEST_SUITE_P(Bonds, SimdBondKernel, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "SharedA" : "SeparateA"; });

TEST(Bonds, BondedBlockIsDeterministicAcrossThreadsAndSurvivesReorders) {
  auto run = [](int threads, int reorder, bool stress_free) {
    WorldSettings ws;
    ws.threads = threads;
    ws.reorder_interval = reorder;
    World w = test::bonded_box(ws, stress_free);
    w.cycle(2000);
    return std::make_pair(w.positions(), w.break_events().size());
  };
  for (bool stress_free : {false, true}) {
    const auto one = run(1, 0, stress_free), two = run(2, 0, stress_free);
    EXPECT_EQ(0, std::memcmp(one.first.data(), two.first.data(), one.first.size() * sizeof(double)))
        << (stress_free ? "stress-free" : "model.md 5");
    EXPECT_EQ(one.second, two.second);
    if (stress_free) {
      EXPECT_GT(one.second, 0u) << "bonds must break: their contacts keep rest overlaps";
    }
  }
}

// Under the thesis's rotation rule (model.md 2) no particle holding a bond turns, so no beam takes
// a moment, and the beam's stiffness is a force stiffness (kbn A, BondMaterial::beam_kn) that
// does not depend on its radius: lambda enters only the periphery stresses [3-27], force / A, and
// the elliptic criterion [3-46..3-49] and the contact bond's c st A scale with st. So lambda and
// st act only as st lambda^2: lambda halved and st four times (both exact in binary) give the same
// run bit for bit, breaks of both kinds included with the energy they release, and stresses four
// times as large. (With the rotation lock off the beams take moments, I = pi Rb^4 / 4, and lambda
// is a parameter of its own.)
TEST(Bonds, UnderTheRotationLockTheBondRadiusOnlyRescalesTheStrength) {
  struct Run {
    std::vector<double> positions;
    std::vector<BreakEvent> breaks;
  };
  auto run = [](double lambda, double st, bool lock) {
    WorldSettings ws;
    ws.dt = 5e-4;
    ws.lock_bonded_rotation = lock;
    World w = test::random_box(600, ws);
    w.cycle(3000);  // settle
    BondMaterial bm;
    bm.radius_factor = lambda;
    bm.tensile_strength = st;
    bm.contact_strength = 1.5;
    w.install_bonds(bm, 2e-5, {}, false);
    w.cycle(2000);
    return Run{w.positions(), w.break_events()};
  };
  const double st = 0.03;
  const Run one = run(1.0, st, true), half = run(0.5, 4 * st, true);
  ASSERT_EQ(one.positions.size(), half.positions.size());
  EXPECT_EQ(0, std::memcmp(one.positions.data(), half.positions.data(), one.positions.size() * sizeof(double)));
  ASSERT_EQ(one.breaks.size(), half.breaks.size());
  std::size_t beams = 0, contact_bonds = 0;
  for (std::size_t k = 0; k < one.breaks.size(); ++k) {
    const BreakEvent &a = one.breaks[k], &b = half.breaks[k];
    EXPECT_EQ(a.step, b.step);
    EXPECT_EQ(a.id_a, b.id_a);
    EXPECT_EQ(a.id_b, b.id_b);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.mode, b.mode);
    EXPECT_EQ(4 * a.sigma, b.sigma);
    EXPECT_EQ(4 * a.tau, b.tau);
    EXPECT_EQ(a.released_energy, b.released_energy);  // force^2 / stiffness: no A in it
    (a.kind == BreakEvent::Kind::beam ? beams : contact_bonds) += 1;
  }
  EXPECT_GT(beams, 10u) << "the criterion must be exercised";
  EXPECT_GT(contact_bonds, 0u);
  // Where particles holding bonds turn, the same change is another material.
  const Run free_one = run(1.0, st, false), free_half = run(0.5, 4 * st, false);
  EXPECT_NE(0, std::memcmp(free_one.positions.data(), free_half.positions.data(),
                           free_one.positions.size() * sizeof(double)));
}

// A break step brings the topology up to date in what it changed only
// (refresh_bond_topology_after_breaks): after steps of breaks of every kind (bonds gone whole,
// contact bonds and beams apart, particles freed, by each lock rule) it holds what a full
// refresh builds from the bond list, the emptied slots of the partners' runs aside.
TEST(Bonds, BreakStepsLeaveTheTopologyAFullRefreshBuilds) {
  struct Topology {
    std::vector<std::int32_t> incidence_start, partners, bonded_particles, beam_count;
    std::vector<std::int64_t> incidence_entry;
    std::vector<std::uint8_t> locked, held;
    std::vector<std::size_t> dead;
    std::size_t partial_bonds;
    bool partial, moments_zero, any_rotating;
    bool operator==(const Topology&) const = default;
  };
  auto topology = [](const detail::State& s) {
    const detail::Caches& c = s.cache;
    Topology t{c.bond_incidence.start, {}, c.bonded_particles, c.beam_count, c.bond_incidence.entry,
               std::vector<std::uint8_t>(s.p.rotation_locked.begin(), s.p.rotation_locked.begin() + std::ptrdiff_t(s.p.n)),
               c.bond_held, c.dead_bonds, c.partial_bonds, c.bonds_partial, c.bond_moments_zero, s.any_rotating};
    std::sort(t.dead.begin(), t.dead.end());
    for (const std::int32_t o : c.partners)
      if (o != detail::kNoPartner) t.partners.push_back(o);
    return t;
  };
  struct Rule { int lock_bonds; bool beams; double c; };
  for (const Rule rule : {Rule{1, false, 1.0}, Rule{3, false, 0.5}, Rule{1, true, 1.0}, Rule{2, true, 0.0}}) {
    SCOPED_TRACE(testing::Message() << "rotation_lock_bonds " << rule.lock_bonds << ", beams only "
                                    << rule.beams << ", contact_strength " << rule.c);
    WorldSettings ws;
    ws.dt = 5e-4;
    ws.rotation_lock_bonds = rule.lock_bonds;
    ws.rotation_lock_beams = rule.beams;
    World w = test::random_box(600, ws);
    w.cycle(3000);
    BondMaterial bm;
    bm.tensile_strength = 0.05;
    bm.contact_strength = rule.c;
    const std::size_t installed = w.install_bonds(bm, 2e-5);
    // Shaken apart: a random velocity each, well above what the bonds hold.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t id = 0; id < w.particle_count(); ++id)
      w.set_velocity(std::int64_t(id), {2e-3 * u(rng), 2e-3 * u(rng), 2e-3 * u(rng)});
    detail::State& s = w.state();
    bool some_partial = false, some_freed = false, some_dead = false;
    // Compared after every fifth step that broke bonds (the breaks of the steps between pile up
    // in the runs of partners); only a step with breaks finds the kernel's flags again.
    for (int step = 0, breaking = 0; step < 400; ++step) {
      const std::size_t before = w.break_events().size();
      w.cycle(1);
      if (w.break_events().size() == before || ++breaking % 5 != 0) continue;
      const Topology after_breaks = topology(s);
      detail::refresh_bond_topology(s);
      ASSERT_EQ(after_breaks, topology(s)) << "after step " << w.step_count();
      some_partial = some_partial || s.cache.bonds_partial;
      some_freed = some_freed || s.any_rotating;
      some_dead = some_dead || !s.cache.dead_bonds.empty();
    }
    const std::size_t breaks = w.break_events().size();
    EXPECT_GT(breaks, installed / 4) << "most steps break bonds";
    EXPECT_LT(w.bonds().size(), installed) << "bonds went whole";
    EXPECT_EQ(some_partial, rule.c != 0.0) << "contact bonds and beams break apart, unless together";
    EXPECT_TRUE(some_freed) << "damage frees particles";
    EXPECT_TRUE(some_dead) << "bonds wait dead in the list for the next build";
  }
}

namespace {
// The box of the test above, bonds installed (contact bonds breaking apart at 0.5 st A) and shaken
// apart.
World shaken_bonded_box() {
  WorldSettings ws;
  ws.dt = 5e-4;
  World w = test::random_box(600, ws);
  w.cycle(3000);
  BondMaterial bm;
  bm.tensile_strength = 0.05;
  bm.contact_strength = 0.5;
  w.install_bonds(bm, 2e-5);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t id = 0; id < w.particle_count(); ++id)
    w.set_velocity(std::int64_t(id), {2e-3 * u(rng), 2e-3 * u(rng), 2e-3 * u(rng)});
  return w;
}

std::vector<double> motion_of(const World& w) {
  std::vector<double> m = w.positions();
  const std::vector<double> v = w.velocities();
  m.insert(m.end(), v.begin(), v.end());
  for (std::size_t id = 0; id < w.particle_count(); ++id) {
    const Vec3 spin = w.angular_velocity(std::int64_t(id));
    m.insert(m.end(), {spin.x, spin.y, spin.z});
  }
  return m;
}

bool same_bits(const std::vector<double>& x, const std::vector<double>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
}

bool same_events(const std::vector<BreakEvent>& x, const std::vector<BreakEvent>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const BreakEvent &a = x[k], &b = y[k];
    const double ax[] = {a.time, a.position.x, a.position.y, a.position.z, a.sigma, a.tau, a.released_energy};
    const double bx[] = {b.time, b.position.x, b.position.y, b.position.z, b.sigma, b.tau, b.released_energy};
    if (a.step != b.step || a.id_a != b.id_a || a.id_b != b.id_b || a.kind != b.kind || a.mode != b.mode ||
        std::memcmp(ax, bx, sizeof ax) != 0)
      return false;
  }
  return true;
}
}  // namespace

// A bond of which nothing holds stays in the list, dead, until the next neighbour build
// (BondStore::dead); its incidence entries add -0 to the gather's sums, which leaves them as they
// were. Against the same run with the dead bonds taken out after every step (the list a break
// step used to leave): the motion of every particle, every break event and the stored and
// released energies bit for bit. The friction booked by the bond kernel (contact springs whose
// contact bond broke) is summed by blocks and SIMD lanes of the bond list, whose slots the dead
// bonds shift: the same terms, grouped otherwise, so equal to rounding (measured: 4e-16 relative);
// on two threads it is the same bits.
TEST(Bonds, DeadBondsLeaveTheRunAsTakingThemOutAtOnce) {
  World kept = shaken_bonded_box(), taken = shaken_bonded_box(), two = shaken_bonded_box();
  two.set_threads(2);
  const std::size_t installed = kept.state().bonds.n;
  std::size_t most_dead = 0;
  for (int step = 0; step < 400; ++step) {
    kept.cycle(1);
    taken.cycle(1);
    two.cycle(1);
    most_dead = std::max(most_dead, kept.state().cache.dead_bonds.size());
    detail::compact_bonds(taken.state());
    ASSERT_TRUE(same_bits(motion_of(kept), motion_of(taken))) << "after step " << kept.step_count();
  }
  EXPECT_GT(most_dead, 20u) << "bonds died between builds";
  EXPECT_GT(kept.state().rebuilds, 5u) << "and builds took them out";
  EXPECT_GT(kept.break_events().size(), 500u);
  EXPECT_TRUE(same_events(kept.break_events(), taken.break_events()));
  EXPECT_EQ(kept.bond_count(), taken.bond_count());
  const Energies a = kept.energies(), b = taken.energies();
  EXPECT_EQ(a.kinetic, b.kinetic);
  EXPECT_EQ(a.strain, b.strain);
  EXPECT_EQ(a.released, b.released);
  EXPECT_EQ(a.damping, b.damping);
  EXPECT_GT(a.friction, 0.0);
  // Regrouping a step's sum of n non-negative terms moves it by at most n eps of the sum.
  const double bound = double(installed) * std::numeric_limits<double>::epsilon();
  EXPECT_NEAR(a.friction, b.friction, bound * a.friction);
  // The regrouped sums are still the run's own: the same on two threads, bit for bit.
  EXPECT_TRUE(same_bits(motion_of(kept), motion_of(two)));
  EXPECT_EQ(a.friction, two.energies().friction);
}

// A checkpoint written while dead bonds wait for the next build keeps them where they were: the
// loaded run goes on as the one that was not saved, bit for bit, its friction sums included.
TEST(Bonds, ACheckpointKeepsTheDeadBondsInTheirSlots) {
  World run = shaken_bonded_box(), saved = shaken_bonded_box();
  for (int step = 0; step < 1000 && saved.state().cache.dead_bonds.empty(); ++step) {
    saved.cycle(1);
    run.cycle(1);
  }
  ASSERT_FALSE(saved.state().cache.dead_bonds.empty());
  const std::string path = ::testing::TempDir() + "/dead_bonds.h5";
  saved.save(path);
  World loaded = World::load(path, 0, "auto");
  EXPECT_EQ(loaded.state().cache.dead_bonds.size(), saved.state().cache.dead_bonds.size());
  EXPECT_EQ(loaded.bond_count(), saved.bond_count());
  EXPECT_EQ(loaded.bonds().size(), saved.bonds().size());
  run.cycle(300);
  loaded.cycle(300);
  EXPECT_TRUE(same_bits(motion_of(run), motion_of(loaded)));
  EXPECT_TRUE(same_events(run.break_events(), loaded.break_events()));
  EXPECT_EQ(run.energies().friction, loaded.energies().friction);
  EXPECT_EQ(run.energies().strain, loaded.energies().strain);
}

// Where no end of a bond turns the bond records hold the forces only (kernels::BondRecord::forces)
// and the gather leaves the torque of the bonds' shear forces out; World::torque and
// World::group_torque add it when asked. Checked against the torque rebuilt from what
// world.contacts() and world.bonds() report, -(R - U/2) n x Fs per contact and bond, on every
// particle away from the walls of a bonded box; the gathered column alone misses it.
TEST(Bonds, TheTorqueOfAParticleThatDoesNotTurnHoldsItsBondsShear) {
  WorldSettings ws;
  World w = test::bonded_box(ws, false);
  w.cycle(300);
  const detail::State& s = w.state();
  ASSERT_EQ(s.cache.bond_records, kernels::BondRecord::forces) << "every bonded particle is locked";
  std::vector<Vec3> rebuilt(w.particle_count(), Vec3{0, 0, 0});
  std::vector<double> scale(w.particle_count(), 0.0);
  auto add = [&](std::int64_t id, const Vec3& n, double U, const Vec3& fs) {
    const Vec3 t = cross(n, fs) * -(w.radius(id) - 0.5 * U);
    rebuilt[std::size_t(id)] += t;
    scale[std::size_t(id)] += norm(t);
  };
  for (const ContactInfo& c : w.contacts()) {
    add(c.id_a, c.normal, c.overlap, c.shear_force);
    add(c.id_b, c.normal, c.overlap, c.shear_force);
  }
  std::vector<int> bonded(w.particle_count(), 0);
  for (const BondInfo& b : w.bonds()) {
    ASSERT_EQ(b.twisting_moment, 0.0);
    add(b.id_a, b.normal, -b.gap, b.shear_force);
    add(b.id_b, b.normal, -b.gap, b.shear_force);
    ++bonded[std::size_t(b.id_a)], ++bonded[std::size_t(b.id_b)];
  }
  const double L = 12e-3;  // test::random_box's walls: x, y in [0, L], z above 0
  std::size_t checked = 0, missed = 0;
  for (std::size_t id = 0; id < w.particle_count(); ++id) {
    const Vec3 x = w.position(std::int64_t(id));
    const double r = w.radius(std::int64_t(id));
    if (!bonded[id] || x.x < r || x.y < r || x.z < r || x.x > L - r || x.y > L - r) continue;
    const Vec3 t = w.torque(std::int64_t(id));
    ASSERT_LE(norm(t - rebuilt[id]), 1e-12 * scale[id]) << "particle " << id;
    const std::size_t i = std::size_t(s.p.index_of_id[id]);
    missed += norm(Vec3{s.p.tx[i], s.p.ty[i], s.p.tz[i]} - rebuilt[id]) > 1e-3 * scale[id];
    ++checked;
  }
  EXPECT_GT(checked, 200u);  // 284 of the 600
  EXPECT_GT(missed, checked / 2) << "the gathered column alone leaves the bonds' terms out";
  // A checkpoint keeps the layout, so the loaded world answers the same.
  const std::string path = ::testing::TempDir() + "/torque_left_out.h5";
  w.save(path);
  const World loaded = World::load(path, 1, "auto");
  for (std::size_t id = 0; id < w.particle_count(); id += 7) {
    const Vec3 a = w.torque(std::int64_t(id)), b = loaded.torque(std::int64_t(id));
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << "particle " << id;
  }
  // A rigid group of fixed rotation does not turn either; its torque about its centre holds its
  // members' bonds' terms too: sum (t_i + r_i x f_i) over its members, rebuilt as above.
  std::vector<std::int64_t> members;
  for (std::size_t id = 0; id < w.particle_count() && members.size() < 40; ++id) {
    const Vec3 x = w.position(std::int64_t(id));
    const double r = w.radius(std::int64_t(id));
    if (bonded[id] && x.z > 2e-3 && x.x > r && x.y > r && x.x < L - r && x.y < L - r) members.push_back(std::int64_t(id));
  }
  ASSERT_GE(members.size(), 20u);
  GroupMotion held;
  held.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  held.rotation = Dof::fixed;
  const int g = w.add_group(members, held);
  w.cycle(20);
  ASSERT_EQ(s.cache.bond_records, kernels::BondRecord::forces);
  Vec3 expected{0, 0, 0};
  double total = 0;
  const std::vector<BondInfo> bonds = w.bonds();
  const std::vector<ContactInfo> contacts = w.contacts();
  // Bonds and contacts between members are left out: the step leaves them out (frozen bonds,
  // State::frozen_bonds), their forces cancelling within the body.
  auto member = [&](std::int64_t id) { return std::find(members.begin(), members.end(), id) != members.end(); };
  for (const std::int64_t id : members) {
    Vec3 t{0, 0, 0};
    for (const ContactInfo& c : contacts)
      if ((c.id_a == id || c.id_b == id) && !(member(c.id_a) && member(c.id_b)))
        t += cross(c.normal, c.shear_force) * -(w.radius(id) - 0.5 * c.overlap);
    for (const BondInfo& b : bonds)
      if ((b.id_a == id || b.id_b == id) && !(member(b.id_a) && member(b.id_b)))
        t += cross(b.normal, b.shear_force) * -(w.radius(id) + 0.5 * b.gap);
    expected += t + cross(w.position(id) - w.group_position(g), w.force(id));
    total += norm(t) + norm(cross(w.position(id) - w.group_position(g), w.force(id)));
  }
  EXPECT_LE(norm(w.group_torque(g) - expected), 1e-12 * total);
  EXPECT_GT(norm(s.groups[std::size_t(g)].torque - expected), 1e-6 * total) << "the gathered sum alone misses them";
  // A particle that turns (here: bonded rotation unlocked) needs the levers in the records.
  ws.lock_bonded_rotation = false;
  World turning = test::bonded_box(ws, false);
  turning.cycle(10);
  EXPECT_NE(turning.state().cache.bond_records, kernels::BondRecord::forces);
}

// A bond material is checked field by field against its table (materials.hpp) before anything
// is installed, and the refusal names the field and its range; one material per world.
TEST(Bonds, ABadBondMaterialIsRefusedByNameAndNothingIsInstalled) {
  World w;
  w.add_particle({0, 0, 0}, kR);
  w.add_particle({0, 0, 2 * kR}, kR);
  auto error_of = [&](const BondMaterial& m) { return test::error_of([&] { w.install_bonds(m); }); };
  BondMaterial bad;
  bad.beam_kn = -1;
  bad.tensile_strength = 1;
  EXPECT_EQ(error_of(bad), "install_bonds: bond material: beam_kn -1 must be 0 (the world's contact kn) or in (0, inf) N/m");
  bad = BondMaterial{};
  bad.radius_factor = 0;
  bad.breakable = false;
  EXPECT_EQ(error_of(bad), "install_bonds: bond material: radius_factor 0 outside (0, inf)");
  bad = BondMaterial{};
  EXPECT_EQ(error_of(bad), "install_bonds: a breakable bond needs tensile_strength > 0 (Pa), got 0: give it, or "
                           "breakable = false for unbreakable bonds");
  EXPECT_EQ(w.bond_count(), 0u);
  BondMaterial good;
  good.breakable = false;
  EXPECT_EQ(w.install_bonds(good), 1u);
  BondMaterial other = good;
  other.beam_ks = 0.05;
  EXPECT_NE(error_of(other).find("one bond material per world"), std::string::npos);
  // The beam's stiffness left at 0 is the contact springs' (model.md 5): kbn A = kn, kbs = kbn / 10,
  // whether given so or left to the default, so the two are one material.
  BondMaterial explicit_stiffness = good;
  explicit_stiffness.beam_kn = w.settings().contact.kn;
  explicit_stiffness.beam_ks = w.settings().contact.kn / 10;
  EXPECT_EQ(error_of(explicit_stiffness), "(no error)");
  WorldSettings stiff;
  stiff.contact.kn = 3.0;
  World v(stiff);
  v.add_particle({0, 0, 0}, kR);
  v.add_particle({0, 0, 2 * kR}, kR);
  ASSERT_EQ(v.install_bonds(good), 1u);
  EXPECT_EQ(v.state().bonds.material.beam_kn, 3.0);
  EXPECT_EQ(v.state().bonds.material.beam_ks, 0.3);
}

// The servo's stiffness counts the pairs and bonds joining two bodies (stages/groups.cpp); a break
// step keeps both counts current (the freed pairs merged into the list of pairs joining bodies,
// the dead bonds' ends counted out) instead of taking them again from every pair and bond. A
// bonded block sheared between two platens, its top one under the servo, against the same run
// with the counts taken afresh at every step: the platens' stiffness and every particle's motion
// bit for bit, with bonds joining the platens to the block broken on the way.
namespace {
// A bonded block sheared between two platens (test::sheared_layers), its top one under the servo:
// contact bonds breaking apart at 0.5 st A, bonds to the platens among them; the bonds inside each
// platen frozen (the platens do not turn).
World bonded_sheared_block(int& top) {
  WorldSettings ws;
  ws.dt = 5e-4;
  auto bond = [](World& w, std::int64_t) {
    BondMaterial bm;
    bm.tensile_strength = 0.05;
    bm.contact_strength = 0.5;
    w.install_bonds(bm);
  };
  test::ShearedLayers box = test::sheared_layers(ws, 10, 6, 1e-3, 2e-3, 1e-6, bond);
  top = box.top;
  return std::move(box.w);
}
}  // namespace

TEST(Bonds, TheServoCountsAfterBreaksAreTheOnesTakenAfresh) {
  int top = -1, top_afresh = -1;
  World w = bonded_sheared_block(top), afresh = bonded_sheared_block(top_afresh);
  std::size_t kept_steps = 0;
  const std::uint32_t ends_before = [&] {
    w.cycle(1);
    afresh.cycle(1);
    return w.state().cache.servo.bond_ends[std::size_t(top)];
  }();
  for (int step = 0; step < 600; ++step) {
    const std::size_t breaks = w.break_events().size();
    const std::uint64_t rebuilds = w.state().rebuilds;
    w.cycle(1);
    afresh.cycle(1);
    // A break step that was no build kept the servo's pair list current.
    kept_steps += w.break_events().size() > breaks && w.state().rebuilds == rebuilds &&
                  w.state().cache.servo.pairs_at == w.state().rebuilds;
    afresh.state().cache.servo.pairs_at = ~std::uint64_t(0);
    afresh.state().cache.servo.bonds_of = ~std::uint64_t(0);
    ASSERT_EQ(w.state().groups[std::size_t(top)].contact_stiffness,
              afresh.state().groups[std::size_t(top_afresh)].contact_stiffness) << "step " << w.step_count();
    ASSERT_TRUE(same_bits(motion_of(w), motion_of(afresh))) << "step " << w.step_count();
  }
  EXPECT_GT(kept_steps, 10u);
  EXPECT_LT(w.state().cache.servo.bond_ends[std::size_t(top)], ends_before) << "bonds to the platen broke";
}

// A world whose bonds all broke holds none, even while they wait dead for the next build: it takes
// bonds of another material, as one whose list was emptied would.
TEST(Bonds, AWorldWhoseBondsAllBrokeTakesBondsOfAnotherMaterial) {
  BondMaterial bm;
  bm.tensile_strength = 2.0;
  bm.contact_strength = 0;  // the contact bond breaks with the beam
  Pair p = bonded_pair(bm, moving({0, 0, 1e-6}));
  while (p.w.break_events().empty() && p.w.step_count() < 1000000) p.w.cycle(1);
  ASSERT_EQ(p.w.bond_count(), 0u);
  ASSERT_EQ(p.w.state().cache.dead_bonds.size(), 1u) << "the bond waits dead in the list";
  BondMaterial other;
  other.tensile_strength = 5.0;
  EXPECT_EQ(test::error_of([&] { p.w.install_bonds(other, 1.0); }), "(no error)");
  EXPECT_EQ(p.w.bonds().size(), 1u) << "the pair, within the tolerance, bonded again";
  EXPECT_TRUE(p.w.state().cache.dead_bonds.empty());
}

// A break step's freed pairs make the idle split of the platens stale; the next split need not
// look for bonds to freeze or thaw (Caches::idle_pairs_only): against the same run with a full
// split after every break step, every motion bit for bit and the frozen bonds the same.
TEST(Bonds, ASplitAfterABreakStepAloneLeavesTheFrozenBondsAsTheyAre) {
  int top = -1, top_full = -1;
  World w = bonded_sheared_block(top), full = bonded_sheared_block(top_full);
  std::size_t pairs_only = 0;
  for (int step = 0; step < 600; ++step) {
    w.cycle(1);
    full.cycle(1);
    pairs_only += w.state().cache.idle_pairs_only;
    full.state().cache.idle_pairs_only = false;
    ASSERT_TRUE(same_bits(motion_of(w), motion_of(full))) << "step " << w.step_count();
  }
  EXPECT_GT(pairs_only, 10u);
  EXPECT_GT(w.state().frozen_bonds.n, 0u);
  EXPECT_EQ(w.state().frozen_bonds.n, full.state().frozen_bonds.n);
  EXPECT_EQ(w.bond_count(), full.bond_count());
}
