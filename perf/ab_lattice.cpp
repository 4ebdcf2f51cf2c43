// In-process A/B of two engine builds on the peers' lattice scene (perf/ab.sh builds them):
//
//   build/perf/ab_lattice A/libasperity_ab.so B/libasperity_ab.so n=40 rounds=30 steps=10
//   build/perf/ab_lattice A.so A.so n=22 nb=100   # one build, cost per particle-step against size
//   build/perf/ab_lattice A.so A.so n=30 bonded_b=1   # one build, the bonded block against the lattice
//   build/perf/ab_lattice A.so A.so threads=1 threads_b=2   # one build, 1 -> 2 threads in one process
//   ASPERITY_AB_WORLD=out/joint_state.h5 build/perf/ab_lattice A.so B.so threads=2 warmup=50
//                                         # a saved world instead of the lattice (the joint's shear)
//
// Both modules build the scene; then `rounds` times each runs `steps` steps, in alternating order,
// each timed on the wall clock. Printed: per build the best and median ns per particle-step, the
// median of the per-round ratios B/A (the figure to quote: both halves of a round saw the same
// machine), and whether the two trajectories are bitwise the same (a digest of every position).
#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct Module {
  void* (*make)(int, int);
  void (*cycle)(void*, long);
  long (*particles)(void*);
  unsigned long long (*digest)(void*);
  void (*free)(void*);
  void* run = nullptr;
};

template <class F>
void bind(void* lib, const char* path, const char* name, F& f) {
  f = reinterpret_cast<F>(dlsym(lib, name));
  if (!f) {
    std::fprintf(stderr, "ab_lattice: %s has no symbol %s (not built by perf/ab.sh?)\n", path, name);
    std::exit(2);
  }
}

Module load(const char* path) {
  void* lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    std::fprintf(stderr, "ab_lattice: cannot load %s: %s\n", path, dlerror());
    std::exit(2);
  }
  Module m;
  bind(lib, path, "asperity_ab_make", m.make);
  bind(lib, path, "asperity_ab_cycle", m.cycle);
  bind(lib, path, "asperity_ab_particles", m.particles);
  bind(lib, path, "asperity_ab_digest", m.digest);
  bind(lib, path, "asperity_ab_free", m.free);
  return m;
}

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "ab_lattice: %s\nusage: ab_lattice A.so B.so [n=40] [nb=n] [rounds=30] [steps=10] "
               "[warmup=200] [threads=1] [threads_b=threads] [bonded_b=0]\n",
               why);
  std::exit(2);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) usage("two modules are needed");
  long n = 40, nb = 0, rounds = 30, steps = 10, warmup = 200, threads = 1, threads_b = 0, bonded_b = 0;
  for (int i = 3; i < argc; ++i) {
    const char* eq = std::strchr(argv[i], '=');
    if (!eq) usage((std::string("expected key=value, got ") + argv[i]).c_str());
    const std::string key(argv[i], std::size_t(eq - argv[i]));
    char* end = nullptr;
    const long v = std::strtol(eq + 1, &end, 10);
    if (*end || v < 1) usage((std::string("not a positive integer: ") + argv[i]).c_str());
    if (key == "n") n = v;
    else if (key == "nb") nb = v;
    else if (key == "rounds") rounds = v;
    else if (key == "steps") steps = v;
    else if (key == "warmup") warmup = v;
    else if (key == "threads") threads = v;
    else if (key == "threads_b") threads_b = v;
    else if (key == "bonded_b") bonded_b = v;
    else usage((std::string("unknown key ") + key).c_str());
  }
  if (nb == 0) nb = n;
  if (threads_b == 0) threads_b = threads;
  Module m[2] = {load(argv[1]), load(argv[2])};
  for (int v = 0; v < 2; ++v) {
    // bonded_b=1: A the plain lattice, B bonded (ab_module.cpp reads the variable when it makes
    // a scene): the bonded block's throughput against the lattice's, in one process.
    if (bonded_b) {
      if (v == 1) setenv("ASPERITY_AB_BONDED", "1", 1);
      else unsetenv("ASPERITY_AB_BONDED");
    }
    m[v].run = m[v].make(int(v ? nb : n), int(v ? threads_b : threads));
    m[v].cycle(m[v].run, warmup);
  }
  // nb != n (the same build twice, say): cost per particle-step against size in one process; B
  // runs about as many particle-steps per round as A.
  const double particles[2] = {double(m[0].particles(m[0].run)), double(m[1].particles(m[1].run))};
  // A module older than ASPERITY_AB_WORLD builds the lattice instead: refuse to compare the two.
  if (nb == n && !bonded_b && particles[0] != particles[1]) {
    std::fprintf(stderr, "ab_lattice: the two modules made different scenes (%.0f and %.0f particles): "
                 "does each know ASPERITY_AB_WORLD?\n", particles[0], particles[1]);
    return 2;
  }
  const long count[2] = {steps, std::max(1L, long(double(steps) * particles[0] / particles[1] + 0.5))};
  std::vector<double> t[2], ratio;
  using Clock = std::chrono::steady_clock;
  for (long r = 0; r < rounds; ++r) {
    double s[2];
    for (int k = 0; k < 2; ++k) {
      const int v = (r % 2) ? 1 - k : k;  // A first in even rounds, B first in odd ones
      const auto t0 = Clock::now();
      m[v].cycle(m[v].run, count[v]);
      s[v] = std::chrono::duration<double>(Clock::now() - t0).count() / (particles[v] * double(count[v]));
      t[v].push_back(1e9 * s[v]);
    }
    ratio.push_back(s[1] / s[0]);
  }
  const char* world = std::getenv("ASPERITY_AB_WORLD");
  if (world && *world)
    std::printf("world %s, %.0f particles, %ld rounds of %ld steps, %ld thread(s)\n", world,
                particles[0], rounds, steps, threads);
  else
    std::printf("lattice n=%ld, %.0f particles, %ld rounds of %ld steps, %ld thread(s)\n", n,
                particles[0], rounds, steps, threads);
  if (threads_b != threads)
    std::printf("B: %ld thread(s): the same scene on another thread count, whose trajectory must not "
                "differ\n", threads_b);
  if (nb != n || bonded_b)
    std::printf("B: lattice n=%ld%s, %.0f particles, %ld steps a round\n", nb, bonded_b ? " bonded" : "",
                particles[1], count[1]);
  for (int v = 0; v < 2; ++v)
    std::printf("%s: best %.2f, median %.2f ns/particle-step  (%s)\n", v ? "B" : "A",
                *std::min_element(t[v].begin(), t[v].end()), median(t[v]), argv[1 + v]);
  std::printf("B/A time per particle-step: median of the rounds' ratios %.3f (quartiles %.3f-%.3f)\n", median(ratio),
              [&] { auto q = ratio; std::sort(q.begin(), q.end()); return q[q.size() / 4]; }(),
              [&] { auto q = ratio; std::sort(q.begin(), q.end()); return q[(3 * q.size()) / 4]; }());
  if (nb == n && !bonded_b) {
    const bool same = m[0].digest(m[0].run) == m[1].digest(m[1].run);
    std::printf("trajectories: %s\n", same ? "bitwise the same" : "DIFFERENT");
  }
  for (Module& x : m) x.free(x.run);
  return 0;
}
