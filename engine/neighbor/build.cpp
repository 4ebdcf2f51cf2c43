// Neighbour search (model.md 6): linked cells, a Verlet list with a skin, history carried across
// rebuilds, and a periodic reorder of the particles along a Morton curve (in large scenes: the
// raster order of their cells).
//
// Design notes
// - Pairs are keyed by current indices (a < b) and kept sorted. Between two rebuilds without a
//   reorder the indices do not change, so the old and new sorted lists merge in one linear walk
//   and every surviving pair gets its normal and shear force back exactly. A reorder renumbers the
//   old list first (swapping a and b, and negating the history vectors, where the order flips)
//   and re-sorts it. This keeps the pair list in the particles' memory order (good locality for
//   the gathers) while carrying history as exactly as keying by stable ids would.
// - The list is built particle by particle (each particle i lists its j > i in its 27 cells,
//   sorted), counted first and filled second, so it is the same for any thread count. The grid
//   keeps a copy of the binned centres and radii in cell order, in which the three cells of a row
//   are one contiguous run: a kernel tests a particle's nine rows a batch at a time.
// - Pairs of two members of one rigid group are never listed.
// - The reorder sorts the particles by cell along a Morton (Z-order) curve, or, in scenes of
//   kRasterFrom particles and more, in the raster order of the cells (one axis fastest, then the
//   next, the longest axis slowest). Past the caches the kernels read the particle columns as
//   streams, and in raster order a particle's neighbours ahead of it (+1 cell, +1 row, +1 plane)
//   advance with it as three sequential streams, which the hardware prefetchers follow; a Morton
//   curve keeps more neighbours close but jumps across its block boundaries, and a Hilbert curve
//   never jumps but turns every few cells. Smaller scenes keep the Morton order: in cache the
//   order makes little difference, and any other order changes the rounding of every sum, and
//   with it the packings and the calibrations made with them (the REV of materials.lua would
//   pack differently).
// - Rigid-group members follow the free particles, and inert members come last (each class along
//   the curve): blocks of members then hold nothing to integrate. Scenes without groups (every
//   packing, the lattice) keep the curve's order alone.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "bodies/groups.hpp"
#include "bodies/mesh.hpp"
#include "core/aligned.hpp"
#include "neighbor/build.hpp"
#include "neighbor/topology.hpp"
#include "state.hpp"

namespace asperity::detail {

namespace {

// The cells of the particles as they are now, written into g (its columns keep their pages).
void make_grid(const ParticleStore& p, double skin, std::uint64_t step, CellGrid& g) {
  const std::size_t n = p.n;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.inert[i]) continue;
    const double c[3] = {p.x[i], p.y[i], p.z[i]};
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], c[d]);
      hi[d] = std::max(hi[d], c[d]);
    }
    rmax = std::max(rmax, p.radius[i]);
  }
  // A runaway particle (the health check stops the step that makes a position non-finite, but
  // a finite one may still be far out) must not make the extent overflow: the loop below would
  // then grow the cells forever.
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(hi[d] - lo[d])) {
      std::size_t far = 0;
      double worst = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const double c[3] = {p.x[i], p.y[i], p.z[i]};
        if (!p.inert[i] && !(std::fabs(c[d]) <= worst)) worst = std::fabs(c[d]), far = i;
      }
      throw HealthError("neighbour search: particles spread over a non-finite extent (a runaway "
                        "particle)", step, p.id[far], "position", worst);
    }
  // Cell edge >= the largest Ra + Rb + skin, so a pair within reach is in adjacent cells.
  g.cell = std::max(2 * rmax + skin, 1e-12);
  // A sparse scene would make the grid huge: grow the cells until there are at most ~2 per
  // particle (the search stays correct with larger cells, only less selective).
  auto dims = [&](double cell, int d) {
    return static_cast<int>(std::min(1e6, std::floor((hi[d] - lo[d]) / cell) + 1));
  };
  if (lo[0] > hi[0]) lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;  // nothing to bin
  while (double(dims(g.cell, 0)) * dims(g.cell, 1) * dims(g.cell, 2) > 2.0 * double(n) + 64)
    g.cell *= 1.26;
  g.ox = lo[0];
  g.oy = lo[1];
  g.oz = lo[2];
  g.nx = dims(g.cell, 0);
  g.ny = dims(g.cell, 1);
  g.nz = dims(g.cell, 2);
  const std::size_t cells = std::size_t(g.nx) * g.ny * g.nz;
  g.cell_of.resize(n);
  g.start.assign(cells + 1, 0);
  // Inert particles (interior of a rigid body) are not binned at all.
  std::size_t binned = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.inert[i]) {
      g.cell_of[i] = -1;
      continue;
    }
    int a, b, c;
    g.coords(p.x[i], p.y[i], p.z[i], a, b, c);
    g.cell_of[i] = static_cast<std::int32_t>((std::size_t(c) * g.ny + b) * g.nx + a);
    ++g.start[g.cell_of[i] + 1];
    ++binned;
  }
  std::partial_sum(g.start.begin(), g.start.end(), g.start.begin());
  g.members.resize(binned + kMaxLanes);
  std::vector<std::int32_t> fill(g.start.begin(), g.start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (g.cell_of[i] >= 0) g.members[fill[g.cell_of[i]]++] = std::int32_t(i);
  for (auto* column : {&g.mx, &g.my, &g.mz, &g.mr}) column->resize(binned + kMaxLanes);
  for (std::size_t t = 0; t < binned; ++t) {
    const auto i = std::size_t(g.members[t]);
    g.mx[t] = p.x[i];
    g.my[t] = p.y[i];
    g.mz[t] = p.z[i];
    g.mr[t] = p.radius[i];
  }
  for (std::size_t t = binned; t < binned + kMaxLanes; ++t) {
    g.mx[t] = g.my[t] = g.mz[t] = g.mr[t] = 0;
    g.members[t] = -1;
  }
  g.longest_row = 0;
  for (std::size_t row = 0; row < cells; row += std::size_t(g.nx))
    for (int m = 0; m < g.nx; ++m) {
      const std::size_t last = row + std::size_t(std::min(m + 2, g.nx - 1)) + 1;
      g.longest_row = std::max(g.longest_row, g.start[last] - g.start[row + std::size_t(m)]);
    }
  g.group_of_cell.assign(cells, -1);
  for (std::size_t c = 0; c < cells; ++c) {
    if (g.start[c] == g.start[c + 1]) continue;
    std::int32_t common = p.group[std::size_t(g.members[std::size_t(g.start[c])])];
    for (std::int32_t t = g.start[c] + 1; t < g.start[c + 1] && common >= 0; ++t)
      if (p.group[std::size_t(g.members[std::size_t(t)])] != common) common = -2;
    g.group_of_cell[c] = common;
  }
}

inline constexpr std::size_t kRasterFrom = 20000;  // particles (design notes)

std::uint64_t spread_bits(std::uint64_t v) {  // 21 bits -> every third bit
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// The axes of the raster order (design notes): slowest the one with the most cells (a plane of
// the other two is then smallest), fastest the longer of the other two (long runs); ties put z
// slowest and x fastest.
std::array<int, 3> raster_axes(const CellGrid& g) {
  const int count[3] = {g.nx, g.ny, g.nz};
  std::array<int, 3> axis{0, 1, 2};  // fastest, middle, slowest
  std::stable_sort(axis.begin(), axis.end(), [&](int u, int v) { return count[u] < count[v]; });
  // Now ascending by count (ties in x, y, z order): slowest is the last; the fastest is the
  // longer of the first two (on a tie the lower axis).
  if (count[axis[1]] > count[axis[0]]) std::swap(axis[0], axis[1]);
  return axis;
}

// A bond list renumbered by a reorder and sorted by (a, b) again; the history flips with the
// roles where a and b swap.
void renumber_bonds(BondStore& bq, const std::vector<std::int64_t>& new_index) {
  for (std::size_t k = 0; k < bq.n; ++k) {
    std::int64_t a = new_index[bq.a[k]], b = new_index[bq.b[k]];
    if (a > b) {
      std::swap(a, b);
      bq.swap_roles(k);
    }
    bq.a[k] = a;
    bq.b[k] = b;
  }
  std::vector<std::size_t> bp(bq.n);
  std::iota(bp.begin(), bp.end(), 0);
  std::sort(bp.begin(), bp.end(), [&](std::size_t u, std::size_t v) {
    return bq.a[u] != bq.a[v] ? bq.a[u] < bq.a[v] : bq.b[u] < bq.b[v];
  });
  BondStore bs;
  bs.material = bq.material;
  bs.any = bq.any;
  bs.resize(bq.n);
  for (std::size_t k = 0; k < bq.n; ++k) bs.copy_from(bq, bp[k], k);
  bq = std::move(bs);
}

// A spare that a busier phase left more than twice as large as the list now written into it
// (a genesis's pairs at its widest skin, its mould's candidates) is released first, so that the
// next phases do not carry that phase's memory.
void release_if_oversized(PairStore& q, std::size_t pairs) {
  if (q.a.capacity() > 2 * round_up(pairs, kMaxLanes)) q = PairStore();
}
void release_if_oversized(WallContacts& w, std::size_t contacts) {
  if (w.particle.capacity() > 2 * contacts) w = WallContacts();
}

// Renumber particles along the Morton curve of their cells, or in their raster order in large
// scenes (design notes), stable within a cell, and every index that refers to them.
void reorder(State& s, const CellGrid& g) {
  ParticleStore& p = s.p;
  const std::size_t n = p.n;
  const bool raster = n >= kRasterFrom;
  const std::array<int, 3> axis = raster_axes(g);
  const std::uint64_t count[3] = {std::uint64_t(g.nx), std::uint64_t(g.ny), std::uint64_t(g.nz)};
  auto cell_code = [&](const std::uint64_t (&c)[3]) {
    if (!raster) return spread_bits(c[0]) | spread_bits(c[1]) << 1 | spread_bits(c[2]) << 2;
    return (c[axis[2]] * count[axis[1]] + c[axis[1]]) * count[axis[0]] + c[axis[0]];
  };
  std::vector<std::uint64_t> code(n);
  for (std::size_t i = 0; i < n; ++i) {
    int a, b, c;
    g.coords(p.x[i], p.y[i], p.z[i], a, b, c);
    code[i] = cell_code({std::uint64_t(a), std::uint64_t(b), std::uint64_t(c)});
  }
  // Free particles first, then rigid-group members, then inert ones, each class along the curve:
  // a block of members or inert particles then holds no free particle, so the integration skips
  // it and its gather visits only the busy members (bodies/groups.cpp, split_idle). Without
  // groups every particle is in the first class and the order is the curve's alone.
  std::vector<std::uint8_t> klass(n, 0);
  for (std::size_t i = 0; i < n; ++i) klass[i] = p.inert[i] ? 2 : p.group[i] >= 0 ? 1 : 0;
  std::vector<std::int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t u, std::int32_t v) {
    return klass[u] != klass[v] ? klass[u] < klass[v] : code[u] < code[v];
  });
  std::vector<std::int64_t> new_index(p.capacity);
  std::iota(new_index.begin(), new_index.end(), 0);  // null particles keep their place
  for (std::size_t i = 0; i < n; ++i) new_index[order[i]] = std::int64_t(i);
  p.permute(order);

  // Old pairs: renumber, keep a < b (flip the history with the roles), re-sort.
  PairStore& q = s.pairs;
  std::vector<std::size_t> perm(q.n);
  for (std::size_t k = 0; k < q.n; ++k) {
    std::int64_t a = new_index[q.a[k]], b = new_index[q.b[k]];
    if (a > b) {
      std::swap(a, b);
      q.swap_roles(k);
    }
    q.a[k] = a;
    q.b[k] = b;
  }
  std::iota(perm.begin(), perm.end(), 0);
  std::sort(perm.begin(), perm.end(), [&](std::size_t u, std::size_t v) {
    return q.a[u] != q.a[v] ? q.a[u] < q.a[v] : q.b[u] < q.b[v];
  });
  PairStore& sorted = s.cache.spare_pairs;
  release_if_oversized(sorted, q.n);
  sorted.resize(q.n);
  for (std::size_t k = 0; k < q.n; ++k) {
    const std::size_t o = perm[k];
    sorted.a[k] = q.a[o]; sorted.b[k] = q.b[o];
    sorted.copy_history(q, o, k);
  }
  std::swap(q, sorted);

  // Wall contacts: renumber and re-sort by (particle, wall, facet).
  WallContacts& w = s.walls.contacts;
  for (std::size_t k = 0; k < w.n; ++k) w.particle[k] = std::int32_t(new_index[w.particle[k]]);
  std::vector<std::size_t> wp(w.n);
  std::iota(wp.begin(), wp.end(), 0);
  std::sort(wp.begin(), wp.end(), [&](std::size_t u, std::size_t v) {
    return std::tie(w.particle[u], w.wall[u], w.facet[u]) <
           std::tie(w.particle[v], w.wall[v], w.facet[v]);
  });
  WallContacts& ws = s.cache.spare_wall_contacts;
  release_if_oversized(ws, w.n);
  ws.resize(w.n);
  const bool distances = w.distance.size() == w.n;
  for (std::size_t k = 0; k < w.n; ++k) {
    const std::size_t o = wp[k];
    ws.particle[k] = w.particle[o]; ws.wall[k] = w.wall[o]; ws.facet[k] = w.facet[o];
    WallContacts::history_columns([&](const ColumnInfo&, auto& to, const auto& from) { to[k] = from[o]; }, ws, w);
    ws.distance[k] = distances ? w.distance[o] : 0.0;  // 0: unknown, never skips (WallContacts)
  }
  std::swap(w, ws);

  // Bonds, active and frozen: the same renumbering; the history flips with the roles.
  renumber_bonds(s.bonds, new_index);
  renumber_bonds(s.frozen_bonds, new_index);
  // Inherited contacts of broken bonds: renumber (sorted when merged).
  PairStore& ih = s.inherited;
  for (std::size_t k = 0; k < ih.n; ++k) {
    std::int64_t a = new_index[ih.a[k]], b = new_index[ih.b[k]];
    if (a > b) {
      std::swap(a, b);
      ih.swap_roles(k);
    }
    ih.a[k] = a;
    ih.b[k] = b;
  }
  for (auto& grp : s.groups) {
    for (auto* list : {&grp.members, &grp.inert}) {
      for (auto& m : *list) m = std::int32_t(new_index[m]);
      std::sort(list->begin(), list->end());
    }
  }
  refresh_bond_topology(s);
  ++s.reorders;
}

inline bool bonded(const State& s, std::size_t i, std::int32_t o) {
  if (s.cache.partners.empty()) return false;
  const auto first = s.cache.partners.begin() + s.cache.partner_start[i];
  const auto last = s.cache.partners.begin() + s.cache.partner_start[i + 1];
  return first != last && std::binary_search(first, last, o);
}

// The j > i within reach of particle i, in the order of its cells (the caller sorts them). The
// three cells of a row are adjacent in `members`, so each row is one run (less the cells that
// hold only i's own group), which the kernel reads as columns: dx^2 + dy^2 + dz^2 < (Ri + skin +
// Rj)^2 with d = xj - xi, the test of every search before, so the list is the same. Only its few
// hits (bonded partners touch: they are among them) ask for the group and the partners. `hits`
// has room for nine rows (CellGrid::longest_row).
template <class Out>
void neighbours_of(const State& s, const CellGrid& g, std::size_t i, std::int32_t* hits, Out&& out) {
  const ParticleStore& p = s.p;
  if (p.inert[i]) return;
  int ci, cj, ck;
  g.coords(p.x[i], p.y[i], p.z[i], ci, cj, ck);
  const std::int32_t gi = p.group[i];
  auto own = [&](std::size_t cell) { return gi >= 0 && g.group_of_cell[cell] == gi; };
  std::int32_t runs[2 * 9 * 2];  // at most two runs per row (its middle cell left out)
  std::size_t count = 0;
  const int m0 = std::max(ci - 1, 0), m1 = std::min(ci + 1, g.nx - 1);
  for (int k = std::max(ck - 1, 0); k <= std::min(ck + 1, g.nz - 1); ++k)
    for (int j = std::max(cj - 1, 0); j <= std::min(cj + 1, g.ny - 1); ++j) {
      const std::size_t row = (std::size_t(k) * g.ny + j) * g.nx;
      for (int m = m0; m <= m1;) {
        if (own(row + m)) {
          ++m;
          continue;
        }
        int e = m;
        while (e < m1 && !own(row + e + 1)) ++e;
        const std::int32_t first = g.start[row + m], last = g.start[row + e + 1];
        if (first < last) {
          runs[2 * count] = first;
          runs[2 * count + 1] = last;
          ++count;
        }
        m = e + 1;
      }
    }
  const kernels::NearArgs args{g.mx.data(), g.my.data(), g.mz.data(), g.mr.data(), g.members.data(),
                               p.x[i], p.y[i], p.z[i], p.radius[i] + s.skin, std::int32_t(i)};
  const std::size_t found = s.ctx.kernels->near(args, runs, count, hits);
  for (std::size_t h = 0; h < found; ++h) {
    const std::int32_t o = g.members[std::size_t(hits[h])];
    if (gi >= 0 && p.group[o] == gi) continue;
    if (bonded(s, i, o)) continue;
    out(o);
  }
}

void build_pairs(State& s, const CellGrid& g) {
  const std::size_t n = s.p.n;
  // One search per particle, into lists per chunk of kChunk particles (the unit the threads share
  // out), then copied into the store at their offsets: the list is the same for any thread count.
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<std::int32_t>>& found = s.cache.found_pairs;
  found.resize(chunks);
  std::vector<std::int64_t> count(n + 1, 0);
#pragma omp parallel num_threads(thread_count(s))
  {
    std::vector<std::int32_t> hits(9 * std::size_t(g.longest_row));
#pragma omp for schedule(dynamic, 1)
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      std::vector<std::int32_t>& list = found[chunk];
      list.clear();
      for (std::size_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
        const std::size_t first = list.size();
        neighbours_of(s, g, i, hits.data(), [&](std::int32_t o) { list.push_back(o); });
        std::sort(list.begin() + std::ptrdiff_t(first), list.end());
        count[i + 1] = std::int64_t(list.size() - first);
      }
    }
  }
  std::partial_sum(count.begin(), count.end(), count.begin());
  const std::size_t total = std::size_t(count[n]);

  // Written into the spare store (its pages mapped and zeroed once: a fracture run rebuilds every
  // hundred steps or so, and fresh pages for the list cost as much as its search) and swapped in.
  PairStore& fresh = s.cache.spare_pairs;
  release_if_oversized(fresh, total);
  fresh.resize(total);
  // Carry history: both lists sorted by (a, b), each chunk's pairs merged with the old list from
  // where its first particle's pairs begin there.
  const PairStore& old = s.pairs;
  const ParticleStore& p = s.p;
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count(s))
  for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
    const std::size_t lo = chunk * kChunk, hi = std::min(n, (chunk + 1) * kChunk);
    const std::size_t begin = std::size_t(count[lo]), end = std::size_t(count[hi]);
    std::copy(found[chunk].begin(), found[chunk].end(), fresh.b.begin() + std::ptrdiff_t(begin));
    for (std::size_t i = lo; i < hi; ++i)
      std::fill(fresh.a.begin() + count[i], fresh.a.begin() + count[i + 1], std::int64_t(i));
    std::size_t o = std::size_t(std::lower_bound(old.a.begin(), old.a.begin() + std::ptrdiff_t(old.n),
                                                  std::int64_t(lo)) - old.a.begin());
    for (std::size_t k = begin; k < end; ++k) {
      const std::int64_t a = fresh.a[k], b = fresh.b[k];
      while (o < old.n && (old.a[o] < a || (old.a[o] == a && old.b[o] < b))) ++o;
      if (o < old.n && old.a[o] == a && old.b[o] == b) {
        fresh.copy_history(old, o, k);
        // The overlap as it is now (radii may have changed since the last step): the time-step
        // estimate made right after this rebuild counts the contacts of the current geometry.
        const double dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
        fresh.overlap[k] = p.radius[a] + p.radius[b] - std::sqrt(dx * dx + dy * dy + dz * dz);
      } else {
        fresh.overlap[k] = p.radius[a] + p.radius[b] - start_pair(fresh, k, p);
      }
    }
  }
  // Contacts left behind by broken bonds take over their capped shear force.
  PairStore& ih = s.inherited;
  if (ih.n > 0) {
    std::vector<std::size_t> order(ih.n);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t u, std::size_t v) {
      return ih.a[u] != ih.a[v] ? ih.a[u] < ih.a[v] : ih.b[u] < ih.b[v];
    });
    std::size_t j = 0;
    for (std::size_t k = 0; k < total && j < ih.n; ++k) {
      while (j < ih.n && (ih.a[order[j]] < fresh.a[k] ||
                          (ih.a[order[j]] == fresh.a[k] && ih.b[order[j]] < fresh.b[k])))
        ++j;
      if (j < ih.n && ih.a[order[j]] == fresh.a[k] && ih.b[order[j]] == fresh.b[k]) {
        fresh.copy_history(ih, order[j], k);
      }
    }
    ih.resize(0);
  }
  fresh.fill_padding(p.null_a(), p.null_b());
  std::swap(s.pairs, fresh);  // the previous list is the spare now (build_neighbors, keep_spares)
  build_incidence(n, s.pairs.a.data(), s.pairs.b.data(), total, s.incidence);
}

void build_wall_contacts(State& s) {
  const ParticleStore& p = s.p;
  const std::size_t n = p.n;
  auto& walls = s.walls.walls;
  // Per chunk of kChunk particles, in particle order (the unit the threads share out): a few
  // hundred lists where one per particle would be a hundred thousand small ones, allocated again
  // at every build, whose growing sizes fragment the heap (a genesis rebuilds hundreds of times
  // while its radii grow, and its resident memory grew with them). Kept between builds with the
  // spares (keep_spares).
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<WallCandidate>>& cand = s.cache.found_wall_contacts;
  cand.resize(chunks);
  for (auto& list : cand) list.clear();
  for (Wall& wall : walls)
    wall.candidates_within_half_skin =
        wall.kind == Wall::Kind::mesh && !wall.removed && wall.velocity == Vec3{0, 0, 0};
  std::size_t most_triangles = 0;
  for (const Mesh& mesh : s.walls.meshes) most_triangles = std::max(most_triangles, mesh.triangles.size());
#pragma omp parallel num_threads(thread_count(s))
  {
    std::vector<std::int32_t> tris;
    std::vector<std::uint8_t> seen(most_triangles, 0);
#pragma omp for schedule(dynamic, 1)
    for (std::size_t chunk = 0; chunk < chunks; ++chunk)
      for (std::size_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
        if (p.inert[i]) continue;
        const Vec3 c{p.x[i], p.y[i], p.z[i]};
        const double reach = p.radius[i] + s.skin;
        // A free particle's triangles of a still mesh within R + skin/2 (Wall::candidates_within_
        // half_skin): one farther away stays farther than R while the particle and the wall close
        // at most skin/2 (the rebuild rule), so the wall stage would skip it at every step until
        // the next build (stages/walls.cpp, the same rounding margin). Dropping it changes no bit.
        const double near_reach = (p.radius[i] + 0.5 * s.skin) * (1 + 1e-9);
        for (std::size_t w = 0; w < walls.size(); ++w) {
          const Wall& wall = walls[w];
          if (wall.removed) continue;
          if (wall.kind == Wall::Kind::plane) {
            const double d = dot(c - (wall.point + wall.displacement), wall.normal);
            if (d < reach) cand[chunk].push_back({std::int32_t(i), std::int32_t(w), 0, 0.0});
          } else {
            const Mesh& mesh = s.walls.meshes[wall.mesh];
            const Vec3 q = c - wall.displacement;
            const double r = wall.candidates_within_half_skin && p.group[i] < 0 ? near_reach : reach;
            query_mesh(mesh, q, r, tris, seen);
            const std::size_t first = cand[chunk].size();
            for (std::int32_t t : tris) {
              const auto& tri = mesh.triangles[t];
              int feature;
              const Vec3 cp = closest_point_on_triangle(q, mesh.vertices[tri[0]],
                                                        mesh.vertices[tri[1]],
                                                        mesh.vertices[tri[2]], feature);
              const Vec3 d = q - cp;
              if (dot(d, d) < r * r) cand[chunk].push_back({std::int32_t(i), std::int32_t(w), t, norm(d)});
            }
            // The few within reach in facet order, the list's order (by particle, wall, facet).
            std::sort(cand[chunk].begin() + std::ptrdiff_t(first), cand[chunk].end(),
                      [](const WallCandidate& u, const WallCandidate& v) { return u.facet < v.facet; });
          }
        }
      }
  }
  WallContacts& fresh = s.cache.spare_wall_contacts;
  std::size_t total = 0;
  for (auto& c : cand) total += c.size();
  release_if_oversized(fresh, total);
  fresh.resize(total);
  fresh.start.assign(n + 1, 0);
  std::size_t k = 0;
  for (const auto& list : cand)
    for (const WallCandidate& c : list) {
      fresh.particle[k] = c.particle;
      fresh.wall[k] = c.wall;
      fresh.facet[k] = c.facet;
      fresh.distance[k] = c.distance;
      ++fresh.start[std::size_t(c.particle) + 1];
      ++k;
    }
  for (std::size_t i = 0; i < n; ++i) fresh.start[i + 1] += fresh.start[i];
  // Carry history, both lists sorted by (particle, wall, facet).
  const WallContacts& old = s.walls.contacts;
  std::size_t o = 0;
  for (k = 0; k < total; ++k) {
    const auto key = std::tie(fresh.particle[k], fresh.wall[k], fresh.facet[k]);
    while (o < old.n && std::tie(old.particle[o], old.wall[o], old.facet[o]) < key) ++o;
    const bool known = o < old.n && std::tie(old.particle[o], old.wall[o], old.facet[o]) == key;
    // No history yet: the pads (a zero normal, which the wall kernel takes as "the current one").
    WallContacts::history_columns([&](const ColumnInfo& c, auto& to, const auto& from) {
      to[k] = known ? from[o] : c.pad;
    }, fresh, old);
  }
  std::swap(s.walls.contacts, fresh);  // the previous list is the spare now
}

// Whether a build keeps the lists it replaced (the pair and wall contact lists, the chunks' found
// lists) as spares for the next build, reorder or merge to write into, or releases them. A list's
// fresh pages (mapped, zeroed by the system, then value-initialised) cost about what its search
// does: that counts where builds come every few dozen or hundred steps (a genesis, a fracture
// run's debris) and is lost in the steps where they come every few thousand (a closure, an
// elastic shear), where a spare would be a second list of resident memory for nothing. Where
// bonds can break, break steps merge freed pairs through the spare pair store (insert_pairs).
constexpr std::uint64_t kSpareBuildGap = 1000;  // steps

bool keep_spares(const State& s) {
  return (s.bonds.n > 0 && s.bonds.material.breakable) || s.step - s.cache.last_build_step < kSpareBuildGap;
}

}  // namespace

void ensure_skin(State& s) {
  if (s.skin > 0) return;
  const ParticleStore& p = s.p;
  double mean = 0;
  for (std::size_t i = 0; i < p.n; ++i) mean += p.radius[i];
  s.skin = s.settings.skin > 0 ? s.settings.skin : 0.4 * (p.n ? mean / double(p.n) : 1e-3);
}

void build_neighbors(State& s) {
  ParticleStore& p = s.p;
  const bool keep = keep_spares(s);
  compact_bonds(s);  // the bonds that broke since the last build leave the list (before a reorder)
  sync_lazy(s);  // idle group members are searched: bring them to where they are
  ensure_skin(s);
  CellGrid& grid = s.cache.grid;
  make_grid(p, s.skin, s.step, grid);
  const int every = s.settings.reorder_interval;
  if (p.n > 0 && (s.force_reorder || (every > 0 && s.rebuilds_since_reorder >= std::uint64_t(every)))) {
    reorder(s, grid);
    make_grid(p, s.skin, s.step, grid);
    s.rebuilds_since_reorder = 0;
    s.force_reorder = false;
  }
  build_pairs(s, grid);
  build_wall_contacts(s);
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.inert[i]) continue;
    p.x0[i] = p.x[i];
    p.y0[i] = p.y[i];
    p.z0[i] = p.z[i];
  }
  for (auto& w : s.walls.walls) w.displacement_at_build = w.displacement;
  if (!keep) release_spares(s);
  s.cache.last_build_step = s.step;
  ++s.rebuilds;
  ++s.rebuilds_since_reorder;
  s.need_rebuild = false;
  s.cache.idle_pairs_only = false;  // the groups' members may have moved between bodies' reach
  split_idle(s);
}

void release_spares(State& s) {
  s.cache.spare_pairs = PairStore();
  s.cache.spare_wall_contacts = WallContacts();
  s.cache.found_pairs = {};
  s.cache.found_wall_contacts = {};
}

void build_incidence(std::size_t particles, const std::int64_t* a, const std::int64_t* b,
                     std::size_t count, Incidence& inc) {
  inc.start.assign(particles + 1, 0);
  for (std::size_t k = 0; k < count; ++k) {
    ++inc.start[a[k] + 1];
    ++inc.start[b[k] + 1];
  }
  for (std::size_t i = 0; i < particles; ++i) inc.start[i + 1] += inc.start[i];
  inc.entry.resize(2 * count);
  std::vector<std::int32_t> fill(inc.start.begin(), inc.start.end() - 1);
  // Entries as b first: their a < the particle, so they precede its own a-pairs in the sorted
  // list; each run is ascending, so every particle's entries are in ascending order.
  for (std::size_t k = 0; k < count; ++k) inc.entry[fill[b[k]]++] = std::int64_t(k) << 1 | 1;
  for (std::size_t k = 0; k < count; ++k) inc.entry[fill[a[k]]++] = std::int64_t(k) << 1;
}

double start_pair(PairStore& q, std::size_t k, const ParticleStore& p) {
  const auto a = q.a[k], b = q.b[k];
  const double dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
  const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
  q.nx[k] = d > 0 ? dx / d : 1.0;
  q.ny[k] = d > 0 ? dy / d : 0.0;
  q.nz[k] = d > 0 ? dz / d : 0.0;
  q.fsx[k] = q.fsy[k] = q.fsz[k] = 0;
  q.fn[k] = q.rest[k] = 0;
  return d;
}

void insert_pairs(State& s, const PairStore& add) {
  if (add.n == 0) return;
  const PairStore& old = s.pairs;
  // The merged list is written into the spare store (its pages already mapped: a fracture run
  // merges on most of its steps) and swapped in; the old list becomes the spare.
  PairStore& merged = s.cache.spare_pairs;
  merged.resize(old.n + add.n);
  // Where each added pair goes: before the first old pair above it in (a, b) order.
  std::vector<std::size_t> at(add.n);
  {
    std::size_t i = 0;
    for (std::size_t j = 0; j < add.n; ++j) {
      while (i < old.n && (old.a[i] != add.a[j] ? old.a[i] < add.a[j] : old.b[i] < add.b[j])) ++i;
      at[j] = i;
    }
  }
  // Column by column: the old pairs in runs between the added ones.
  auto merge = [&](auto& to, const auto& from_old, const auto& from_add) {
    std::size_t o = 0, k = 0;
    for (std::size_t j = 0; j < add.n; ++j) {
      std::copy(from_old.begin() + std::ptrdiff_t(o), from_old.begin() + std::ptrdiff_t(at[j]), to.begin() + std::ptrdiff_t(k));
      k += at[j] - o;
      o = at[j];
      to[k++] = from_add[j];
    }
    std::copy(from_old.begin() + std::ptrdiff_t(o), from_old.begin() + std::ptrdiff_t(old.n), to.begin() + std::ptrdiff_t(k));
  };
  merge(merged.a, old.a, add.a);
  merge(merged.b, old.b, add.b);
  // The last step's normal forces and overlaps: from the columns, or, where the old list holds
  // them in its records (the columns stale), from there below.
  PairStore::history_columns(
      [&](const ColumnInfo&, auto& to, const auto& o, const auto& a) {
        if (!old.outputs_in_records || (&to != &merged.fn && &to != &merged.overlap)) merge(to, o, a);
      },
      merged, old, add);
  if (old.outputs_in_records) {
    std::size_t o = 0, k = 0;
    for (std::size_t j = 0; j <= add.n; ++j) {
      for (const std::size_t end = j < add.n ? at[j] : old.n; o < end; ++o, ++k) {
        merged.fn[k] = old.out[kPairRecord * o + 7];
        merged.overlap[k] = old.out[kPairRecord * o + 3];
      }
      if (j < add.n) {
        merged.fn[k] = add.normal_force(j);
        merged.overlap[k] = add.overlap_at(j);
        ++k;
      }
    }
  }
  merged.fill_padding(s.p.null_a(), s.p.null_b());
  std::swap(s.pairs, merged);
  build_incidence(s.p.n, s.pairs.a.data(), s.pairs.b.data(), s.pairs.n, s.incidence);
  // The servo's pairs joining two bodies (if current): their indices moved past the added pairs
  // before them, and the added pairs joining two bodies join them, in the merged order.
  ServoContacts& servo = s.cache.servo;
  if (servo.pairs_at == s.rebuilds) {
    const auto& group = s.p.group;
    std::vector<std::uint32_t> listed;
    listed.reserve(servo.pairs.size() + add.n);
    std::size_t j = 0;
    for (const std::uint32_t k : servo.pairs) {
      for (; j < add.n && at[j] <= k; ++j)
        if (group[add.a[j]] != group[add.b[j]]) listed.push_back(std::uint32_t(at[j] + j));
      listed.push_back(std::uint32_t(k + j));
    }
    for (; j < add.n; ++j)
      if (group[add.a[j]] != group[add.b[j]]) listed.push_back(std::uint32_t(at[j] + j));
    servo.pairs.swap(listed);
  }
  s.cache.idle_pairs_only = s.cache.idle_valid || s.cache.idle_pairs_only;
  s.cache.idle_valid = false;  // a member may have a pair now
}

}  // namespace asperity::detail
