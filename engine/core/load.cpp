#include "core/load.hpp"

#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace asperity::detail {

double proc_stat_busy_seconds(std::string_view text, const std::vector<int>& cpus, double ticks) {
  // Lines "cpu  user nice system idle iowait irq softirq steal guest guest_nice" (the aggregate)
  // and "cpuN ..." per CPU. Idle and iowait are not busy; steal is time the hypervisor gave to
  // other machines, not to a process of this one; guest time is already inside user.
  std::vector<char> seen(cpus.size(), 0);
  double total = 0;
  bool any = false;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line.substr(0, 3) != "cpu") continue;
    std::size_t i = 3;
    int number = -1;  // the aggregate line
    if (i < line.size() && line[i] >= '0' && line[i] <= '9') {
      number = 0;
      while (i < line.size() && line[i] >= '0' && line[i] <= '9') number = 10 * number + (line[i++] - '0');
    }
    std::size_t slot = cpus.size();
    if (cpus.empty()) {
      if (number != -1) continue;
    } else {
      if (number < 0) continue;
      slot = std::size_t(std::find(cpus.begin(), cpus.end(), number) - cpus.begin());
      if (slot == cpus.size()) continue;
    }
    const std::string fields(line.substr(i));
    const char* p = fields.c_str();
    double value[7] = {0, 0, 0, 0, 0, 0, 0};
    int count = 0;
    for (; count < 7; ++count) {
      char* next = nullptr;
      value[count] = std::strtod(p, &next);
      if (next == p) break;
      p = next;
    }
    if (count < 7) return -1;  // not the format of /proc/stat
    total += value[0] + value[1] + value[2] + value[5] + value[6];
    any = true;
    if (slot < cpus.size()) seen[slot] = 1;
  }
  if (!any || std::find(seen.begin(), seen.end(), 0) != seen.end()) return -1;
  return total / ticks;
}

int free_threads(int cpus, double others) {
  const int n = int(std::floor(double(cpus) - std::max(0.0, others) + 0.3));
  return std::clamp(n, 1, std::max(1, cpus));
}

CpuSample sample_cpu() {
  CpuSample s;
  s.wall = LoadWatch::now();
  std::vector<int> cpus;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) cpus.push_back(c);
  // The "cpu" lines come first; the rest of the file (interrupt counts) can be long.
  std::ifstream f("/proc/stat");
  std::string text, line;
  while (std::getline(f, line) && line.compare(0, 3, "cpu") == 0) text += line + '\n';
  const long ticks = sysconf(_SC_CLK_TCK);
  if (text.empty() || ticks <= 0) return s;
  s.busy = proc_stat_busy_seconds(text, cpus, double(ticks));
  if (s.busy < 0) return s;
  rusage ru{};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return s;
  s.self = double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
           1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  s.cpus = cpus.empty() ? int(std::max(1u, std::thread::hardware_concurrency())) : int(cpus.size());
  s.valid = true;
  return s;
}

int LoadWatch::limit(double now) {
  if (now < next_.load(std::memory_order_relaxed)) return limit_.load(std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(mutex_);
  if (now < next_.load(std::memory_order_relaxed)) return limit_.load(std::memory_order_relaxed);
  const CpuSample s = sampler_();
  const bool first = !last_.valid;
  if (s.valid && last_.valid && s.wall > last_.wall) {
    // The busy time is counted in ticks (10 ms): over half a second on two CPUs a reading is
    // good to ~0.04 of a core.
    const double busy = s.busy - last_.busy, self = s.self - last_.self;
    const double others = std::max(0.0, (busy - self) / (s.wall - last_.wall));
    others_.store(others, std::memory_order_relaxed);
    limit_.store(free_threads(s.cpus, others), std::memory_order_relaxed);
  }
  if (s.valid) last_ = s;
  next_.store(now + (first ? first_ : interval_), std::memory_order_relaxed);
  return limit_.load(std::memory_order_relaxed);
}

LoadWatch& process_load() {
  static LoadWatch watch;
  return watch;
}

}  // namespace asperity::detail
