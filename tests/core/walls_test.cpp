// Walls: planes and triangle meshes (model.md 1, 4), contact forces on walls, wall motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "asperity/world.hpp"

using namespace asperity;

namespace {
// A flat square mesh in z = 0 made of cells x cells squares, two triangles each (as a height map
// becomes a mould).
void flat_mesh(int cells, double h, std::vector<Vec3>& v, std::vector<std::array<int, 3>>& t) {
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) v.push_back({i * h, j * h, 0});
  auto at = [&](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      t.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      t.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
}

// Press a sphere onto the mesh at (x, y) with force F and let it settle; return the overlap.
double settle_on_mesh(double x, double y, int cells, double h, std::size_t* contacts = nullptr) {
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  flat_mesh(cells, h, v, t);
  w.add_mesh(v, t);
  const double R = 5e-4, F = 1e-5;
  const auto id = w.add_particle({x, y, R - 0.5 * F / 0.1}, R);
  w.set_applied_force(id, {0, 0, -F});
  w.cycle(3000);
  if (contacts) *contacts = w.stats().wall_contacts;
  return R - w.position(id).z;
}
}  // namespace

TEST(Walls, SphereOnPlaneSettlesAtForceOverStiffness) {
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  ContactMaterial stiff;
  stiff.kn = 0.3;
  w.add_plane({0, 0, 1e-3}, {0, 0, 2});  // normal is normalised
  const auto id = w.add_particle({0, 0, 1.5e-3}, 5e-4);
  w.set_applied_force(id, {0, 0, -1e-5});
  w.cycle(2000);
  EXPECT_NEAR(1.5e-3 - w.position(id).z, 1e-5 / 0.1, 1e-12);
  EXPECT_NEAR(w.wall_force(0).z, -1e-5, 1e-15) << "force of the particle on the wall";
}

TEST(Walls, MeshContactCountsOnceOnFaceEdgeAndVertex) {
  // Shared edges and vertices belong to one triangle: a sphere over a vertex shared by six
  // triangles is pushed by one contact, not six, and settles at the same overlap as on a face.
  const double h = 4e-4, expected = 1e-5 / 0.1;
  std::size_t n;
  EXPECT_NEAR(settle_on_mesh(2.3 * h, 2.6 * h, 8, h, &n), expected, 1e-12) << "face";
  EXPECT_EQ(n, 1u);
  EXPECT_NEAR(settle_on_mesh(2.5 * h, 2.0 * h, 8, h, &n), expected, 1e-12) << "edge";
  EXPECT_EQ(n, 1u);
  EXPECT_NEAR(settle_on_mesh(3.0 * h, 3.0 * h, 8, h, &n), expected, 1e-12) << "vertex";
  EXPECT_EQ(n, 1u);
  EXPECT_NEAR(settle_on_mesh(3.5 * h, 3.5 * h, 8, h, &n), expected, 1e-12) << "diagonal edge";
  EXPECT_EQ(n, 1u);
}

TEST(Walls, LargeMeshIsBinned) {
  // A thesis-scale mould has ~270 000 triangles; a sphere anywhere still finds its triangle.
  const double h = 0.1 / 365;
  const double expected = 1e-5 / 0.1;
  EXPECT_NEAR(settle_on_mesh(0.05123, 0.0877, 365, h), expected, 1e-12);
}

TEST(Walls, FoldedMeshPushesFromBothFaces) {
  // A sphere in a V-shaped groove (two frictionless faces at +-45 degrees) touches both faces:
  // two contacts, and the vertical force splits equally between them.
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  const double s = 2e-3;
  std::vector<Vec3> v{{-s, -s, s}, {-s, s, s}, {0, -s, 0}, {0, s, 0}, {s, -s, s}, {s, s, s}};
  std::vector<std::array<int, 3>> t{{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
  ContactMaterial frictionless;
  frictionless.friction = 0;
  w.add_mesh(v, t, frictionless);
  const double R = 5e-4, F = 1e-5;
  const auto id = w.add_particle({0, 0, R * std::sqrt(2.0)}, R);
  w.set_applied_force(id, {0, 0, -F});
  w.cycle(4000);
  EXPECT_EQ(w.stats().wall_contacts, 2u);
  // Each face carries F / sqrt(2) along its normal: overlap F / (sqrt(2) kn).
  const double U = F / (std::sqrt(2.0) * 0.1);
  EXPECT_NEAR(w.position(id).z, (R - U) * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(w.position(id).x, 0.0, 1e-12);
}

// The wall stage skips a mesh candidate that cannot touch yet: its distance at the neighbour
// build, less how far the particle and the mesh have moved since, is above the radius
// (kernels/walls.cpp). A sphere pressed onto a fine flat mesh and slid across it (or the mesh
// slid under it) reaches triangles it did not touch at the build several times between builds;
// each must take the contact over the step it is reached, or the sphere loses its support for a
// step and drops by ~F dt^2 / m (~1e-5 m here). So its height stays at R - F / kn throughout.
TEST(Walls, SlidingOverAFineMeshKeepsTheContactAcrossTriangles) {
  for (const bool mesh_moves : {false, true}) {
    WorldSettings ws;
    ws.rotation = false;
    World w(ws);
    std::vector<Vec3> v;
    std::vector<std::array<int, 3>> t;
    const double h = 1e-4, R = 5e-4, F = 1e-5, kn = 0.1;
    flat_mesh(60, h, v, t);  // 6 mm square of 0.1 mm cells
    const int mesh = w.add_mesh(v, t);
    const auto id = w.add_particle({1.5e-3, 2.05e-3, R - F / kn}, R);
    GroupMotion slide;
    slide.translation = {Dof::velocity, Dof::fixed, Dof::free};
    slide.velocity = {mesh_moves ? 0.0 : 1e-4, 0, 0};
    const int g = w.add_group(std::vector<std::int64_t>{id}, slide);
    w.set_group_applied_force(g, {0, 0, -F});
    if (mesh_moves) w.set_wall_velocity(mesh, {-1e-4, 0, 0});
    w.cycle(3000);  // settled
    double low = 1, high = -1;
    const double x0 = w.position(id).x - w.wall_displacement(mesh).x;
    for (int k = 0; k < 300; ++k) {
      w.cycle(10);
      low = std::min(low, w.position(id).z);
      high = std::max(high, w.position(id).z);
      ASSERT_EQ(w.stats().wall_contacts, 1u) << "mesh moves " << mesh_moves << ", after " << 10 * (k + 1) << " steps";
    }
    // Not vacuous: it crossed many triangles (0.1 mm wide) and the list was rebuilt in between.
    EXPECT_GT(w.position(id).x - w.wall_displacement(mesh).x - x0, 8 * h) << mesh_moves;
    EXPECT_NEAR(low, R - F / kn, 1e-9) << mesh_moves;
    EXPECT_NEAR(high, R - F / kn, 1e-9) << mesh_moves;
  }
}

TEST(Walls, MovingWallPushesAndRecordsItsWork) {
  WorldSettings ws;
  World w(ws);
  w.add_plane({0, 0, 0}, {0, 0, 1});
  const int top = w.add_plane({0, 0, 1.0e-3}, {0, 0, -1});
  w.add_particle({0, 0, 0.5e-3}, 5e-4);
  const Energies e0 = w.energies();
  w.set_wall_velocity(top, {0, 0, -1e-6});
  w.cycle(5000);
  EXPECT_NEAR(w.wall_displacement(top).z, -1e-6 * w.time(), 1e-15);
  const Energies e = w.energies();
  EXPECT_GT(e.boundary_work, 0);
  EXPECT_LT(std::fabs(e.balance_error(e0)), 0.01 * e.boundary_work);
  EXPECT_NEAR(w.wall_force(top).z, -w.wall_force(0).z, 1e-3 * std::fabs(w.wall_force(0).z))
      << "quasi-static: both walls carry the same load";
}

TEST(Walls, RemovedWallNoLongerActs) {
  World w;
  const int floor = w.add_plane({0, 0, 0}, {0, 0, 1});
  const auto id = w.add_particle({0, 0, 4.9e-4}, 5e-4);
  w.cycle(10);
  EXPECT_GT(w.position(id).z, 4.9e-4);
  w.remove_wall(floor);
  w.set_velocity(id, {0, 0, 0});
  const double z = w.position(id).z;
  w.cycle(10);
  EXPECT_EQ(w.position(id).z, z);
  EXPECT_THROW(w.wall_force(7), Error);
}
