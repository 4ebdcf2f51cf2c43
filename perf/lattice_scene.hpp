// The peers' lattice scene (../shared/peers/README.md), built through the public API so that every
// benchmark in perf/ measures the same thing LAMMPS, LIGGGHTS and YADE are measured on:
//
//   n^3 spheres, d = 1 mm, density 2500 kg/m^3, simple cubic lattice of spacing a = 0.99 mm with
//   centres at (i + 1/2) a, six frictional planes at 0 and L = n a (so every particle starts with
//   six 1 % overlaps, walls included), kn = 0.1 N/m, ks = kn 2/7, mu = 0.5 (walls too), no damping,
//   dt = 5e-4 s fixed, a tiny initial velocity. Skin 0.1 d, as LAMMPS's `neighbor 0.0001 bin`.
//
// Particles are created in x-fastest order, like LAMMPS's create_atoms on a lattice.
#pragma once
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "asperity/world.hpp"

namespace asperity::perf {

struct LatticeOptions {
  int n = 40;                // spheres per edge
  int threads = 1;
  std::string simd = "auto";
  int reorder_interval = 10;  // engine default
  bool track_energy = true;   // engine default
};

inline WorldSettings lattice_settings(const LatticeOptions& o) {
  WorldSettings ws;
  ws.contact.kn = 0.1;
  ws.contact.ks = 0.1 * 2.0 / 7.0;
  ws.contact.friction = 0.5;
  ws.density = 2500.0;
  ws.local_damping = 0.0;
  ws.gravity = {0, 0, 0};
  ws.rotation = true;
  ws.skin = 1e-4;
  ws.dt = 5e-4;
  ws.allow_dt_above_estimate = true;
  ws.threads = o.threads;
  ws.simd = o.simd;
  ws.track_energy = o.track_energy;
  ws.reorder_interval = o.reorder_interval;
  return ws;
}

inline World make_lattice(const LatticeOptions& o) {
  const int n = o.n;
  const double d = 1e-3, a = 0.99 * d, L = n * a, R = 0.5 * d;
  World w(lattice_settings(o));
  const std::size_t count = std::size_t(n) * n * n;
  std::vector<double> xyz;
  xyz.reserve(3 * count);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        xyz.push_back((i + 0.5) * a);
        xyz.push_back((j + 0.5) * a);
        xyz.push_back((k + 0.5) * a);
      }
  std::vector<double> radii(count, R);
  const std::int64_t first = w.add_particles(xyz, radii, 2500.0);
  // Tiny random velocity (LAMMPS: `velocity all create 1e-7 ...`, ~1e-6 m/s here): far too small
  // to trigger a neighbour rebuild within the run, as in the peers' runs.
  std::mt19937_64 rng(4928459);
  std::normal_distribution<double> g(0.0, 1e-6);
  for (std::size_t i = 0; i < count; ++i)
    w.set_velocity(first + std::int64_t(i), {g(rng), g(rng), g(rng)});
  const ContactMaterial wall{0.1, 0.1 * 2.0 / 7.0, 0.5};
  w.add_plane({0, 0, 0}, {1, 0, 0}, wall);
  w.add_plane({L, 0, 0}, {-1, 0, 0}, wall);
  w.add_plane({0, 0, 0}, {0, 1, 0}, wall);
  w.add_plane({0, L, 0}, {0, -1, 0}, wall);
  w.add_plane({0, 0, 0}, {0, 0, 1}, wall);
  w.add_plane({0, 0, L}, {0, 0, -1}, wall);
  return w;
}

// Every touching pair of a lattice bonded, unbreakable, with the REV's bond stiffnesses (as
// `perf/lattice.lua bonded=true`): the bond kernel's scene. One step first builds the neighbour
// list the bonds are installed from. The time step stays as it was (callers that step the block
// for long set it back to automatic: the peers' 5e-4 s is above its critical step).
inline void bond_lattice(World& w) {
  w.cycle(1);
  BondMaterial bm;
  bm.beam_kn = 0.1;
  bm.beam_ks = 0.1 * 2.0 / 7.0;
  bm.breakable = false;
  w.install_bonds(bm);
}

}  // namespace asperity::perf
