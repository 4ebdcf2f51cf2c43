// Walls (model.md 1): infinite planes and triangle meshes, moved only by prescription, and the
// list of ball-wall contacts with their shear history.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "asperity/materials.hpp"
#include "asperity/vec3.hpp"
#include "core/aligned.hpp"
#include "store/columns.hpp"

namespace asperity::detail {

// Uniform grid over a mesh's bounding box; each triangle is listed in every cell its bounding box
// overlaps. A query touches only the cells around one particle, so the cost of finding a
// particle's candidate triangles does not grow with the size of the mesh.
struct TriangleBins {
  Vec3 origin;
  double cell = 1;
  std::array<int, 3> dims{1, 1, 1};
  std::vector<std::int32_t> start;  // cells + 1
  std::vector<std::int32_t> triangles;
};

struct Mesh {
  std::vector<Vec3> vertices;  // at creation; the wall's displacement is added
  std::vector<std::array<int, 3>> triangles;
  // Bits 0-2: this triangle owns its edge AB, BC, CA; bits 3-5: its vertex A, B, C. A contact whose
  // closest point lies on an edge or vertex shared by several triangles counts only for the owner
  // (the lowest-numbered triangle sharing it), so a sphere on a fold is pushed once, not twice.
  std::vector<std::uint8_t> owns;
  // Triangles around each vertex (CSR): a contact on an edge or vertex is real only if no
  // triangle sharing that feature is closer to the sphere (otherwise that triangle's face or
  // edge is the contact, and this one is its shadow).
  std::vector<std::int32_t> vertex_start, vertex_triangles;
  // Per triangle and edge (AB, BC, CA): the one other triangle sharing it, -1 if none, -2 if
  // several (derived by bin_mesh, like the bins).
  std::vector<std::int32_t> edge_neighbour;
  TriangleBins bins;

  // Its arrays past the caches (4 MB, as records_past_caches in state.hpp; a thesis-scale mould
  // is, a 2 cm one is not). The wall stage then prefetches the triangles of the contacts it will
  // evaluate, which pays only where they do not stay in cache (stages/walls.cpp).
  bool past_caches() const {
    const std::size_t bytes = vertices.size() * sizeof(Vec3) + triangles.size() * sizeof(triangles[0]) +
                              owns.size() + (vertex_start.size() + vertex_triangles.size() + edge_neighbour.size()) * sizeof(std::int32_t);
    return bytes > (std::size_t(4) << 20);
  }
};

struct Wall {
  enum class Kind : std::uint8_t { plane, mesh } kind = Kind::plane;
  ContactMaterial material;
  Vec3 point, normal;      // plane: through point (at creation), unit normal towards particles
  int mesh = -1;           // index into WallStore::meshes
  Vec3 velocity{0, 0, 0};
  Vec3 displacement{0, 0, 0};          // since creation
  Vec3 displacement_at_build{0, 0, 0};
  Vec3 force{0, 0, 0};                 // of the particles on the wall, last step
  bool removed = false;
  // A mesh standing still at the last neighbour build lists a free particle's triangles only
  // within R + skin/2, not R + skin (neighbor/build.cpp): about half of a mould's candidates,
  // which its wall stage and gather then no longer walk. The rebuild rule keeps that list
  // complete: the free particles and the wall may then close only skin/2 between them (step.cpp).
  bool candidates_within_half_skin = false;
};

// A wall contact a neighbour build found, before the list is made of them (neighbor/build.cpp).
struct WallCandidate {
  std::int32_t particle, wall, facet;
  double distance;  // centre to the triangle (mesh); 0 for a plane
};

// Ball-wall contacts within the skin, sorted by (particle, wall, facet). The particle plays the
// role of b in the contact law: the normal points from the wall to the centre.
struct WallContacts {
  std::size_t n = 0;
  std::vector<std::int32_t> particle, wall, facet;
  std::vector<double> nx, ny, nz, fsx, fsy, fsz, fn, overlap;
  std::vector<double> slip;  // slip energy of the last step (plane contacts; an output only)
  // Mesh candidates: the distance from the particle's centre to the triangle when the list was
  // built, which bounds it from below until the next build (stages/walls.cpp); 0 where unknown
  // (a list loaded or re-sorted without it), which never skips a candidate.
  std::vector<double> distance;
  std::vector<std::int32_t> start;  // per particle offsets (CSR), particles + 1

  // The history columns once: f(info, this column of each of `q`...). What a rebuild carries
  // over (a contact new to the list takes the pads: a zero normal is "take the current one"),
  // a reorder copies and a checkpoint saves (besides particle, wall, facet and start).
  template <class F, class... Stores>
  static void history_columns(F&& f, Stores&... q) {
    f(ColumnInfo{"nx", 0}, q.nx...);
    f(ColumnInfo{"ny", 0}, q.ny...);
    f(ColumnInfo{"nz", 0}, q.nz...);
    f(ColumnInfo{"fsx", 0}, q.fsx...);
    f(ColumnInfo{"fsy", 0}, q.fsy...);
    f(ColumnInfo{"fsz", 0}, q.fsz...);
    f(ColumnInfo{"fn", 0}, q.fn...);
    f(ColumnInfo{"overlap", -1}, q.overlap...);
  }

  void resize(std::size_t count) {
    n = count;
    for (auto* c : {&particle, &wall, &facet}) c->resize(count);
    history_columns([&](const ColumnInfo&, auto& c) { c.resize(count); }, *this);
    for (auto* c : {&slip, &distance}) c->resize(count);
  }
};

struct WallStore {
  std::vector<Wall> walls;
  std::vector<Mesh> meshes;
  WallContacts contacts;
};

}  // namespace asperity::detail
