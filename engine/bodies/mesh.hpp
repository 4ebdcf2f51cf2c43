// Triangle-mesh geometry shared by the neighbour search (a particle's candidate triangles) and
// the wall stage (a contact's closest point and feature).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "asperity/vec3.hpp"
#include "store/walls.hpp"

namespace asperity::detail {

// Closest point on triangle (a, b, c) to p; `feature`: 0 face, 1..3 vertex a, b, c, 4..6 edge ab,
// bc, ca. Defined in stages/walls.cpp, in the unit of its hottest caller.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                               int& feature);
// bodies/mesh.cpp: the mesh's edge neighbours (Mesh::edge_neighbour) and its grid of triangles
// (Mesh::bins), derived from its vertices and triangles.
void bin_mesh(Mesh& mesh);
// bodies/mesh.cpp: candidate triangles of `mesh` within `reach` of the point `q` (mesh
// coordinates), each once, in the order of the bins. `seen` holds a byte per triangle of the
// mesh, all 0, and is left so.
void query_mesh(const Mesh& mesh, const Vec3& q, double reach, std::vector<std::int32_t>& out,
                std::vector<std::uint8_t>& seen);
// Whether triangle `tri` has vertex v.
inline bool holds_vertex(const std::array<int, 3>& tri, int v) {
  return tri[0] == v || tri[1] == v || tri[2] == v;
}

}  // namespace asperity::detail
