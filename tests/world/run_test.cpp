// World::run: the run loop with its limits, checks, stop conditions and interruptions.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "asperity/world.hpp"
#include "scenes.hpp"

using namespace asperity;
using asperity::test::random_box;

namespace {
std::vector<Vec3> positions(const World& w) {
  std::vector<Vec3> out;
  for (std::int64_t id = 0; id < std::int64_t(w.particle_count()); ++id) out.push_back(w.position(id));
  return out;
}
}  // namespace

TEST(Run, AStepLimitRunsThoseStepsExactlyAsCycleDoes) {
  World a = random_box(60), b = random_box(60);
  RunPlan plan;
  plan.steps = 250;
  const RunResult r = a.run(plan);
  EXPECT_EQ(r.steps, 250u);
  EXPECT_EQ(r.end, RunResult::End::steps);
  EXPECT_EQ(b.cycle(250), 250u);
  EXPECT_EQ(a.step_count(), b.step_count());
  EXPECT_EQ(positions(a), positions(b));
}

TEST(Run, TheCallbackAndTheStopConditionRunEveryNSteps) {
  World w = random_box(60);
  RunPlan plan;
  plan.every = 50;
  std::vector<std::uint64_t> called, asked;
  plan.callback = [&] { called.push_back(w.step_count()); };
  plan.stop_when = [&] {
    asked.push_back(w.step_count());
    return w.step_count() >= 200;
  };
  const RunResult r = w.run(plan);
  EXPECT_EQ(r.end, RunResult::End::stop_when);
  EXPECT_EQ(r.steps, 200u);
  EXPECT_EQ(called, (std::vector<std::uint64_t>{50, 100, 150, 200}));
  EXPECT_EQ(asked, called);
}

// The sample hook keeps its own cadence, counted from the run's start like the checks, and
// neither it nor the callback's cadence changes the trajectory.
TEST(Run, TheSampleHookRunsOnItsOwnCadence) {
  World w = random_box(60), plain = random_box(60);
  RunPlan plan;
  plan.steps = 230;
  plan.every = 100;
  std::vector<std::uint64_t> sampled, called;
  plan.sample_every = 30;
  plan.sample = [&] { sampled.push_back(w.step_count()); };
  plan.callback = [&] { called.push_back(w.step_count()); };
  EXPECT_EQ(w.run(plan).steps, 230u);
  EXPECT_EQ(sampled, (std::vector<std::uint64_t>{30, 60, 90, 120, 150, 180, 210}));
  EXPECT_EQ(called, (std::vector<std::uint64_t>{100, 200}));
  plain.cycle(230);
  EXPECT_EQ(positions(w), positions(plain));

  RunPlan half;  // a hook without its cadence, or a cadence without its hook
  half.steps = 10;
  half.sample = [] {};
  EXPECT_THROW(w.run(half), Error);
  half.sample = nullptr;
  half.sample_every = 5;
  EXPECT_THROW(w.run(half), Error);
}

TEST(Run, EquilibriumEndsTheRunAtTheFirstCheckBelowTheRatio) {
  WorldSettings ws;
  ws.local_damping = 0.7;
  World w = random_box(60, ws);
  RunPlan plan;
  plan.until_equilibrium = true;
  plan.ratio = 1e-2;
  plan.every = 100;
  plan.steps = 200000;
  const RunResult r = w.run(plan);
  ASSERT_EQ(r.end, RunResult::End::equilibrium);
  EXPECT_EQ(r.steps % 100, 0u);
  EXPECT_LE(r.ratio, 1e-2);
  EXPECT_EQ(r.ratio, w.unbalanced_force_ratio());
}

TEST(Run, AStopRequestEndsTheRunAndOnlyThatRun) {
  World w = random_box(60);
  RunPlan plan;
  plan.steps = 1000;
  plan.every = 100;
  plan.callback = [&] { w.request_stop(); };
  const RunResult r = w.run(plan);
  EXPECT_EQ(r.end, RunResult::End::interrupted);
  EXPECT_EQ(r.steps, 100u);  // the chunk after the check stopped before its first step
  EXPECT_EQ(w.cycle(10), 10u);

  int polls = 0;
  RunPlan outside;
  outside.steps = 1000;
  outside.interrupted = [&] { return ++polls == 3; };
  const std::uint64_t before = w.step_count();
  const RunResult o = w.run(outside);
  EXPECT_EQ(o.end, RunResult::End::interrupted);
  EXPECT_EQ(polls, 3);  // polled after every chunk, the run ends at the first yes
  EXPECT_EQ(o.steps, w.step_count() - before);
  EXPECT_GE(o.steps, 3u);  // three chunks of at least one step, doubling while they are quick
  EXPECT_LE(o.steps, 7u);
}

TEST(Run, AHookThatThrowsEndsTheRunWithTheWorldIntact) {
  World w = random_box(60);
  RunPlan plan;
  plan.every = 20;
  plan.stop_when = [&]() -> bool {
    w.request_stop();  // a request left behind by the failed run must not stop the next one
    throw std::runtime_error("hook failed");
  };
  EXPECT_THROW(w.run(plan), std::runtime_error);
  EXPECT_EQ(w.step_count(), 20u);
  EXPECT_EQ(w.cycle(5), 5u);
}

TEST(Run, APlanWithoutAnEndOrWithBadValuesIsRefused) {
  World w = random_box(10);
  RunPlan none;
  EXPECT_THROW(w.run(none), Error);
  RunPlan every;
  every.steps = 10;
  every.every = 0;
  EXPECT_THROW(w.run(every), Error);
  RunPlan ratio;
  ratio.until_equilibrium = true;
  ratio.ratio = 0;
  EXPECT_THROW(w.run(ratio), Error);
  EXPECT_EQ(w.step_count(), 0u);
}

TEST(Run, SetDampingStepsAsAWorldMadeWithThatDamping) {
  // [3-28] read at every step: damping changed on a world moves its particles exactly as a world
  // made with that damping, and differently from the damping it had.
  WorldSettings made_low, made_high;
  made_low.local_damping = 0.2;
  made_high.local_damping = 0.7;
  World low = random_box(60, made_low), changed = random_box(60, made_high), high = random_box(60, made_high);
  changed.set_damping(0.2);
  low.cycle(300);
  changed.cycle(300);
  high.cycle(300);
  EXPECT_EQ(positions(changed), positions(low));
  EXPECT_NE(positions(changed), positions(high));
  EXPECT_THROW(changed.set_damping(1.0), Error);
  EXPECT_THROW(changed.set_damping(-0.1), Error);
}
