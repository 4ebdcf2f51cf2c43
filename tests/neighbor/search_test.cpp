// The neighbour search (model.md 6) lists exactly the pairs a check of every pair finds.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "state.hpp"

using namespace asperity;

// A polydisperse cloud (radii 0.2 to 0.8 mm, overlapping at random) with two rigid groups, inert
// members, bonds and a few particles far out, which make the grid's cells grow past their least
// size: the list holds i < j with neither inert, not of one group, not bonded, and
// |xj - xi|^2 < (Ri + skin + Rj)^2 (that rounding), on every kernel set, and nothing else.
TEST(Search, ListsExactlyThePairsACheckOfEveryPairFinds) {
  std::vector<std::string> sets{"scalar"};
  for (const auto& arch : available_simd_architectures()) sets.push_back(arch);
  for (bool far_out : {false, true})
    for (const auto& arch : sets) {
      WorldSettings ws;
      ws.simd = arch;
      ws.dt = 1e-6;
      ws.skin = 1e-4;
      World w(ws);
      std::mt19937_64 rng(5);
      std::uniform_real_distribution<double> u(0, 1);
      std::vector<double> xyz, radii;
      const int n = 3000;
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < 3; ++d) xyz.push_back(0.02 * u(rng));
        radii.push_back(2e-4 + 6e-4 * u(rng));
      }
      if (far_out)
        for (double d : {0.4, -0.3, 0.25}) {
          xyz.insert(xyz.end(), {d, 0.01, 0.01});
          radii.push_back(5e-4);
        }
      const std::int64_t first = w.add_particles(xyz, radii, 2500.0);
      std::vector<std::int64_t> low, high, deep;
      for (std::int64_t id = first; id < first + n; ++id) {
        const auto c = w.position(id);
        if (c.z < 0.003) low.push_back(id);
        if (c.z > 0.017) (c.x < 0.005 ? deep : high).push_back(id);
      }
      w.add_group(low, GroupMotion{{Dof::fixed, Dof::fixed, Dof::fixed}});
      std::vector<std::int64_t> top = high;
      top.insert(top.end(), deep.begin(), deep.end());
      w.add_group(top, GroupMotion{{Dof::fixed, Dof::fixed, Dof::fixed}});
      w.set_inert(deep);
      w.rebuild_neighbors();
      BondMaterial bm;
      bm.breakable = false;
      ASSERT_GT(w.install_bonds(bm, 0.0), 1000u);  // the touching pairs
      w.rebuild_neighbors();

      const auto& s = w.state();
      const auto& p = s.p;
      std::set<std::pair<std::int64_t, std::int64_t>> bonded;
      detail::for_each_bond(s, [&](const detail::BondStore& q, std::size_t k) {
        bonded.insert(std::minmax(q.a[k], q.b[k]));
      });
      std::vector<std::pair<std::int64_t, std::int64_t>> want, got;
      for (std::size_t i = 0; i < p.n; ++i)
        for (std::size_t j = i + 1; j < p.n; ++j) {
          if (p.inert[i] || p.inert[j]) continue;
          if (p.group[i] >= 0 && p.group[i] == p.group[j]) continue;
          if (bonded.count({std::int64_t(i), std::int64_t(j)})) continue;
          const double dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i], dz = p.z[j] - p.z[i];
          const double cut = p.radius[i] + s.skin + p.radius[j];
          if (dx * dx + dy * dy + dz * dz < cut * cut) want.emplace_back(i, j);
        }
      for (std::size_t k = 0; k < s.pairs.n; ++k) got.emplace_back(s.pairs.a[k], s.pairs.b[k]);
      EXPECT_GT(want.size(), 300u);  // besides the bonded ones: contacts and pairs within the skin
      if (far_out) {
        EXPECT_GT(s.cache.grid.cell, 2.5 * (8e-4 + s.skin)) << "cells grown";
      }
      EXPECT_EQ(got, want) << arch << (far_out ? ", particles far out" : "");
    }
}
