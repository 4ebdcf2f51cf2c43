// Walls: planes and triangle meshes (model.md 1, 4), contact forces on walls, wall motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "asperity/world.hpp"
#include "bodies/mesh.hpp"
#include "state.hpp"

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

// The same mesh added to a world; returns the wall.
int add_flat_mesh(World& w, int cells, double h, const ContactMaterial& m = {}) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  flat_mesh(cells, h, v, t);
  return w.add_mesh(v, t, m);
}

// Press a sphere onto the mesh at (x, y) with force F and let it settle; return the overlap.
double settle_on_mesh(double x, double y, int cells, double h, std::size_t* contacts = nullptr) {
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  add_flat_mesh(w, cells, h);
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
// (stages/walls.cpp). A sphere pressed onto a fine flat mesh and slid across it (or the mesh
// slid under it) reaches triangles it did not touch at the build several times between builds;
// each must take the contact over the step it is reached, or the sphere loses its support for a
// step and drops by ~F dt^2 / m (~1e-5 m here). So its height stays at R - F / kn throughout.
TEST(Walls, SlidingOverAFineMeshKeepsTheContactAcrossTriangles) {
  for (const bool mesh_moves : {false, true}) {
    WorldSettings ws;
    ws.rotation = false;
    World w(ws);
    const double h = 1e-4, R = 5e-4, F = 1e-5, kn = 0.1;
    const int mesh = add_flat_mesh(w, 60, h);  // 6 mm square of 0.1 mm cells
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

// Each edge's other triangle (Mesh::edge_neighbour), which the shared-edge test checks instead of
// walking the triangles around a vertex: one across an inner edge, none (-1) on the boundary,
// -2 where three triangles meet on one edge (a fin), which keeps the walk.
TEST(Walls, EdgeNeighboursOfAMesh) {
  World w;
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  flat_mesh(2, 1e-3, v, t);  // 8 triangles; cell (0, 0) holds triangles 0 and 1
  v.push_back({1e-3, 1e-3, 1e-3});
  t.push_back({0, 4, 9});  // a fin on the diagonal edge 0-4 of cell (0, 0)
  w.add_mesh(v, t);
  const auto& en = w.state().walls.meshes[0].edge_neighbour;
  ASSERT_EQ(en.size(), 3 * t.size());
  // Triangle 0 = (0, 1, 4): edge 0-1 on the boundary, edge 1-4 shared with cell (1, 0)'s
  // triangle 3 = (1, 5, 4), edge 4-0 shared by triangle 1 and the fin 8.
  EXPECT_EQ(en[0], -1);
  EXPECT_EQ(en[1], 3);
  EXPECT_EQ(en[2], -2);
  // Triangle 1 = (0, 4, 3): edge 0-4 with triangle 0 and the fin; edge 4-3 shared with cell
  // (0, 1)'s triangle 4 = (3, 4, 7); edge 3-0 on the boundary.
  EXPECT_EQ(en[3], -2);
  EXPECT_EQ(en[4], 4);
  EXPECT_EQ(en[5], -1);
  // Every inner edge is seen from both sides.
  for (std::size_t k = 0; k < en.size(); ++k)
    if (en[k] >= 0) {
      const int o = en[k];
      EXPECT_TRUE(en[3 * o] == int(k / 3) || en[3 * o + 1] == int(k / 3) || en[3 * o + 2] == int(k / 3)) << k;
    }
}

// A mesh standing still at the neighbour build lists a free particle's triangles only within
// R + skin/2 (Wall::candidates_within_half_skin, neighbor/build.cpp); a moving mesh, and a rigid
// group's member, within R + skin.
TEST(Walls, StillMeshListsFreeParticlesWithinHalfTheSkin) {
  const double h = 4e-4, R = 5e-4, skin = 2e-4;
  auto candidates = [&](double gap, bool mesh_moves, bool in_group) {
    WorldSettings ws;
    ws.rotation = false;
    ws.skin = skin;
    World w(ws);
    const int mesh = add_flat_mesh(w, 8, h);
    const auto id = w.add_particle({3.3 * h, 3.6 * h, R + gap}, R);
    if (in_group) w.add_group(std::vector<std::int64_t>{id});
    if (mesh_moves) w.set_wall_velocity(mesh, {1e-9, 0, 0});
    w.rebuild_neighbors();
    EXPECT_EQ(w.state().walls.walls[mesh].candidates_within_half_skin, !mesh_moves);
    return w.state().walls.contacts.n;
  };
  EXPECT_GT(candidates(0.4 * skin, false, false), 0u);
  EXPECT_EQ(candidates(0.6 * skin, false, false), 0u) << "beyond R + skin/2 of a still mesh";
  EXPECT_GT(candidates(0.6 * skin, true, false), 0u) << "a moving mesh: the whole skin";
  EXPECT_GT(candidates(0.6 * skin, false, true), 0u) << "a group's member: the whole skin";
  EXPECT_EQ(candidates(1.1 * skin, true, false), 0u);
}

// A still mesh that left a free sphere off its list (farther than R + skin/2) and then starts
// moving towards it may close only skin/2 before the list is rebuilt (step.cpp). So the contact
// starts in the step the mesh reaches the sphere: after the first step with a wall force the
// overlap is at most two steps of the mesh's travel (the one its force was computed at, and the
// move after it). Under the whole-skin rule the mesh would pass 0.3 skin (15 steps) into the
// sphere unseen.
TEST(Walls, StillMeshSetMovingCatchesTheSphereItLeftOff) {
  WorldSettings ws;
  ws.rotation = false;
  const double h = 4e-4, R = 5e-4, skin = 2e-4;
  ws.skin = skin;
  World w(ws);
  const int mesh = add_flat_mesh(w, 8, h);
  const auto id = w.add_particle({3.3 * h, 3.6 * h, R + 0.7 * skin}, R);
  w.cycle(1);
  ASSERT_EQ(w.state().walls.contacts.n, 0u) << "the sphere is off the still mesh's list";
  const double travel = skin / 50;  // per step
  w.set_wall_velocity(mesh, {0, 0, travel / w.dt()});
  int steps = 0;
  while (w.wall_force(mesh).z == 0 && steps < 100) {
    w.cycle(1);
    ++steps;
  }
  ASSERT_LT(steps, 100) << "the mesh never touched the sphere";
  EXPECT_GE(steps, 34) << "0.7 skin at skin / 50 a step";
  const double overlap = R - (w.position(id).z - w.wall_displacement(mesh).z);
  EXPECT_GT(overlap, 0);
  EXPECT_LE(overlap, 2 * travel) << "caught late, after " << steps << " steps";
}

// The free sphere's version of SlidingOverAFineMeshKeepsTheContactAcrossTriangles: a frictionless
// sphere sliding on its own over a still fine mesh, whose list holds its triangles within
// R + skin/2 only, takes each triangle's contact over in the step it reaches it.
TEST(Walls, FreeSphereSlidingOverAStillMeshKeepsItsContact) {
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  const double h = 1e-4, R = 5e-4, F = 1e-5, kn = 0.1;
  ContactMaterial frictionless;
  frictionless.friction = 0;
  const int mesh = add_flat_mesh(w, 60, h, frictionless);
  const auto id = w.add_particle({1.5e-3, 2.05e-3, R - F / kn}, R);
  w.set_applied_force(id, {0, 0, -F});
  w.cycle(3000);  // settled
  w.set_velocity(id, {1e-4, 0, 0});
  const double x0 = w.position(id).x;
  const auto rebuilds = w.stats().rebuilds;
  double low = 1, high = -1;
  for (int k = 0; k < 300; ++k) {
    w.cycle(10);
    low = std::min(low, w.position(id).z);
    high = std::max(high, w.position(id).z);
    ASSERT_EQ(w.stats().wall_contacts, 1u) << "after " << 10 * (k + 1) << " steps";
  }
  EXPECT_TRUE(w.state().walls.walls[mesh].candidates_within_half_skin);
  EXPECT_GT(w.position(id).x - x0, 8 * h);
  EXPECT_GT(w.stats().rebuilds, rebuilds + 5);
  EXPECT_NEAR(low, R - F / kn, 1e-9);
  EXPECT_NEAR(high, R - F / kn, 1e-9);
}

// The wall contacts a build lists on a still mesh are the triangles a check of every triangle
// finds: for each free particle, every triangle whose closest point lies within R + skin/2 (the
// still mesh's reach, Wall::candidates_within_half_skin) by the same computation, in facet order.
// A bumpy mesh, its triangles in many bins each, under particles of radii 0.2 to 0.8 mm.
TEST(Walls, AStillMeshListsTheTrianglesACheckOfEveryTriangleFinds) {
  WorldSettings ws;
  ws.dt = 1e-6;
  ws.skin = 2e-4;
  World w(ws);
  const int cells = 40;
  const double h = 3e-4;
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  flat_mesh(cells, h, v, t);
  for (auto& p : v) p.z = 2e-4 * std::sin(p.x / 7e-4) * std::cos(p.y / 5e-4);
  w.add_mesh(v, t, ContactMaterial{});
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> xyz, radii;
  for (int i = 0; i < 600; ++i) {
    xyz.insert(xyz.end(), {cells * h * u(rng), cells * h * u(rng), -1e-3 + 2.5e-3 * u(rng)});
    radii.push_back(2e-4 + 6e-4 * u(rng));
  }
  w.add_particles(xyz, radii, 2500.0);
  w.rebuild_neighbors();
  const auto& s = w.state();
  const auto& p = s.p;
  const auto& mesh = s.walls.meshes[0];
  std::vector<std::pair<std::int64_t, std::int32_t>> want, got;
  for (std::size_t i = 0; i < p.n; ++i) {
    const double r = (p.radius[i] + 0.5 * s.skin) * (1 + 1e-9);
    for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
      const auto& tri = mesh.triangles[k];
      int feature;
      const Vec3 q{p.x[i], p.y[i], p.z[i]};
      const Vec3 d = q - detail::closest_point_on_triangle(q, mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                                           mesh.vertices[tri[2]], feature);
      if (dot(d, d) < r * r) want.emplace_back(std::int64_t(i), std::int32_t(k));
    }
  }
  const auto& wc = s.walls.contacts;
  for (std::size_t k = 0; k < wc.n; ++k) {
    EXPECT_EQ(wc.wall[k], 0);
    got.emplace_back(wc.particle[k], wc.facet[k]);
  }
  EXPECT_GT(want.size(), 600u);  // several triangles a particle
  EXPECT_EQ(got, want);
}
