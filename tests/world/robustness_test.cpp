// Bad values at the API boundary and non-finite state inside the step: refused by name, or
// stopped by the health check; never a hang, a crash or a success with NaN state.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scenes.hpp"
#include "state.hpp"

using namespace asperity;
using asperity::test::error_of;

namespace {
World pair_of_spheres() {
  World w;
  w.add_particle({0, 0, 0}, 1e-3);
  w.add_particle({1.9e-3, 0, 0}, 1e-3);
  return w;
}
}  // namespace

TEST(Robustness, ValuesOutsideTheirBoundsAreRefusedByName) {
  World w = pair_of_spheres();
  EXPECT_EQ(error_of([&] { w.add_particle({0, 0, 0}, 1e-3, 1e-300); }),
            "add_particle: density 1e-300 outside [1e-06, 1e+09] kg/m^3");
  EXPECT_EQ(error_of([&] { w.add_particle({0, 0, 0}, 1e200); }), "add_particle: radius 1e+200 outside [1e-06, 1000] m");
  EXPECT_NE(error_of([&] { w.add_particle({-1.7e308, 0, 0}, 1e-3); }).find("add_particle: position (-1.7e+308, 0, 0) outside"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { w.set_dt_safety(1e-320); }).rfind("set_dt_safety: dt_safety 9.99989e-321 outside [0.001, 2]", 0), 0u);
  EXPECT_EQ(w.particle_count(), 2u);
  // A plane normal whose square overflows is normalised all the same.
  const int plane = w.add_plane({0, 0, -0.01}, {0, 0, 1e200});
  EXPECT_EQ(w.state().walls.walls[std::size_t(plane)].normal, (Vec3{0, 0, 1}));
}

TEST(Robustness, AFailedAddGroupLeavesTheWorldAsItWas) {
  World w = pair_of_spheres();
  GroupMotion m;
  m.translation = {Dof::free, Dof::free, Dof::servo};
  m.servo[2].max_velocity = -1;
  const std::int64_t ids[] = {0, 1};
  EXPECT_NE(error_of([&] { w.add_group(ids, m); }).find("servo on z: max_velocity -1 outside (0, inf) m/s"), std::string::npos);
  EXPECT_EQ(w.group_count(), 0u);
  EXPECT_EQ(w.group_of(0), -1);
  EXPECT_EQ(w.group_of(1), -1);
  w.cycle(20);  // once read past the group's members
  EXPECT_EQ(w.add_group(ids, GroupMotion{}), 0);
  w.cycle(20);
}

// The displacement check does not see a spin; the kinetic energy of the step does.
TEST(Robustness, NonFiniteAngularVelocityStopsTheStep) {
  World w = pair_of_spheres();
  w.cycle(1);
  w.state().p.wz[w.state().p.index_of_id[1]] = std::nan("");  // inf is caught as a turn of more than 0.1 rad
  w.state().cache.spin_known = false;
  try {
    w.cycle(5);
    FAIL() << "the step went on";
  } catch (const HealthError& e) {
    EXPECT_EQ(e.particle_id, 1);
    EXPECT_EQ(e.quantity, "kinetic energy");
  }
}

// Particles spread over more than the largest double (a run-away): an error, not a cell grid that
// grows its cells forever.
TEST(Robustness, ParticlesSpreadBeyondTheRangeOfDoublesStopTheStep) {
  World w = pair_of_spheres();
  auto& p = w.state().p;
  p.x[p.index_of_id[0]] = -1.7e308;
  p.x[p.index_of_id[1]] = 1.7e308;
  EXPECT_THROW(w.rebuild_neighbors(), HealthError);
  w.state().need_rebuild = true;
  try {
    w.cycle(1);
    FAIL() << "the step went on";
  } catch (const HealthError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite extent"), std::string::npos);
  }
}

// After a stopped step the world keeps its non-finite values for inspection; no later cycle may
// succeed while any are left, even where the step would not touch them (a fixed group's member).
TEST(Robustness, NoCycleSucceedsWhileAStoppedStepsNaNIsLeft) {
  World w = pair_of_spheres();
  w.state().p.vx[w.state().p.index_of_id[0]] = std::nan("");
  EXPECT_THROW(w.cycle(1), HealthError);
  GroupMotion fixed;
  fixed.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  const std::int64_t member[] = {0};
  w.add_group(member, fixed);
  try {
    w.cycle(3);
    FAIL() << "a cycle succeeded with a NaN left";
  } catch (const HealthError& e) {
    EXPECT_NE(std::string(e.what()).find("still holds the non-finite values"), std::string::npos) << e.what();
  }
}

// A fixed time step near the largest double, allowed above the estimate: the clock overflows and
// the step stops instead of returning with time = inf.
TEST(Robustness, AClockThatOverflowsStopsTheStep) {
  WorldSettings ws;
  ws.allow_dt_above_estimate = true;
  World w(ws);
  w.add_particle({0, 0, 0}, 1e-3);
  w.set_dt(1.7e308);
  try {
    w.cycle(3);
    FAIL() << "time = " << w.time();
  } catch (const HealthError& e) {
    EXPECT_EQ(e.quantity, "time");
  }
}

// The health check's overlap limit: a pair pressed 1.2 radii deep stops the step under the default
// limit (one radius) and runs under a raised one, which a checkpoint keeps.
TEST(Robustness, AnOverlapDeeperThanTheLimitStopsTheStepAndTheLimitCanBeRaised) {
  auto deep_pair = [] {
    World w;
    w.add_particle({0, 0, 0}, 1e-3);
    w.add_particle({0.8e-3, 0, 0}, 1e-3);  // overlap 1.2e-3 = 1.2 R
    GroupMotion held;                       // two fixed bodies: the overlap stays
    held.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
    const std::int64_t a[] = {0}, b[] = {1};
    w.add_group(a, held);
    w.add_group(b, held);
    return w;
  };
  World w = deep_pair();
  try {
    w.cycle(200);  // the check runs with the time-step estimate, every dt_interval steps
    FAIL() << "the step went on with an overlap of 1.2 R";
  } catch (const HealthError& e) {
    EXPECT_EQ(e.quantity, "overlap / R");
    EXPECT_NEAR(e.value, 1.2, 1e-6);
  }
  World v = deep_pair();
  EXPECT_EQ(error_of([&] { v.set_overlap_limit(2.0); }).rfind("set_overlap_limit: overlap_limit 2 outside (0, 2)", 0), 0u);
  v.set_overlap_limit(1.5);
  EXPECT_NO_THROW(v.cycle(200));
  const std::string path = ::testing::TempDir() + "overlap_limit.h5";
  v.save(path);
  EXPECT_EQ(World::load(path).settings().overlap_limit, 1.5);
  WorldSettings bad;
  bad.overlap_limit = 0;
  EXPECT_NE(error_of([&] { World x(bad); }).find("overlap_limit 0 outside (0, 2)"), std::string::npos);
}
