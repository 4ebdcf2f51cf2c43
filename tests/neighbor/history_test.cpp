// Shear history survives neighbour rebuilds exactly (model.md 6), and particle reordering does not
// change the physics.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include "scenes.hpp"
#include "state.hpp"

using namespace asperity;

TEST(History, ForcesIdenticalWithAndWithoutARebuildDuringAContact) {
  // An oblique collision of two spinning spheres: the shear force builds up, turns with the
  // contact plane and slips; a rebuild half-way through the contact must change nothing.
  auto run = [](bool rebuild) {
    WorldSettings ws;
    ws.local_damping = 0;
    ws.reorder_interval = 0;
    World w(ws);
    const auto a = w.add_particle({0, 0, 0}, 5e-4);
    const auto b = w.add_particle({0.3e-3, 0.1e-3, 1.0e-3}, 5e-4);
    w.set_velocity(b, {-1e-4, 0, -1e-3});
    w.set_angular_velocity(a, {0.5, 0.2, 1.0});
    w.set_dt(w.critical_dt() / 200);
    while (w.contact_count() == 0) w.cycle(1);
    w.cycle(100);
    if (rebuild) w.rebuild_neighbors();
    w.cycle(100);
    const auto c = w.contacts();
    EXPECT_EQ(c.size(), 1u);
    return c.empty() ? ContactInfo{} : c[0];
  };
  const ContactInfo plain = run(false), rebuilt = run(true);
  ASSERT_GT(norm(plain.shear_force), 0.0) << "the test must build up shear history";
  EXPECT_EQ(plain.shear_force, rebuilt.shear_force);
  EXPECT_EQ(plain.normal_force, rebuilt.normal_force);
  EXPECT_EQ(plain.normal, rebuilt.normal);
}

TEST(History, FrequentRebuildsGiveBitwiseTheSameTrajectory) {
  // Rebuilds add and drop non-touching pairs, whose zero contributions do not change any sum.
  // A fixed dt: the automatic one is re-estimated at each rebuild, which would differ.
  WorldSettings ws;
  ws.reorder_interval = 0;
  ws.dt = 5e-4;
  World a = test::random_box(300, ws), b = test::random_box(300, ws);
  for (int k = 0; k < 40; ++k) {
    a.cycle(50);
    b.cycle(50);
    b.rebuild_neighbors();
  }
  EXPECT_GT(b.stats().rebuilds, a.stats().rebuilds);
  const auto pa = a.positions(), pb = b.positions();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_EQ(0, std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(double)));
}

TEST(History, ReorderingKeepsThePhysics) {
  // A reorder renumbers particles (flipping pair roles and history signs where the order changes);
  // sums then run in another order, so results agree to rounding, not bitwise.
  // A granular flow is chaotic: rounding differences grow exponentially, so compare over a short
  // run that still has several rebuilds, each with a reorder.
  WorldSettings never;
  never.reorder_interval = 0;
  never.dt = 5e-4;
  WorldSettings often = never;
  often.reorder_interval = 1;
  World a = test::random_box(300, never), b = test::random_box(300, often);
  a.cycle(300);
  b.cycle(300);
  EXPECT_GE(b.stats().reorders, 3u);
  const auto pa = a.positions(), pb = b.positions();
  double worst = 0;
  for (std::size_t k = 0; k < pa.size(); ++k) worst = std::max(worst, std::fabs(pa[k] - pb[k]));
  EXPECT_LT(worst, 1e-12) << "positions agree to rounding (m)";
  EXPECT_EQ(a.contact_count(), b.contact_count());
}

// The order of the particles in memory (neighbor/build.cpp, reorder): a scene of 20 000
// particles or more is sorted by the raster order of its cells (x fastest, z slowest on a cube),
// which past the caches runs faster than the Morton curve that smaller scenes keep (their results,
// calibrations included, stay as they were). A cubic lattice created in a shuffled order, its
// spacing wider than a cell, so that no two sites share a cell and the sites' order is the
// cells' order.
namespace {
constexpr double kSpacing = 2e-3, kRadius = 0.5e-3;

World shuffled_lattice(int n) {
  std::vector<std::array<int, 3>> sites;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) sites.push_back({i, j, k});
  std::mt19937_64 rng(7);
  std::shuffle(sites.begin(), sites.end(), rng);
  std::vector<double> xyz, radii(sites.size(), kRadius);
  for (const auto& s : sites)
    for (int d = 0; d < 3; ++d) xyz.push_back((s[d] + 0.5) * kSpacing);
  WorldSettings ws;
  ws.dt = 1e-4;
  World w(ws);
  w.add_particles(xyz, radii, 2500.0);
  w.cycle(1);  // the first neighbour build reorders
  return w;
}

std::array<long, 3> site_of(const detail::ParticleStore& p, std::size_t i) {
  auto c = [](double v) { return std::lround(v / kSpacing - 0.5); };
  return {c(p.z[i]), c(p.y[i]), c(p.x[i])};
}

// Whether the particles' index order is the lexicographic order of their sites (z, y, x).
bool raster_ordered(World& w) {
  const auto& p = w.state().p;
  for (std::size_t i = 1; i < p.n; ++i)
    if (site_of(p, i) < site_of(p, i - 1)) return false;
  return true;
}
}  // namespace

TEST(History, LargeScenesAreOrderedByTheRasterOfTheirCells) {
  World big = shuffled_lattice(28);  // 21 952 particles
  ASSERT_GE(big.stats().reorders, 1u);
  EXPECT_TRUE(raster_ordered(big));
  World small = shuffled_lattice(20);  // 8 000: the Morton curve, which starts at the corner
  ASSERT_GE(small.stats().reorders, 1u);
  EXPECT_FALSE(raster_ordered(small));
  EXPECT_EQ(site_of(small.state().p, 0), (std::array<long, 3>{0, 0, 0}));
  EXPECT_EQ(site_of(small.state().p, 1), (std::array<long, 3>{0, 0, 1}));  // then +x
}

// With rigid groups the reorder puts free particles first, then members, then inert members, each
// class along the curve: blocks of members hold no free particle to integrate.
TEST(History, TheReorderPutsFreeParticlesBeforeGroupMembersAndInertOnesLast) {
  WorldSettings ws;
  ws.dt = 1e-4;
  World w(ws);
  std::vector<double> xyz, radii;
  std::vector<std::int64_t> top, deep;
  std::mt19937 rng(3);
  std::vector<std::array<int, 3>> sites;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) sites.push_back({x, y, z});
  std::shuffle(sites.begin(), sites.end(), rng);
  for (const auto& s : sites) {
    for (int d = 0; d < 3; ++d) xyz.push_back((s[d] + 0.5) * kSpacing);
    radii.push_back(0.45 * kSpacing);
  }
  const std::int64_t first = w.add_particles(xyz, radii, 2500.0);
  for (std::int64_t id = first; id < first + std::int64_t(sites.size()); ++id) {
    const auto& s = sites[std::size_t(id - first)];
    if (s[2] >= 6) top.push_back(id);               // the two top layers: a platen
    if (s[2] == 7 && s[0] < 4) deep.push_back(id);  // half of its top layer inert
  }
  w.add_group(top, GroupMotion{{Dof::fixed, Dof::fixed, Dof::fixed}});
  w.set_inert(deep);
  w.cycle(1);  // the first neighbour build reorders
  ASSERT_GE(w.stats().reorders, 1u);
  const auto& p = w.state().p;
  auto klass = [&](std::size_t i) { return p.inert[i] ? 2 : p.group[i] >= 0 ? 1 : 0; };
  std::size_t counts[3] = {0, 0, 0};
  for (std::size_t i = 0; i < p.n; ++i) {
    ++counts[klass(i)];
    if (i > 0) {
      ASSERT_LE(klass(i - 1), klass(i)) << "index " << i;
    }
  }
  EXPECT_EQ(counts[0], 384u);
  EXPECT_EQ(counts[1], 128u - 32u);
  EXPECT_EQ(counts[2], 32u);
}
