// Whole-step throughput on the peers' lattice scene (perf/lattice_scene.hpp): build, 200 warm-up
// steps, then `steps` timed steps through World::cycle, exactly what a script's run loop does.
// The last line is `particle-steps/s: <number>` (what perf/peers.sh reads).
//
//   lattice_bench [n=40] [steps=1000] [threads=1] [warmup=200] [simd=auto] [reorder=10]
//                 [energy=1] [stages=0] [repeat=1]
//
// stages=1 also times each stage function on its own (same state, after the run) and prints the
// share of a step each takes; `other` is the rest of step_once (dt estimate and energy check every
// 100 steps, bookkeeping, health checks).
// repeat=k runs the timed segment k times and reports the best (the machine is shared).
// Also printed: the process CPU time of the timed steps and `cpu-particle-steps/s` (particle-steps
// per CPU-second). With threads=1 that figure hardly moves when other programs compete for the
// cores, so it is the one to compare on a busy machine (LAMMPS prints its CPU share too).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <utility>

#include "lattice_scene.hpp"
#include "stages/bonds.hpp"
#include "stages/integrate.hpp"
#include "stages/pairs.hpp"
#include "stages/walls.hpp"
#include "neighbor/build.hpp"
#include "state.hpp"
#include "step.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double cpu_seconds() {  // CPU time of the whole process (all threads)
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Mean wall and CPU seconds per call.
template <class F>
std::pair<double, double> time_per_call(F&& f, int calls) {
  const auto t0 = Clock::now();
  const double c0 = cpu_seconds();
  for (int i = 0; i < calls; ++i) f();
  return {seconds_since(t0) / calls, (cpu_seconds() - c0) / calls};
}

// One stage on its own, run as the step runs its stages (run_stages).
void run_stage(asperity::detail::State& s, asperity::detail::StageLoop st) {
  asperity::detail::run_stages(s, {&st});
}

[[noreturn]] void usage(const char* bad) {
  std::fprintf(stderr,
               "lattice_bench: bad argument '%s'\nusage: lattice_bench [n=40] [steps=1000] "
               "[threads=1] [warmup=200] [simd=auto] [reorder=10] [energy=1] [stages=0] "
               "[repeat=1]\n",
               bad);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  asperity::perf::LatticeOptions o;
  long steps = 1000, warmup = 200;
  int stages = 0, repeat = 1;
  for (int i = 1; i < argc; ++i) {
    const char* eq = std::strchr(argv[i], '=');
    if (!eq) usage(argv[i]);
    const std::string key(argv[i], std::size_t(eq - argv[i])), val(eq + 1);
    try {
      if (key == "n") o.n = std::stoi(val);
      else if (key == "steps") steps = std::stol(val);
      else if (key == "threads") o.threads = std::stoi(val);
      else if (key == "warmup") warmup = std::stol(val);
      else if (key == "simd") o.simd = val;
      else if (key == "reorder") o.reorder_interval = std::stoi(val);
      else if (key == "energy") o.track_energy = std::stoi(val) != 0;
      else if (key == "stages") stages = std::stoi(val);
      else if (key == "repeat") repeat = std::max(1, std::stoi(val));
      else usage(argv[i]);
    } catch (const std::logic_error&) {
      usage(argv[i]);
    }
  }
  if (o.n < 2 || steps < 1 || warmup < 0 || o.threads < 0) usage("(value out of range)");

  const auto t_build = Clock::now();
  asperity::World w = asperity::perf::make_lattice(o);
  const std::size_t N = w.particle_count();
  w.cycle(std::uint64_t(warmup));
  const double build_s = seconds_since(t_build);
  const auto st0 = w.stats();
  std::printf("asperity %s (%s), lattice n=%d: %zu particles, %zu pairs, %zu contacts, %zu wall "
              "contacts\n",
              ASPERITY_VERSION, ASPERITY_BUILD_TYPE, o.n, N, st0.pairs, st0.contacts,
              st0.wall_contacts);
  std::printf("simd: %s, threads: %d, dt: %g s, build + %ld warm-up steps: %.3f s\n",
              w.simd_architecture().c_str(), w.settings().threads, w.dt(), warmup, build_s);

  double best = 1e300, best_cpu = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    const double c0 = cpu_seconds();
    w.cycle(std::uint64_t(steps));
    const double el = seconds_since(t0);
    best = std::min(best, el);
    best_cpu = std::min(best_cpu, cpu_seconds() - c0);
    if (repeat > 1) std::printf("run %d: %.4f s, %.4g particle-steps/s\n", r, el, double(N) * steps / el);
  }
  const auto st1 = w.stats();
  std::printf("timed: %ld steps in %.4f s (%.3f us/step, %.2f ns/particle-step), rebuilds during "
              "the run: %llu\n",
              steps, best, 1e6 * best / steps, 1e9 * best / (double(N) * steps),
              static_cast<unsigned long long>(st1.rebuilds - st0.rebuilds));
  std::printf("cpu time: %.4f s (%.0f %% of the wall time x threads)\n", best_cpu,
              100.0 * best_cpu / (best * w.settings().threads));

  if (stages) {
    using namespace asperity::detail;
    State& s = w.state();
    const int calls = int(std::max<long>(10, std::min<long>(steps, 200)));
    // With one thread, CPU time (robust against other programs on the machine). The items are
    // interleaved call by call, so a burst of activity elsewhere (which also takes shared cache and
    // memory bandwidth, and CPU time does not see that) hits them alike.
    const bool cpu = w.settings().threads == 1;
    double sum[4] = {0, 0, 0, 0};
    for (int c = 0; c < calls; ++c) {
      auto add = [&](int k, auto&& f) {
        const auto [wall, ct] = time_per_call(f, 1);
        sum[k] += cpu ? ct : wall;
      };
      add(0, [&] { w.cycle(1); });
      add(1, [&] { run_stage(s, pair_stage(pair_view(s))); });
      add(2, [&] { run_stage(s, wall_stage(wall_view(s))); });
      add(3, [&] { run_stage(s, integrate_stage(integrate_view(s))); });
    }
    const double t_step = sum[0] / calls, t_pair = sum[1] / calls, t_wall = sum[2] / calls,
                 t_gi = sum[3] / calls;
    const int nb_calls = std::max(3, calls / 20);
    const auto [nb_wall, nb_cpu] = time_per_call([&] { build_neighbors(s); }, nb_calls);
    const double t_nb = cpu ? nb_cpu : nb_wall;
    const double other = t_step - t_pair - t_wall - t_gi;
    auto line = [&](const char* name, double t) {
      std::printf("  %-22s %9.3f ms  %6.2f ns/particle  %5.1f %%\n", name, 1e3 * t,
                  1e9 * t / double(N), 100.0 * t / t_step);
    };
    std::printf("stages (mean %s time of %d calls each; neighbour build not part of these steps):\n",
                cpu ? "CPU" : "wall", calls);
    line("step (World::cycle(1))", t_step);
    line("contacts (pair kernel)", t_pair);
    line("walls", t_wall);
    line("gather + integrate", t_gi);
    line("other", other);
    line("neighbour build", t_nb);
  }
  std::printf("cpu-particle-steps/s: %.6g\n", double(N) * double(steps) / best_cpu);
  std::printf("particle-steps/s: %.6g\n", double(N) * double(steps) / best);
  return 0;
}
