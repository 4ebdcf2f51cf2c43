// One build of the engine as a loadable module, for perf/ab_lattice.cpp: two such modules, built
// from two source trees (perf/ab.sh), run the lattice scene in one process, alternated every few
// steps, so the machine's drift (other tenants, clock) hits both alike. Separate processes on the
// shared development machine differ by up to 2x within minutes (perf/README.md), which buries the
// 5-20 % a kernel change is worth.
//
// Only a C interface is exported (the build hides every other symbol), so the two modules' engines,
// with the same C++ names, never see each other.
#include <cstdlib>
#include <cstring>
#include <memory>

#include "lattice_scene.hpp"
#include "state.hpp"

namespace {
struct Run {
  asperity::World world;
};
}  // namespace

extern "C" {

// ASPERITY_AB_BONDED=1 in the environment: every touching pair bonded, unbreakable, as
// `perf/lattice.lua bonded=true` (the bond kernel's scene), with the automatic time step.
// ASPERITY_AB_WORLD=FILE: instead of the lattice, the world of a checkpoint (say the joint in
// mid-shear, `scripts/joint.lua shear=0.1 save=FILE`), which continues as the saved run would;
// with ASPERITY_AB_REORDER=1 renumbered first by the module's own reorder.
__attribute__((visibility("default"))) void* asperity_ab_make(int n, int threads) {
  if (const char* file = std::getenv("ASPERITY_AB_WORLD"); file && *file) {
    auto* run = new Run{asperity::World::load(file, threads)};
    // ASPERITY_AB_REORDER=1: renumber the loaded world now, as each module's build would order it
    // (a saved world keeps the order of the build that saved it).
    if (const char* r = std::getenv("ASPERITY_AB_REORDER"); r && std::strcmp(r, "1") == 0) {
      run->world.state().force_reorder = true;
      run->world.rebuild_neighbors();
    }
    return run;
  }
  asperity::perf::LatticeOptions o;
  o.n = n;
  o.threads = threads;
  auto* run = new Run{asperity::perf::make_lattice(o)};
  const char* bonded = std::getenv("ASPERITY_AB_BONDED");
  if (bonded && std::strcmp(bonded, "1") == 0) {
    asperity::perf::bond_lattice(run->world);
    run->world.set_dt(0);
  }
  return run;
}

__attribute__((visibility("default"))) void asperity_ab_cycle(void* run, long steps) {
  static_cast<Run*>(run)->world.cycle(std::uint64_t(steps));
}

__attribute__((visibility("default"))) long asperity_ab_particles(void* run) {
  return long(static_cast<Run*>(run)->world.particle_count());
}

// A digest of every position (their bits, in id order): equal digests after the same steps mean
// the two builds computed the same trajectory bit for bit.
__attribute__((visibility("default"))) unsigned long long asperity_ab_digest(void* run) {
  unsigned long long h = 1469598103934665603ull;  // FNV-1a over the bytes
  for (double v : static_cast<Run*>(run)->world.positions()) {
    unsigned char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  }
  return h;
}

__attribute__((visibility("default"))) void asperity_ab_free(void* run) {
  delete static_cast<Run*>(run);
}

}  // extern "C"
