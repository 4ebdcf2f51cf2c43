// Critical time step (model.md 3) and the health checks around it.
//
// The estimate sqrt(m / k_tran) with k_tran summed over a body's contacts is conservative: for a
// chain, whose highest mode has omega = 2 sqrt(kn/m), leapfrog is stable up to dt = sqrt(m/kn),
// which is sqrt(2) times the estimate sqrt(m / 2kn) of an interior particle (by Gershgorin's
// theorem no contact network can be tighter than that factor). So a chain at 1.2x the estimate
// does not blow up by itself: the engine refuses the step because dt is above the estimate. Beyond
// sqrt(2)x, with the refusal switched off, the chain does blow up, and the runaway check sees it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "asperity/world.hpp"
#include "report.hpp"

using namespace asperity;
using asperity::test::report;

namespace {
World chain(int n, bool allow) {
  WorldSettings ws;
  ws.local_damping = 0;
  ws.rotation = false;
  ws.contact.friction = 0;
  ws.allow_dt_above_estimate = allow;
  World w(ws);
  // Spheres 0.02 mm into each other and into two end planes: every contact stays closed for the
  // small velocities given, so the chain is a fixed-fixed mass-spring chain.
  const double R = 5e-4, a = 0.98e-3;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i) {
    const auto id = w.add_particle({i * a, 0, 0}, R);
    w.set_velocity(id, {1e-4 * u(rng), 0, 0});
  }
  ContactMaterial frictionless;
  frictionless.friction = 0;
  w.add_plane({-a / 2, 0, 0}, {1, 0, 0}, frictionless);
  w.add_plane({(n - 0.5) * a, 0, 0}, {-1, 0, 0}, frictionless);
  return w;
}
}  // namespace

TEST(TimeStep, EstimateIsSqrtMassOverContactStiffness) {
  World w = chain(10, false);
  const double m = w.mass(0);
  // Interior particles have two contacts: sqrt(m / (2 kn)).
  EXPECT_NEAR(w.critical_dt(), std::sqrt(m / (2 * 0.1)), 1e-15);
  w.cycle(1);
  EXPECT_NEAR(w.dt(), 0.8 * std::sqrt(m / (2 * 0.1)), 1e-15) << "automatic dt = 0.8 x estimate";
}

TEST(TimeStep, HeavierParticleRaisesTheEstimateBySqrtOfItsMass) {
  // A light sphere between two heavy ones (each with one contact and a plane) sets the estimate;
  // four times its density doubles its sqrt(m / k) [3-30], up to the next body's.
  WorldSettings ws;
  ws.contact.friction = 0;
  World w(ws);
  const auto heavy_a = w.add_particle({0, 0, 0}, 1e-3);
  const auto light = w.add_particle({1.398e-3, 0, 0}, 0.4e-3);
  const auto heavy_b = w.add_particle({2.796e-3, 0, 0}, 1e-3);
  const double m = w.mass(light), k = 0.1;
  EXPECT_NEAR(w.critical_dt(), std::sqrt(m / (2 * k)), 1e-15) << "two contacts of the light one";
  w.set_density(light, 4 * w.density(light));
  EXPECT_DOUBLE_EQ(w.mass(light), 4 * m);
  EXPECT_NEAR(w.critical_dt(), 2 * std::sqrt(m / (2 * k)), 1e-15);
  // Its group's mass follows.
  const std::vector<std::int64_t> pair{heavy_a, heavy_b};
  const int g = w.add_group(pair);
  const double before = w.group_mass(g);
  w.set_density(heavy_b, 2 * w.density(heavy_b));
  EXPECT_DOUBLE_EQ(w.group_mass(g), before + w.mass(heavy_a));
  EXPECT_THROW(w.set_density(light, 0.0), Error);
  EXPECT_THROW(w.set_density(light, std::nan("")), Error);
}

TEST(TimeStep, ChainRunsStablyAtNinetyFivePercent) {
  World w = chain(20, false);
  const double est = w.critical_dt();
  w.set_dt(0.95 * est);
  w.cycle(1);
  const Energies e0 = w.energies();
  EXPECT_NO_THROW(w.cycle(50000));
  const Energies e = w.energies();
  report("chain at 0.95 x estimate, (Ek+Es) after 5e4 steps / start", (e.kinetic + e.strain) / (e0.kinetic + e0.strain), 1.0);
  EXPECT_NEAR((e.kinetic + e.strain) / (e0.kinetic + e0.strain), 1.0, 0.05);
}

TEST(TimeStep, AboveTheEstimateIsRefused) {
  World w = chain(20, false);
  const double est = w.critical_dt();
  w.set_dt(1.2 * est);
  try {
    w.cycle(10);
    FAIL() << "dt at 1.2x the estimate must be refused";
  } catch (const HealthError& e) {
    EXPECT_EQ(e.quantity, "dt");
    EXPECT_NEAR(e.value, 1.2 * est, 1e-18);
    EXPECT_NE(std::string(e.what()).find("critical estimate"), std::string::npos);
  }
}

TEST(TimeStep, BeyondTheTrueLimitTheBlowUpIsDetected) {
  World w = chain(20, true);
  const double est = w.critical_dt();
  // Stable just below the true limit sqrt(2) x estimate ...
  w.set_dt(1.3 * est);
  EXPECT_NO_THROW(w.cycle(20000));
  // ... and detected within a few hundred steps beyond it.
  World v = chain(20, true);
  v.set_dt(1.6 * est);
  std::uint64_t detected_at = 0;
  try {
    v.cycle(20000);
  } catch (const HealthError& e) {
    detected_at = e.step;
    EXPECT_GE(e.particle_id >= 0 || e.quantity == "kinetic + strain energy", true);
  }
  report("chain at 1.6 x estimate (fixed dt allowed): step at which the blow-up is detected", detected_at, 0);
  EXPECT_GT(detected_at, 0u) << "the runaway must be detected";
  EXPECT_LT(detected_at, 2000u);
}

TEST(TimeStep, DampingRatioOfOneDegreeOfFreedom) {
  // A sphere pressed into a plane by a constant force oscillates about U0 = F/kn. Local damping
  // reduces the force by alpha while accelerating and raises it while decelerating, so successive
  // extrema (on opposite sides) shrink by sqrt((1 - alpha) / (1 + alpha)) [3-28].
  for (double alpha : {0.1, 0.3, 0.7}) {
    WorldSettings ws;
    ws.local_damping = alpha;
    ws.rotation = false;
    World w(ws);
    const double R = 5e-4, F = 1e-5, U0 = F / 0.1;
    w.add_plane({0, 0, 0}, {0, 0, 1});
    const auto id = w.add_particle({0, 0, R - 1.5 * U0}, R);  // amplitude 0.5 U0
    w.set_applied_force(id, {0, 0, -F});
    const double T = 2 * std::acos(-1.0) * std::sqrt(w.mass(id) / 0.1);
    w.set_dt(T / 4000);
    std::vector<double> extrema;
    double prev = w.position(id).z - (R - U0), prev2 = prev;
    for (int k = 0; k < 4000 * 4 && extrema.size() < 4; ++k) {
      w.cycle(1);
      const double x = w.position(id).z - (R - U0);
      if ((prev > prev2 && prev >= x) || (prev < prev2 && prev <= x)) extrema.push_back(prev);
      prev2 = prev;
      prev = x;
    }
    ASSERT_GE(extrema.size(), 3u);
    const double expected = std::sqrt((1 - alpha) / (1 + alpha));
    char what[96];
    std::snprintf(what, sizeof what, "alpha %.1f: first extremum ratio vs sqrt((1-a)/(1+a))", alpha);
    report(what, std::fabs(extrema[1] / extrema[0]), expected);
    for (std::size_t k = 1; k < extrema.size(); ++k)
      EXPECT_NEAR(std::fabs(extrema[k] / extrema[k - 1]), expected, 2e-3)
          << "alpha " << alpha << " extremum " << k;
  }
}

// An overlap deeper than the smaller radius: the linear contact law is used outside any sense.
// Two rigid bodies driven into each other (no dynamics, so no other check fires first) are
// reported once the overlap passes the radius, and not before.
TEST(Health, AnOverlapDeeperThanTheRadiusIsReported) {
  const double R = 1e-3;
  WorldSettings ws;
  ws.rotation = false;
  ws.dt = 1e-5;
  ws.contact.kn = 1e3;
  ws.contact.ks = 1e2;
  World w(ws);
  const auto a = w.add_particle({0, 0, 0}, R);
  const auto b = w.add_particle({2 * R, 0, 0}, R);  // touching
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  const std::vector<std::int64_t> ga{a}, gb{b};
  w.add_group(ga, fixed);
  GroupMotion push = fixed;
  push.translation = {Dof::velocity, Dof::fixed, Dof::fixed};
  push.velocity = {-1e-2, 0, 0};  // 1e-7 m = 1e-4 R per step
  w.add_group(gb, push);
  EXPECT_NO_THROW(w.cycle(9500)) << "overlap 0.95 R: still accepted";
  try {
    w.cycle(2000);
    FAIL() << "an overlap beyond the radius must be reported";
  } catch (const HealthError& e) {
    EXPECT_EQ(e.quantity, "overlap / R");
    EXPECT_GT(e.value, 1.0);
    EXPECT_LT(e.value, 1.02) << "found within one check interval (100 steps = 0.01 R)";
    EXPECT_NE(std::string(e.what()).find("too soft"), std::string::npos);
  }
}

// The measure behind that check, which scripts read to warn well before it fires: overlap over
// the radius of the smaller body, for a pair, a wall contact and a bond, each the deepest in turn.
// Overlaps are outputs of a step (as contact_count): each is read after one step so short that
// nothing moves measurably.
TEST(Health, MaxOverlapRatioIsTheDeepestOverlapOverTheSmallerRadius) {
  WorldSettings ws;
  ws.rotation = false;
  ws.dt = 1e-12;
  World w(ws);
  EXPECT_EQ(w.max_overlap_ratio(), 0.0) << "an empty world";
  // Pair: radii 1 and 0.5 mm, centres 1.4 mm apart: U = 0.1 mm, over the smaller radius 0.2.
  w.add_particle({0, 0, 0}, 1e-3);
  w.add_particle({1.4e-3, 0, 0}, 0.5e-3);
  w.cycle(1);
  EXPECT_NEAR(w.max_overlap_ratio(), 0.2, 1e-9);
  // A wall contact 0.3 of its particle's radius deep is deeper.
  w.add_plane({0, 0, -5e-3}, {0, 0, 1});
  w.add_particle({0, 5e-3, -4.3e-3}, 1e-3);
  w.cycle(1);
  EXPECT_NEAR(w.max_overlap_ratio(), 0.3, 1e-9);
  // A bonded pair pressed 0.45 of the smaller radius: bonds count as contacts.
  const auto c = w.add_particle({0, 10e-3, 2e-3}, 1e-3);
  const auto d = w.add_particle({0, 10e-3 + 1.55e-3, 2e-3}, 1e-3);
  const std::vector<std::int64_t> cd{c, d};
  BondMaterial bm;
  bm.breakable = false;
  EXPECT_EQ(w.install_bonds(bm, -1, cd), 1u);
  w.cycle(1);
  EXPECT_NEAR(w.max_overlap_ratio(), 0.45, 1e-9);
}

// turning_only keeps the contacts with a particle free to turn: the deepest overlap of the joint's
// bonded halves (rotation-locked by their bonds) and rigid platens (groups of fixed rotation)
// does not count, a free particle's contact does, whichever side it is on.
TEST(Health, MaxOverlapRatioTurningOnlyCountsContactsWithAParticleFreeToTurn) {
  WorldSettings ws;
  ws.dt = 1e-12;
  World w(ws);
  // Free pair: radii 1 and 0.5 mm, U = 0.1 mm, 0.2 of the smaller radius.
  const auto a = w.add_particle({0, 0, 0}, 1e-3);
  const auto b = w.add_particle({1.4e-3, 0, 0}, 0.5e-3);
  // Bonded pair (locked by its bond, lock_bonded_rotation), pressed 0.45 of the smaller radius.
  const auto c = w.add_particle({0, 10e-3, 0}, 1e-3);
  const auto d = w.add_particle({0, 10e-3 + 1.55e-3, 0}, 1e-3);
  const std::vector<std::int64_t> cd{c, d};
  BondMaterial bm;
  bm.breakable = false;
  EXPECT_EQ(w.install_bonds(bm, -1, cd), 1u);
  // A rigid group of fixed rotation (the default motion) whose members overlap 0.35.
  const auto e = w.add_particle({0, 20e-3, 0}, 1e-3);
  const auto f = w.add_particle({0, 20e-3 + 1.65e-3, 0}, 1e-3);
  const std::vector<std::int64_t> ef{e, f};
  w.add_group(ef);
  w.cycle(1);
  EXPECT_NEAR(w.max_overlap_ratio(), 0.45, 1e-9) << "every contact";
  EXPECT_NEAR(w.max_overlap_ratio(true), 0.2, 1e-9) << "the free pair only";
  // One side of the free pair locked: the other still turns.
  w.set_rotation_locked(a, true);
  EXPECT_NEAR(w.max_overlap_ratio(true), 0.2, 1e-9);
  w.set_rotation_locked(b, true);
  EXPECT_EQ(w.max_overlap_ratio(true), 0.0) << "nothing turns";
  EXPECT_NEAR(w.max_overlap_ratio(), 0.45, 1e-9);
  // A free particle pressed on a group member: the contact counts.
  w.add_particle({1.7e-3, 20e-3, 0}, 1e-3);
  w.cycle(1);
  EXPECT_NEAR(w.max_overlap_ratio(true), 0.3, 1e-9);
}

// Dimensional consistency of the whole step. In the linear model, multiplying every stiffness
// (contacts, walls, beams) by 4, gravity and bond strength by 4 (accelerations, stresses), and
// the prescribed velocities by 2 while halving dt is the same motion at twice the speed: forces
// x4, velocities x2, the same positions step by step. Every factor is a power of two, so the
// correspondence is exact in floating point too (sqrt(4x) = 2 sqrt(x), and so on): the positions
// must agree bit for bit. A term of the law, damping, integration, break criterion or wall
// motion that missed a dt, a stiffness or a velocity would break it. This is why the run-time
// study (perf/runtime_vs_error.lua) treats stiff or soft contacts as its velocity axis.
TEST(Scaling, StiffnessTimesFourIsTheSameMotionAtTwiceTheSpeed) {
  auto build = [](double f) {
    WorldSettings ws;
    ws.contact.kn = 0.1 * f;
    ws.contact.ks = 0.03 * f;
    ws.contact.friction = 0.4;
    ws.lock_bonded_rotation = false;  // bonded spin and beam moments take part too
    ws.gravity = {0, 0, -9.81 * f};
    World w(ws);
    ContactMaterial wall;
    wall.kn = 0.2 * f;
    wall.ks = 0.05 * f;
    wall.friction = 0.3;
    // 4 x 4 x 4 spheres of radius 0.9-1.1 mm on a jittered lattice, slightly overlapping, between
    // a floor and a lid that comes down.
    const double R = 1e-3, a = 1.98e-3;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k)
          w.add_particle({i * a + 0.02 * R * u(rng), j * a + 0.02 * R * u(rng), R + k * a + 0.02 * R * u(rng)},
                         R * (1 + 0.1 * u(rng)));
    w.add_plane({0, 0, 0}, {0, 0, 1}, wall);
    const int lid = w.add_plane({0, 0, 4 * a}, {0, 0, -1}, wall);
    w.set_wall_velocity(lid, {0, 0, -0.05 * std::sqrt(f)});
    BondMaterial bm;
    bm.beam_kn = 0.1 * f;
    bm.beam_ks = 0.02 * f;
    bm.tensile_strength = 2.0 * f;  // Pa: low enough that some bonds break under the lid
    w.install_bonds(bm);
    w.set_dt(2e-5 / std::sqrt(f));
    return w;
  };
  World slow = build(1), fast = build(4);
  std::size_t breaks = 0;
  for (int chunk = 0; chunk < 30; ++chunk) {
    slow.cycle(100);
    fast.cycle(100);
    for (std::int64_t id = 0; id < std::int64_t(slow.particle_count()); ++id) {
      const Vec3 xs = slow.position(id), xf = fast.position(id);
      ASSERT_TRUE(xs.x == xf.x && xs.y == xf.y && xs.z == xf.z)
          << "particle " << id << " after " << slow.step_count() << " steps";
      const Vec3 vs = slow.velocity(id), vf = fast.velocity(id);
      ASSERT_TRUE(2 * vs.x == vf.x && 2 * vs.y == vf.y && 2 * vs.z == vf.z) << "velocity x2, particle " << id;
      const Vec3 fs = slow.force(id), ff = fast.force(id);
      ASSERT_TRUE(4 * fs.x == ff.x && 4 * fs.y == ff.y && 4 * fs.z == ff.z) << "force x4, particle " << id;
    }
    breaks = slow.break_events().size();
    ASSERT_EQ(fast.break_events().size(), breaks);
  }
  EXPECT_GT(slow.contact_count() + slow.bond_count(), 50u) << "a loaded packing, not free flight";
  const Energies es = slow.energies(), ef = fast.energies();
  EXPECT_EQ(4 * es.kinetic, ef.kinetic);
  EXPECT_EQ(4 * es.strain, ef.strain);
  EXPECT_EQ(4 * es.friction, ef.friction);
  EXPECT_EQ(4 * es.damping, ef.damping);
  std::printf("scaling: %zu bonds broken, %zu bonds and %zu contacts left, friction %.3g J\n", breaks,
              slow.bond_count(), slow.contact_count(), es.friction);
}
