// The cores other processes leave free, for the automatic thread count (WorldSettings::threads
// = 0). A step is split over threads that meet at barriers, so a thread sharing its core with
// another busy process holds every other thread up at each barrier: on a machine with a core
// busy elsewhere, more threads than free cores make a step slower than fewer would. The watcher
// compares the busy time of the CPUs this process may run on (/proc/stat) with the process's own
// CPU time (getrusage) over intervals of half a second and gives the number of threads that the
// rest leaves room for. The thread count changes no result (every stage sums in a fixed order),
// only the speed.
#pragma once
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string_view>
#include <vector>

namespace asperity::detail {

// One reading of the CPU clocks: the busy seconds of this process's CPUs since boot and the
// process's own CPU seconds, at a wall time. valid = false where /proc/stat cannot be read
// (then the watcher leaves the thread count alone).
struct CpuSample {
  double wall = 0;  // s, steady clock
  double busy = 0;  // s, summed over the process's CPUs
  double self = 0;  // s, this process (all its threads)
  int cpus = 0;     // CPUs the process may run on
  bool valid = false;
};

CpuSample sample_cpu();

// The busy seconds (user + nice + system + irq + softirq) of the CPUs numbered in `cpus` in the
// text of /proc/stat; empty `cpus`: of the aggregate "cpu" line. ticks: USER_HZ. Returns -1 if a
// listed CPU has no line.
double proc_stat_busy_seconds(std::string_view text, const std::vector<int>& cpus, double ticks);

// Threads worth running on `cpus` CPUs while other processes keep `others` cores busy on average:
// one per core they leave free, a core counting as free while they take less than 0.3 of it (a
// thread that gets the rest of such a core still gains more than its barrier waits cost). At
// least 1.
int free_threads(int cpus, double others);

// One per process (process_load) for the worlds: a new world starts from what the last one saw.
// limit() may be called from several threads; between samples it reads two atomics.
class LoadWatch {
 public:
  using Sampler = std::function<CpuSample()>;
  // The first interval is short, so that a run knows the load after a tenth of a second; it
  // reads ~20 ticks on two CPUs, +-0.2 of a core, and the next ones correct it.
  explicit LoadWatch(Sampler sampler = sample_cpu, double interval = 0.5, double first = 0.1)
      : sampler_(std::move(sampler)), interval_(interval), first_(first) {}
  // The threads free_threads allows from the last interval (re-sampled when `now`, s on the
  // steady clock, is an interval past the last sample); 0 until the first interval has passed
  // or where the clocks cannot be read.
  int limit(double now);
  // Cores kept busy by other processes over the last interval; -1 before the first.
  double others() const { return others_.load(std::memory_order_relaxed); }
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }

 private:
  Sampler sampler_;
  double interval_, first_;
  std::mutex mutex_;  // the sample and the reading before it
  CpuSample last_;
  std::atomic<double> next_{-1};  // wall time of the next sample
  std::atomic<double> others_{-1};
  std::atomic<int> limit_{0};
};

LoadWatch& process_load();

}  // namespace asperity::detail
