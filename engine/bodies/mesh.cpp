// Triangle meshes as wall geometry (bodies/mesh.hpp): the grid of a mesh's triangles, which
// finds those near a point, and the neighbours across each edge.
#include <algorithm>
#include <cmath>

#include "bodies/mesh.hpp"

namespace asperity::detail {

void bin_mesh(Mesh& mesh) {
  // The other triangle on each edge: -1 on the boundary, -2 where several share it.
  mesh.edge_neighbour.assign(3 * mesh.triangles.size(), -1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int va = mesh.triangles[t][e], vb = mesh.triangles[t][(e + 1) % 3];
      std::int32_t& across = mesh.edge_neighbour[3 * t + std::size_t(e)];
      for (std::int32_t k = mesh.vertex_start[va]; k < mesh.vertex_start[va + 1]; ++k) {
        const std::int32_t o = mesh.vertex_triangles[k];
        if (std::size_t(o) == t || !holds_vertex(mesh.triangles[o], vb)) continue;
        across = across == -1 ? o : -2;
      }
    }
  TriangleBins& g = mesh.bins;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  double edge_sum = 0;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = mesh.vertices[t[k]];
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
      edge_sum += norm(mesh.vertices[t[(k + 1) % 3]] - v);
    }
  }
  const double mean_edge = mesh.triangles.empty() ? 1.0 : edge_sum / (3.0 * mesh.triangles.size());
  g.cell = std::max(2.0 * mean_edge, 1e-12);
  const Vec3 ext = hi - lo;
  auto dim = [&](double e) { return std::max(1, int(std::min(4096.0, std::ceil(e / g.cell)))); };
  while (double(dim(ext.x)) * dim(ext.y) * dim(ext.z) > 4.0 * mesh.triangles.size() + 64) g.cell *= 1.26;
  g.origin = lo;
  g.dims = {dim(ext.x), dim(ext.y), dim(ext.z)};
  const std::size_t cells = std::size_t(g.dims[0]) * g.dims[1] * g.dims[2];
  auto cell_range = [&](const Vec3& mn, const Vec3& mx, int (&r)[3][2]) {
    const double lo3[3] = {mn.x - g.origin.x, mn.y - g.origin.y, mn.z - g.origin.z};
    const double hi3[3] = {mx.x - g.origin.x, mx.y - g.origin.y, mx.z - g.origin.z};
    for (int d = 0; d < 3; ++d) {
      r[d][0] = std::clamp(int(std::floor(lo3[d] / g.cell)), 0, g.dims[d] - 1);
      r[d][1] = std::clamp(int(std::floor(hi3[d] / g.cell)), 0, g.dims[d] - 1);
    }
  };
  std::vector<std::int32_t> count(cells + 1, 0);
  std::vector<std::array<int, 6>> ranges(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    Vec3 mn = mesh.vertices[tri[0]], mx = mn;
    for (int k = 1; k < 3; ++k) {
      const Vec3& v = mesh.vertices[tri[k]];
      mn = {std::min(mn.x, v.x), std::min(mn.y, v.y), std::min(mn.z, v.z)};
      mx = {std::max(mx.x, v.x), std::max(mx.y, v.y), std::max(mx.z, v.z)};
    }
    int r[3][2];
    cell_range(mn, mx, r);
    ranges[t] = {r[0][0], r[0][1], r[1][0], r[1][1], r[2][0], r[2][1]};
    for (int k = r[2][0]; k <= r[2][1]; ++k)
      for (int j = r[1][0]; j <= r[1][1]; ++j)
        for (int i = r[0][0]; i <= r[0][1]; ++i)
          ++count[(std::size_t(k) * g.dims[1] + j) * g.dims[0] + i + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
  g.start = count;
  g.triangles.resize(count[cells]);
  std::vector<std::int32_t> fill(count.begin(), count.end() - 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& r = ranges[t];
    for (int k = r[4]; k <= r[5]; ++k)
      for (int j = r[2]; j <= r[3]; ++j)
        for (int i = r[0]; i <= r[1]; ++i)
          g.triangles[fill[(std::size_t(k) * g.dims[1] + j) * g.dims[0] + i]++] = std::int32_t(t);
  }
}

void query_mesh(const Mesh& mesh, const Vec3& q, double reach, std::vector<std::int32_t>& out,
                std::vector<std::uint8_t>& seen) {
  out.clear();
  const TriangleBins& g = mesh.bins;
  int r[3][2];
  const double c[3] = {q.x - g.origin.x, q.y - g.origin.y, q.z - g.origin.z};
  for (int d = 0; d < 3; ++d) {
    const double lo = (c[d] - reach) / g.cell, hi = (c[d] + reach) / g.cell;
    if (hi < 0 || lo >= g.dims[d]) return;  // the sphere's box misses the mesh's box
    r[d][0] = std::clamp(int(std::floor(lo)), 0, g.dims[d] - 1);
    r[d][1] = std::clamp(int(std::floor(hi)), 0, g.dims[d] - 1);
  }
  for (int k = r[2][0]; k <= r[2][1]; ++k)
    for (int j = r[1][0]; j <= r[1][1]; ++j)
      for (int i = r[0][0]; i <= r[0][1]; ++i) {
        const std::size_t cell = (std::size_t(k) * g.dims[1] + j) * g.dims[0] + i;
        // A triangle lies in every bin it overlaps: each is taken once (a sort of the bins'
        // lists to drop the repeats cost as much as the distance tests after it).
        for (std::int32_t e = g.start[cell]; e < g.start[cell + 1]; ++e) {
          const std::int32_t t = g.triangles[std::size_t(e)];
          if (seen[std::size_t(t)]) continue;
          seen[std::size_t(t)] = 1;
          out.push_back(t);
        }
      }
  for (const std::int32_t t : out) seen[std::size_t(t)] = 0;
}

}  // namespace asperity::detail
