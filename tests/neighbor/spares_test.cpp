// A neighbour build, a reorder and a break step's merge write their lists into the stores the
// last one replaced (Caches::spare_pairs, spare_wall_contacts, found lists; neighbor/build.cpp,
// keep_spares): what those held before must never reach a result.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "neighbor/build.hpp"
#include "scenes.hpp"
#include "state.hpp"

using namespace asperity;

namespace {
// Spheres falling into a box on a still, bumpy mould (planes and a mesh: both wall lists), their
// radii grown then shrunk as a genesis does (the lists grow past their spares' sizes, then fall
// below half of them), reordered every other build, with breakable bonds installed half-way (break
// steps merge freed pairs through the spare pair store).
World mould_scene() {
  WorldSettings ws;
  ws.reorder_interval = 2;
  World w = test::random_box(900, ws, 7, 1.5e-3);
  test::add_bumpy_mould(w, 40);
  return w;
}
}  // namespace

TEST(Spares, ListsWrittenIntoTheLastListsStoresGiveTheRunFreshStoresGive) {
  auto run = [](bool fresh, std::vector<std::vector<double>>& states, std::size_t& reused_builds) {
    World w = mould_scene();
    detail::State& s = w.state();
    reused_builds = 0;
    auto step = [&](int steps) {
      for (int k = 0; k < steps; ++k) {
        const std::uint64_t builds = s.rebuilds;
        const bool spare_ready = s.cache.spare_pairs.a.capacity() > 0 && s.cache.spare_wall_contacts.particle.capacity() > 0;
        w.cycle(1);
        if (s.rebuilds > builds && spare_ready) ++reused_builds;
        if (fresh) detail::release_spares(s);  // every list written into new stores
      }
      states.push_back(w.positions());
      states.push_back(w.velocities());
      for (const auto* c : {&s.p.wx, &s.p.wy, &s.p.wz}) states.emplace_back(c->begin(), c->begin() + std::ptrdiff_t(s.p.n));
      states.push_back(w.forces());
      states.push_back({w.energies().friction, w.energies().strain, w.wall_force(6).z});
    };
    for (int stage = 0; stage < 6; ++stage) {  // grown by 12 %
      w.scale_radii(1.02);
      step(150);
    }
    BondMaterial bonds;
    bonds.tensile_strength = 2e-3;  // Pa: weak, so that the falling spheres break some
    w.install_bonds(bonds, 1e-5);
    for (int stage = 0; stage < 6; ++stage) {  // shrunk by 30 %: the lists fall below half
      w.scale_radii(0.94);
      step(150);
    }
    EXPECT_GT(w.break_events().size(), 0u) << "break steps must merge freed pairs";
    EXPECT_GT(s.rebuilds, 40u);
    EXPECT_GT(s.reorders, 15u);
  };
  std::vector<std::vector<double>> kept, fresh;
  std::size_t reused = 0, reused_fresh = 0;
  run(false, kept, reused);
  run(true, fresh, reused_fresh);
  EXPECT_GT(reused, 30u) << "the builds must write into the last lists' stores";
  EXPECT_EQ(reused_fresh, 0u);
  ASSERT_EQ(kept.size(), fresh.size());
  for (std::size_t k = 0; k < kept.size(); ++k) EXPECT_TRUE(test::same_bits(kept[k], fresh[k])) << "record " << k;
}

// Where builds come seldom, a build releases the spares (a second list of resident memory for
// nothing); where they come often, or bonds can break, it keeps them.
TEST(Spares, ABuildKeepsItsSparesOnlyWhereBuildsComeOftenOrBondsCanBreak) {
  World w = mould_scene();
  detail::State& s = w.state();
  w.cycle(200);  // falling: builds every few steps
  w.rebuild_neighbors();
  EXPECT_GT(s.cache.spare_pairs.a.capacity(), 0u);
  EXPECT_GT(s.cache.spare_wall_contacts.particle.capacity(), 0u);
  // Then held still (no gravity, no velocity) under a skin of 2 mm: no build for thousands of steps.
  s.settings.gravity = {0, 0, 0};
  for (std::int64_t id = 0; id < std::int64_t(s.p.n); ++id) {
    w.set_velocity(id, {0, 0, 0});
    w.set_angular_velocity(id, {0, 0, 0});
  }
  w.set_skin(2e-3);
  w.rebuild_neighbors();
  const std::uint64_t builds = s.rebuilds;
  w.cycle(1200);
  ASSERT_EQ(s.rebuilds, builds);
  w.rebuild_neighbors();
  EXPECT_EQ(s.cache.spare_pairs.a.capacity(), 0u);
  EXPECT_EQ(s.cache.spare_wall_contacts.particle.capacity(), 0u);
  BondMaterial bonds;
  bonds.tensile_strength = 1e3;  // Pa: breakable, none breaks
  w.install_bonds(bonds, 1e-5);
  w.cycle(1200);
  w.rebuild_neighbors();
  EXPECT_GT(s.cache.spare_pairs.a.capacity(), 0u) << "break steps merge through the spare";
}
