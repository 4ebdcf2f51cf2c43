// run_stages (engine/step.cpp): each thread runs its own share of a stage's blocks from the front,
// then takes what is left of the other shares from their backs. Whatever the timing, every block
// must run exactly once, and a stage after a barrier must start only when every block before it
// is done; a thread held back must be helped.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "state.hpp"
#include "step.hpp"

namespace asperity::detail {
namespace {

TEST(Stages, EveryBlockRunsOnceAndASlowShareIsTaken) {
  State s;
  s.settings.threads = 2;
  s.ctx.max_threads = 2;
  constexpr std::size_t kFirst = 40, kSecond = 13, kThird = 9;
  std::vector<std::atomic<int>> first(kFirst), second(kSecond), third(kThird);
  std::vector<int> first_by(kFirst, -1);
  std::atomic<bool> early{false};  // a block after the barrier saw an unfinished earlier block
  std::atomic<int> finished{0};

  StageLoop a, b, c;
  a.blocks = kFirst;
  a.run = [&](std::size_t blk) {
    first_by[blk] = omp_get_thread_num();
    // Thread 1 is slow: thread 0 must take the back of its share.
    if (omp_get_thread_num() == 1) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ++first[blk];
  };
  b.blocks = kSecond;  // no barrier: may run while stage a still runs on the other thread
  b.run = [&](std::size_t blk) { ++second[blk]; };
  c.blocks = kThird;
  c.after_barrier = true;
  c.run = [&](std::size_t blk) {
    for (std::size_t k = 0; k < kFirst; ++k) early = early || first[k].load() != 1;
    for (std::size_t k = 0; k < kSecond; ++k) early = early || second[k].load() != 1;
    ++third[blk];
  };
  c.finish = [&] { ++finished; };
  run_stages(s, {&a, &b, &c});

  for (std::size_t k = 0; k < kFirst; ++k) EXPECT_EQ(first[k].load(), 1) << "stage a, block " << k;
  for (std::size_t k = 0; k < kSecond; ++k) EXPECT_EQ(second[k].load(), 1) << "stage b, block " << k;
  for (std::size_t k = 0; k < kThird; ++k) EXPECT_EQ(third[k].load(), 1) << "stage c, block " << k;
  EXPECT_FALSE(early.load()) << "a stage after the barrier started before the earlier blocks were done";
  EXPECT_EQ(finished.load(), 1);
  // Thread 1's share is blocks 20..39; thread 0, never slowed, takes some of them from the back.
  int taken = 0;
  for (std::size_t k = kFirst / 2; k < kFirst; ++k) taken += first_by[k] == 0;
  EXPECT_GT(taken, 0) << "the slow thread's blocks were not taken by the other";
}

TEST(Stages, OneThreadRunsEveryBlockInOrder) {
  State s;
  s.settings.threads = 1;
  std::vector<std::size_t> order;
  StageLoop a, b;
  a.blocks = 5;
  a.run = [&](std::size_t blk) { order.push_back(blk); };
  b.blocks = 3;
  b.after_barrier = true;
  b.run = [&](std::size_t blk) { order.push_back(100 + blk); };
  run_stages(s, {&a, &b});
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4, 100, 101, 102}));
}

}  // namespace
}  // namespace asperity::detail
