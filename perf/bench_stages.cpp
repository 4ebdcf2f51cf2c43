// Google Benchmark micro-benchmarks of each stage of a step, on the peers' lattice scene
// (perf/lattice_scene.hpp), per size and thread count:
//
//   neighbors/N:<n>/threads:<t>          World::rebuild_neighbors (no reorder; history carried)
//   pair/<simd>/N:<n>/threads:<t>        the pair kernel of each SIMD architecture the CPU has,
//                                        over the whole pair list in the engine's blocks
//   bond/<simd>/N:<n>/threads:<t>        the bond kernel likewise, on the lattice with every
//                                        touching pair bonded (as `perf/lattice.lua bonded=true`:
//                                        unbreakable, beam stiffnesses kn and kn 2/7, rotation
//                                        locked by the bonds as model.md 5 says)
//   walls/N:<n>/threads:<t>              the ball-wall kernel (six planes)
//   gather_integrate/N:<n>/threads:<t>   the fused gather + leapfrog stage
//   step/N:<n>/threads:<t>               World::cycle(1): one whole step
//   omp_parallel_for/threads:<t>         fork/join of one empty parallel loop (per-stage overhead)
//   triad/MB:<m>/threads:<t>             STREAM triad: the machine's cache / memory bandwidth
//
// Counters: `particle_steps` (per second: particles x iterations / time; for the pair kernel this
// is the pair stage's share of a particle-step) and `pairs` where it applies.
//
// Default run: N = 1e4 and 1e5, 1 and 2 threads (about a minute). The full sweep
// N = 1e3 .. 1e6: `bench_stages --full`. Filter as usual, e.g.
//   bench_stages --full --benchmark_filter='pair/.*/N:1000000/'
// The scene is built once per (size, benchmark kind) and reused across thread counts.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "asperity/world.hpp"
#include "core/aligned.hpp"
#include "kernels/kernels.hpp"
#include "lattice_scene.hpp"
#include "stages/bonds.hpp"
#include "stages/integrate.hpp"
#include "stages/pairs.hpp"
#include "stages/walls.hpp"
#include "neighbor/build.hpp"
#include "state.hpp"
#include "step.hpp"

namespace {

using asperity::World;
using namespace asperity::detail;

// One scene per edge size, rebuilt when the size changes (so a 1e6 sweep holds one at a time).
struct SceneCache {
  int n = -1;
  std::string kind;
  std::unique_ptr<World> world;
  World& get(int edge, const std::string& k) {
    if (edge != n || k != kind) {
      world.reset();
      asperity::perf::LatticeOptions o;
      o.n = edge;
      o.threads = 1;
      o.reorder_interval = 0;  // stages are timed on the creation order; see perf/README.md
      world = std::make_unique<World>(asperity::perf::make_lattice(o));
      if (k == "bond") asperity::perf::bond_lattice(*world);
      world->cycle(2);  // neighbour list, wall contacts, history, dt estimate in place
      n = edge;
      kind = k;
    }
    return *world;
  }
};
SceneCache cache;

// One stage on its own, run as the step runs its stages (run_stages).
void run_stage(State& s, StageLoop st) { run_stages(s, {&st}); }

void set_counters(benchmark::State& st, std::size_t particles, std::size_t pairs) {
  st.counters["particle_steps"] =
      benchmark::Counter(double(particles) * double(st.iterations()), benchmark::Counter::kIsRate);
  if (pairs)
    st.counters["pairs"] =
        benchmark::Counter(double(pairs) * double(st.iterations()), benchmark::Counter::kIsRate);
}

void bm_neighbors(benchmark::State& st, int edge, int threads) {
  World& w = cache.get(edge, "neighbors");
  w.set_threads(threads);
  for (auto _ : st) w.rebuild_neighbors();
  set_counters(st, w.particle_count(), w.stats().pairs);
}

// A list kernel over `total` entries in the engine's blocks of kPairBlock (as stages/pairs.cpp
// and stages/bonds.cpp run it), timed with `threads` threads.
template <class Kernel, class Args>
void time_blocks(benchmark::State& st, int threads, Kernel kernel, const Args& k, std::size_t total) {
  const std::size_t blocks = (total + kPairBlock - 1) / kPairBlock;
  std::vector<decltype(kernel(k, 0, 0))> out(blocks);
  for (auto _ : st) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t blk = 0; blk < blocks; ++blk) {
      const std::size_t begin = blk * kPairBlock;
      out[blk] = kernel(k, begin, std::min(total, begin + kPairBlock));
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

// The pair stage with the kernel set of a given name.
void bm_pair(benchmark::State& st, int edge, int threads, std::string simd) {
  World& w = cache.get(edge, "pair");
  State& s = w.state();
  const auto& ks = asperity::kernels::select_kernels(simd);
  time_blocks(st, threads, ks.pair, pair_kernel_args(pair_view(s)), s.pairs.padded);
  set_counters(st, w.particle_count(), s.pairs.n);
  st.SetLabel(ks.name);
}

// The bond stage likewise.
void bm_bond(benchmark::State& st, int edge, int threads, std::string simd) {
  World& w = cache.get(edge, "bond");
  State& s = w.state();
  const auto& ks = asperity::kernels::select_kernels(simd);
  time_blocks(st, threads, s.any_rotating ? ks.bond : ks.bond_norot, bond_kernel_args(bond_view(s)),
              s.bonds.padded);
  set_counters(st, w.particle_count(), 0);
  st.counters["bonds"] =
      benchmark::Counter(double(s.bonds.n) * double(st.iterations()), benchmark::Counter::kIsRate);
  st.SetLabel(ks.name);
}

void bm_walls(benchmark::State& st, int edge, int threads) {
  World& w = cache.get(edge, "walls");
  w.set_threads(threads);
  State& s = w.state();
  for (auto _ : st) run_stage(s, wall_stage(wall_view(s)));
  set_counters(st, w.particle_count(), 0);
  st.counters["wall_contacts"] = double(s.walls.contacts.n);
}

void bm_gather(benchmark::State& st, int edge, int threads) {
  World& w = cache.get(edge, "gather");
  w.set_threads(threads);
  State& s = w.state();
  for (auto _ : st) run_stage(s, integrate_stage(integrate_view(s)));
  set_counters(st, w.particle_count(), s.pairs.n);
}

void bm_step(benchmark::State& st, int edge, int threads) {
  World& w = cache.get(edge, "step");
  w.set_threads(threads);
  for (auto _ : st) w.cycle(1);
  set_counters(st, w.particle_count(), w.stats().pairs);
}

// Fork/join of one empty `omp parallel for` as the stages use it: the fixed cost each parallel
// stage pays per step, whatever N (several per step).
void bm_omp_region(benchmark::State& st, int threads) {
  std::vector<double> sink(64, 0.0);
  for (auto _ : st) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int i = 0; i < 64; ++i) sink[i] += 1.0;
    benchmark::DoNotOptimize(sink.data());
  }
}

// STREAM-style triad a[i] = b[i] + s c[i] over three arrays of `mb` MB in total: the memory
// bandwidth the stages compete for (24 bytes counted per element: no write-allocate included, as
// STREAM reports it). 24 MB sits in this machine's L3, 768 MB does not.
void bm_triad(benchmark::State& st, std::size_t mb, int threads) {
  const std::size_t n = mb * (1u << 20) / 24;
  asperity::AVec<double> a(n), b(n, 1.0), c(n, 2.0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::size_t i = 0; i < n; ++i) a[i] = 0.0;  // first touch
  for (auto _ : st) {
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + 3.0 * pc[i];
    benchmark::ClobberMemory();
  }
  st.SetBytesProcessed(std::int64_t(st.iterations()) * std::int64_t(n) * 24);
}

void register_all(bool full) {
  for (std::size_t mb : {24, 768})
    for (int t : {1, 2})
      benchmark::RegisterBenchmark(("triad/MB:" + std::to_string(mb) + "/threads:" + std::to_string(t)).c_str(),
                                   [mb, t](benchmark::State& st) { bm_triad(st, mb, t); })
          ->UseRealTime()->Unit(benchmark::kMillisecond);
  for (int t : {1, 2})
    benchmark::RegisterBenchmark(("omp_parallel_for/threads:" + std::to_string(t)).c_str(),
                                 [t](benchmark::State& st) { bm_omp_region(st, t); })
        ->UseRealTime();
  // Edge sizes: 10^3 = 1e3, 22^3 ~ 1.06e4, 46^3 ~ 0.97e5, 100^3 = 1e6.
  const std::vector<int> edges = full ? std::vector<int>{10, 22, 46, 100} : std::vector<int>{22, 46};
  const std::vector<int> threads = {1, 2};
  const auto archs = asperity::available_simd_architectures();
  for (int e : edges) {
    const std::string sz = "/N:" + std::to_string(e * e * e);
    auto reg = [&](const std::string& name, auto fn) {
      for (int t : threads) {
        auto* b = benchmark::RegisterBenchmark((name + sz + "/threads:" + std::to_string(t)).c_str(),
                                               [=](benchmark::State& st) { fn(st, e, t); });
        b->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(full ? 0.5 : 0.2);
      }
    };
    reg("neighbors", bm_neighbors);
    for (const auto& a : archs)
      reg("pair/" + a, [a](benchmark::State& st, int e2, int t) { bm_pair(st, e2, t, a); });
    for (const auto& a : archs)
      reg("bond/" + a, [a](benchmark::State& st, int e2, int t) { bm_bond(st, e2, t, a); });
    reg("walls", bm_walls);
    reg("gather_integrate", bm_gather);
    reg("step", bm_step);
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool full = false;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--full") == 0) full = true;
    else args.push_back(argv[i]);
  }
  int n = int(args.size());
  register_all(full);
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  benchmark::AddCustomContext("simd_available", [] {
    std::string s;
    for (const auto& a : asperity::available_simd_architectures()) s += (s.empty() ? "" : ",") + a;
    return s;
  }());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
