// The automatic thread count leaves the cores that other processes keep busy (core/load.hpp):
// the /proc/stat reading, the rule, the watcher's arithmetic over an interval, and the step's
// use of it, with the clocks replaced by made-up readings.
#include <gtest/gtest.h>

#include <vector>

#include "core/load.hpp"
#include "state.hpp"
#include "step.hpp"

namespace asperity::detail {
namespace {

// Two CPUs; fields user nice system idle iowait irq softirq steal guest guest_nice, in ticks.
constexpr const char* kStat =
    "cpu  1000 20 300 5000 40 6 7 900 11 0\n"
    "cpu0 600 10 200 2000 20 3 4 400 11 0\n"
    "cpu1 400 10 100 3000 20 3 3 500 0 0\n"
    "intr 12345 0 0\n";

TEST(Load, BusyTimeIsUserNiceSystemIrqSoftirqOfTheListedCpus) {
  // busy = user + nice + system + irq + softirq; not idle, iowait, steal, nor guest (in user).
  EXPECT_DOUBLE_EQ(proc_stat_busy_seconds(kStat, {}, 100.0), (1000 + 20 + 300 + 6 + 7) / 100.0);
  EXPECT_DOUBLE_EQ(proc_stat_busy_seconds(kStat, {0}, 100.0), (600 + 10 + 200 + 3 + 4) / 100.0);
  EXPECT_DOUBLE_EQ(proc_stat_busy_seconds(kStat, {1}, 100.0), (400 + 10 + 100 + 3 + 3) / 100.0);
  EXPECT_DOUBLE_EQ(proc_stat_busy_seconds(kStat, {0, 1}, 100.0), (817 + 516) / 100.0);
  EXPECT_LT(proc_stat_busy_seconds(kStat, {0, 2}, 100.0), 0);  // no line for CPU 2
  EXPECT_LT(proc_stat_busy_seconds("cpu 1 2 3\n", {}, 100.0), 0);  // too few fields
  EXPECT_LT(proc_stat_busy_seconds("", {}, 100.0), 0);
}

TEST(Load, ThisMachinesReadingIsSane) {
  const CpuSample a = sample_cpu();
  ASSERT_TRUE(a.valid) << "/proc/stat or getrusage could not be read";
  EXPECT_GE(a.cpus, 1);
  EXPECT_GT(a.busy, 0);
  EXPECT_GE(a.self, 0);
  volatile double x = 0;
  for (int i = 0; i < 20000000; ++i) x = x + 1e-9 * i;  // some CPU time of our own
  const CpuSample b = sample_cpu();
  EXPECT_GT(b.wall, a.wall);
  EXPECT_GT(b.self, a.self);
  EXPECT_GE(b.busy, a.busy);
}

TEST(Load, AThreadPerCoreLeftFree) {
  EXPECT_EQ(free_threads(2, 0.0), 2);
  EXPECT_EQ(free_threads(2, 0.25), 2);  // a little load elsewhere: a second thread still pays
  EXPECT_EQ(free_threads(2, 0.35), 1);
  EXPECT_EQ(free_threads(2, 1.0), 1);   // one core busy (a spinning process)
  EXPECT_EQ(free_threads(2, 3.0), 1);   // never below one
  EXPECT_EQ(free_threads(8, 2.9), 5);
  EXPECT_EQ(free_threads(8, -1.0), 8);  // negative (clock skew) counts as none
  EXPECT_EQ(free_threads(1, 0.0), 1);
}

// A sampler returning made-up readings in turn, counting its calls.
struct Script {
  std::vector<CpuSample> readings;
  int calls = 0;
  LoadWatch::Sampler sampler() {
    return [this] { return readings[std::size_t(std::min<int>(calls++, int(readings.size()) - 1))]; };
  }
};

CpuSample reading(double wall, double busy, double self, int cpus = 2) {
  CpuSample s;
  s.wall = wall;
  s.busy = busy;
  s.self = self;
  s.cpus = cpus;
  s.valid = true;
  return s;
}

TEST(Load, OthersAreTheBusyTimeNotOurs) {
  Script script;
  // t = 0 -> 1 s: both CPUs busy (2 s), 1 s of it ours: others kept one core.
  // t = 1 -> 2 s: one CPU busy, all of it ours: others none.
  // t = 2 -> 2.5 s: 1 s busy, none of it ours: others kept both cores.
  script.readings = {reading(0, 10, 3), reading(1, 12, 4), reading(2, 13, 5), reading(2.5, 14, 5.0)};
  LoadWatch w(script.sampler(), 0.5, 0.2);
  EXPECT_EQ(w.limit(0.0), 0);  // one reading: nothing known yet
  EXPECT_DOUBLE_EQ(w.others(), -1);
  EXPECT_EQ(w.limit(0.15), 0);  // within the first (short) interval: no new reading
  EXPECT_EQ(script.calls, 1);
  EXPECT_EQ(w.limit(1.0), 1);
  EXPECT_DOUBLE_EQ(w.others(), 1.0);
  EXPECT_EQ(w.limit(1.45), 1);  // then intervals of 0.5 s
  EXPECT_EQ(script.calls, 2);
  EXPECT_EQ(w.limit(2.0), 2);
  EXPECT_DOUBLE_EQ(w.others(), 0.0);
  EXPECT_EQ(w.limit(2.5), 1);
  EXPECT_DOUBLE_EQ(w.others(), 2.0);
  EXPECT_EQ(script.calls, 4);
}

TEST(Load, UnreadableClocksLeaveTheCountAlone) {
  Script script;
  script.readings = {CpuSample{}, CpuSample{}};
  LoadWatch w(script.sampler(), 0.5);
  EXPECT_EQ(w.limit(0.0), 0);
  EXPECT_EQ(w.limit(1.0), 0);
  EXPECT_DOUBLE_EQ(w.others(), -1);
}

TEST(Load, AutomaticThreadsFollowTheLimitFixedOnesDoNot) {
  State s;
  s.ctx.max_threads = 2;
  s.p.n = 1000000;  // enough particles for two threads by size
  Script script;
  // Others keep one core busy over the first interval.
  const double t0 = LoadWatch::now();
  script.readings = {reading(t0, 0, 0), reading(t0 + 1, 2, 1)};
  LoadWatch w(script.sampler(), 0.5);
  s.ctx.load = &w;
  EXPECT_EQ(thread_count(s), 2);
  watch_load(s);  // the first reading
  EXPECT_EQ(thread_count(s), 2);
  w.limit(LoadWatch::now() + 1);  // the interval passes
  watch_load(s);
  EXPECT_EQ(s.ctx.load_limit, 1);
  EXPECT_EQ(thread_count(s), 1);
  s.settings.threads = 2;  // asked for: given, whatever the load
  EXPECT_EQ(thread_count(s), 2);
}

}  // namespace
}  // namespace asperity::detail
