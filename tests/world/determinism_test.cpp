// Results do not depend on the thread count, nor on the SIMD architecture, and a seed gives one
// run (the kernels' bitwise equivalence to the scalar reference: kernels/simd_equivalence_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <numeric>
#include <random>
#include <tuple>
#include <type_traits>
#include <string>

#include "core/aligned.hpp"
#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"
#include "kernels/pair_loop.hpp"
#include "scenes.hpp"
#include "neighbor/build.hpp"
#include "state.hpp"

using namespace asperity;


TEST(Determinism, FullStateBitwiseIdenticalWithOneAndTwoThreads) {
  WorldSettings one, two;
  one.threads = 1;
  two.threads = 2;
  World a = test::random_box(3000, one), b = test::random_box(3000, two);
  a.cycle(1500);
  b.cycle(1500);
  ASSERT_GT(a.contact_count(), 500u) << "the scene must be busy";
  EXPECT_TRUE(test::same_bits(a.positions(), b.positions()));
  EXPECT_TRUE(test::same_bits(a.velocities(), b.velocities()));
  EXPECT_TRUE(test::same_bits(a.forces(), b.forces()));
  const Energies ea = a.energies(), eb = b.energies();
  EXPECT_EQ(ea.friction, eb.friction);
  EXPECT_EQ(ea.damping, eb.damping);
  EXPECT_EQ(ea.strain, eb.strain);
}

// Spheres falling into a still, bumpy mesh (a mould) lift it lists within R + skin/2 only
// (Wall::candidates_within_half_skin): the same bits on one thread and on two.
TEST(Determinism, SpheresOnAStillMouldAreTheSameOnOneAndTwoThreads) {
  auto run = [](int threads) {
    WorldSettings ws;
    ws.threads = threads;
    World w = test::random_box(1200, ws, 3, 1.5e-3);
    const int mould = test::add_bumpy_mould(w, 48);
    w.cycle(3000);
    EXPECT_TRUE(w.state().walls.walls[mould].candidates_within_half_skin);
    EXPECT_LT(w.wall_force(mould).z, 0) << "the spheres press on the mould";
    return w;
  };
  World a = run(1), b = run(2);
  EXPECT_TRUE(test::same_bits(a.positions(), b.positions()));
  EXPECT_TRUE(test::same_bits(a.velocities(), b.velocities()));
  EXPECT_TRUE(test::same_bits(a.forces(), b.forces()));
  EXPECT_EQ(a.energies().friction, b.energies().friction);
  const int mould = 6;  // after the box's six planes
  EXPECT_EQ(a.wall_force(mould).z, b.wall_force(mould).z);
}

// Rigid groups run in the step's parallel region once enough members move (engine/step.cpp,
// kParallelMoves): their motion one group per block, their members' moves by particle block. Two
// platens of 576 spheres (every member touches the layer next to it, so all of them move), the
// lower one held, the upper one sheared at a set velocity under a normal-force servo, squeeze four
// layers of free spheres. On one thread and on two, everything is the same bit for bit: the
// particles, the platens' forces and positions, and the ledgers the group stages add to.
TEST(Determinism, PlatensMovedInTheParallelRegionAreTheSameOnOneAndTwoThreads) {
  constexpr int n = 24, layers = 6;
  auto make = [&](int threads, int& top) {
    WorldSettings ws;
    ws.threads = threads;
    // The layers between the platens jiggled.
    auto jiggle_inside = [](World& w, std::int64_t first) {
      std::mt19937_64 rng(77);
      std::normal_distribution<double> jiggle(0, 1e-6);
      for (std::int64_t k = n * n; k < std::int64_t(n * n * (layers - 1)); ++k)
        w.set_velocity(first + k, {jiggle(rng), jiggle(rng), jiggle(rng)});
    };
    test::ShearedLayers box = test::sheared_layers(ws, n, layers, 1e-3, 2e-4, 1e-3, jiggle_inside);
    top = box.top;
    return std::move(box.w);
  };
  int top1 = -1, top2 = -1;
  World one = make(1, top1), two = make(2, top2);
  const Vec3 start = one.group_position(top1);
  one.cycle(400);
  two.cycle(400);
  // Not vacuous: the platens' members are more than kParallelMoves, the upper one moved and is
  // loaded.
  ASSERT_GE(2u * n * n, 512u);
  ASSERT_GT(one.group_position(top1).x - start.x, 0.0);
  ASSERT_GT(one.group_force(top1).z, 0.0);
  EXPECT_TRUE(test::same_bits(one.positions(), two.positions()));
  EXPECT_TRUE(test::same_bits(one.velocities(), two.velocities()));
  EXPECT_TRUE(test::same_bits(one.forces(), two.forces()));
  for (int g : {0, top1}) {
    EXPECT_EQ(one.group_force(g).x, two.group_force(g).x) << g;
    EXPECT_EQ(one.group_force(g).z, two.group_force(g).z) << g;
    EXPECT_EQ(one.group_position(g).z, two.group_position(g).z) << g;
  }
  const Energies e1 = one.energies(), e2 = two.energies();
  EXPECT_EQ(e1.kinetic, e2.kinetic);
  EXPECT_EQ(e1.boundary_work, e2.boundary_work);
  EXPECT_EQ(e1.damping, e2.damping);
  EXPECT_EQ(e1.gravity_work, e2.gravity_work);
  EXPECT_EQ(e1.friction, e2.friction);
  EXPECT_GT(e1.boundary_work, 0.0);
}

// The automatic thread count follows the force work (state.hpp, thread_count): the default
// joint's elastic specimen (4 031 pairs, 9 098 bonds) takes a second thread, its rigid twin
// (161 pairs) and small scenes do not; a set count always wins.
TEST(Determinism, AutomaticThreadCountFollowsTheWork) {
  detail::State s;
  s.ctx.max_threads = 8;
  s.p.n = 3972;
  s.pairs.n = 161;
  EXPECT_EQ(detail::thread_count(s), 1);
  s.pairs.n = 4031;
  s.bonds.n = 9098;
  EXPECT_EQ(detail::thread_count(s), 3);
  s.ctx.max_threads = 2;
  EXPECT_EQ(detail::thread_count(s), 2);
  s.ctx.max_threads = 8;
  s.pairs.n = 30496;  // lattice n = 22
  s.bonds.n = 0;
  EXPECT_EQ(detail::thread_count(s), 4);
  s.pairs.n = 0;  // before the first pair list: by particles
  s.p.n = 64000;
  EXPECT_EQ(detail::thread_count(s), 4);
  s.settings.threads = 1;
  EXPECT_EQ(detail::thread_count(s), 1);
}

TEST(Determinism, SameSeedSameRun) {
  World a = test::random_box(500), b = test::random_box(500);
  a.cycle(1000);
  b.cycle(1000);
  const auto pa = a.positions(), pb = b.positions();
  EXPECT_EQ(0, std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(double)));
}

// The same on a whole run: a bonded box (its listed pairs mostly near misses, and contacts left
// by breaking stress-free bonds, with rest overlaps) stepped once with the live flags written and
// the dead records skipped at every step, once with them only at the probing steps (every 64th,
// stages/pairs.cpp), gives the same positions bit for bit and the same breaks; left to itself
// the engine finds the box sparse and skips.
TEST(Determinism, SkippingDeadPairRecordsLeavesARunBitwiseTheSame) {
  struct Result {
    std::vector<double> positions;
    std::size_t breaks = 0, flagged_steps = 0, live = 0, pairs = 0;
  };
  auto run = [](int mode) {  // 0: automatic, 1: flags every step, 2: only when probing
    World w = test::bonded_box({}, true);
    Result r;
    for (int k = 0; k < 2000; ++k) {
      if (mode > 0) {
        w.state().cache.pair_records_sparse = mode == 1;
        w.state().pairs.live_current = false;
      }
      w.cycle(1);
      r.flagged_steps += w.state().pairs.live_written;
    }
    const detail::PairStore& q = w.state().pairs;
    for (std::size_t k = 0; k < q.n; ++k) r.live += q.live[k];
    r.pairs = q.n;
    r.positions = w.positions();
    r.breaks = w.break_events().size();
    return r;
  };
  const Result every = run(1), probing = run(2), automatic = run(0);
  // Read after the step: a step that broke bonds has merged their pairs into a new store by then.
  EXPECT_GE(every.flagged_steps, 2000u - every.breaks);
  EXPECT_LE(probing.flagged_steps, 2000u / 64 + 1);
  EXPECT_GT(automatic.flagged_steps, 1900u) << "the box is found sparse";
  EXPECT_LT(2 * every.live, every.pairs) << "most listed pairs are near misses";
  EXPECT_GT(every.breaks, 0u);
  EXPECT_EQ(every.breaks, probing.breaks);
  for (const Result* r : {&probing, &automatic})
    EXPECT_EQ(0, std::memcmp(every.positions.data(), r->positions.data(), every.positions.size() * sizeof(double)));
}

TEST(Determinism, WholeRunSameWithEveryArchitecture) {
  std::vector<double> reference;
  for (const auto& arch : available_simd_architectures()) {
    WorldSettings ws;
    ws.simd = arch;
    World w = test::random_box(500, ws);
    EXPECT_EQ(w.simd_architecture(), arch);
    w.cycle(500);
    const auto p = w.positions();
    if (reference.empty()) reference = p;
    else EXPECT_EQ(0, std::memcmp(p.data(), reference.data(), p.size() * sizeof(double))) << arch;
  }
}

TEST(Determinism, UnknownArchitectureIsAClearError) {
  WorldSettings ws;
  ws.simd = "neon";
  try {
    World w(ws);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("neon"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("scalar"), std::string::npos) << "lists the valid ones";
  }
}

// Whether anything spins, which picks the pair and bond kernels with or without spin, is taken
// from the last step (State::spin_known) instead of a scan of the particles each step. Against a
// twin whose answer is cleared before every step, so that it scans every time, the runs must be
// the same bit for bit.
namespace {

std::vector<double> angular_velocities(const World& w) {
  std::vector<double> out;
  for (std::int64_t id = 0; id < std::int64_t(w.particle_count()); ++id)
    for (double c : {w.angular_velocity(id).x, w.angular_velocity(id).y, w.angular_velocity(id).z})
      out.push_back(c);
  return out;
}

void expect_same_run(const World& a, const World& b) {
  EXPECT_TRUE(test::same_bits(a.positions(), b.positions()));
  EXPECT_TRUE(test::same_bits(a.velocities(), b.velocities()));
  EXPECT_TRUE(test::same_bits(angular_velocities(a), angular_velocities(b)));
  EXPECT_TRUE(test::same_bits(a.forces(), b.forces()));
}

}  // namespace

// Loose spheres that start without spin and begin to turn in their frictional contacts: the
// answer is "nothing spins" for the first steps and must turn to "something does" in the step
// after the integration first gives a sphere a spin. Then half of them are bonded. By default that
// locks their rotation and zeroes their spin (model.md 5), and the bond stage's answer is again
// "nothing spins" while the free half keeps turning; with bonded rotation unlocked the bonded
// spheres turn too, and the bond stage must see it.
TEST(Determinism, SpinTakenFromTheLastStepEqualsAScanEveryStep) {
  for (const bool lock : {true, false}) {
    SCOPED_TRACE(lock ? "bonded rotation locked" : "bonded rotation free");
    auto make = [&] {
      WorldSettings ws;
      ws.lock_bonded_rotation = lock;
      World w = test::random_box(400, ws);
      for (std::int64_t id = 0; id < std::int64_t(w.particle_count()); ++id)
        w.set_angular_velocity(id, {0, 0, 0});
      return w;
    };
    World a = make(), b = make();
    std::vector<std::int64_t> even;
    for (std::int64_t id = 0; id < std::int64_t(a.particle_count()); id += 2) even.push_back(id);
    BondMaterial bm;
    bm.breakable = false;
    int still = 0, turning = 0, bonds_still = 0, bonds_turning = 0;
    for (int k = 0; k < 800; ++k) {
      if (k == 400) {
        for (World* w : {&a, &b}) ASSERT_GT(w->install_bonds(bm, 1e-4, even), 50u);
      }
      b.state().cache.spin_known = false;  // the twin scans
      a.cycle(1);
      b.cycle(1);
      const auto& s = a.state();
      ASSERT_TRUE(s.cache.spin_known);
      (s.cache.spin_reachable == 0 ? still : turning) += 1;
      if (k >= 400) (s.cache.spin_bonded == 0 ? bonds_still : bonds_turning) += s.cache.spin_reachable != 0;
    }
    EXPECT_GT(still, 0) << "the run starts without spin";
    EXPECT_GT(turning, 0) << "and the contacts make the spheres turn";
    if (lock) {
      EXPECT_EQ(bonds_turning, 0) << "the bonded spheres do not turn while the others do";
    } else {
      EXPECT_GT(bonds_turning, 0) << "the bonded spheres turn";
    }
    EXPECT_GT(bonds_still + bonds_turning, 0);
    EXPECT_GT(a.contact_count(), 50u) << "unbonded contacts";
    expect_same_run(a, b);
  }
}

// Two layers of spheres that may not turn (rotation locked) in a box, under a layer made a rigid
// group turning at a set angular velocity: only the group's members spin, given their group's angular velocity by the group
// stages after the gather. The next pair stage must see it.
TEST(Determinism, SpinOfRigidGroupMembersReachesThePairStage) {
  constexpr int n = 8;
  constexpr double d = 1e-3, a = 0.99 * d;
  auto make = [&] {
    World w;
    std::vector<double> xyz;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (double c : {(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a}) xyz.push_back(c);
    w.add_particles(xyz, std::vector<double>(xyz.size() / 3, 0.5 * d));
    const double L = n * a;  // a box of five planes keeps the lattice's 1 % overlaps
    w.add_plane({0, 0, 0}, {0, 0, 1});
    w.add_plane({0, 0, 0}, {1, 0, 0});
    w.add_plane({L, 0, 0}, {-1, 0, 0});
    w.add_plane({0, 0, 0}, {0, 1, 0});
    w.add_plane({0, L, 0}, {0, -1, 0});
    std::vector<std::int64_t> top;
    for (std::int64_t id = 0; id < std::int64_t(w.particle_count()); ++id) {
      if (id >= 2 * n * n) top.push_back(id);
      else w.set_rotation_locked(id, true);
    }
    GroupMotion turn;
    turn.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
    turn.rotation = Dof::velocity;
    turn.angular_velocity = {2e-2, 0, 0};
    w.add_group(top, turn);
    return w;
  };
  World x = make(), y = make();
  for (int k = 0; k < 300; ++k) {
    y.state().cache.spin_known = false;
    x.cycle(1);
    y.cycle(1);
  }
  ASSERT_TRUE(x.state().cache.spin_known);
  EXPECT_NE(x.state().cache.spin_reachable, 0u) << "the members spin";
  EXPECT_GT(x.contact_count(), 100u);
  expect_same_run(x, y);
}
