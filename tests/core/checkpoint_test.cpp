// Checkpoints: a run restarted from a checkpoint continues bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "scenes.hpp"
#include "state.hpp"

using namespace asperity;

namespace {
std::string temp_file(const char* name) {
  return (std::filesystem::temp_directory_path() / name).string();
}

bool same(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}
}  // namespace

namespace {
// A busy scene: falling particles in a box, then bonded, a mesh wall, a servo platen; saved,
// loaded and run on beside the original.
void restart_continues_bit_for_bit(bool stress_free_bonds) {
  WorldSettings ws;
  ws.dt = 5e-4;
  World w = test::random_box(400, ws);
  std::vector<Vec3> v{{0, 0, 1e-3}, {0.012, 0, 1e-3}, {0, 0.012, 1e-3}, {0.012, 0.012, 1e-3}};
  std::vector<std::array<int, 3>> t{{0, 1, 3}, {0, 3, 2}};
  w.add_mesh(v, t);
  w.cycle(1500);
  BondMaterial bm;
  bm.tensile_strength = 0.02;
  w.install_bonds(bm, 2e-5, {}, stress_free_bonds);
  std::vector<std::int64_t> top;
  for (std::int64_t id = 0; id < 20; ++id) top.push_back(id);
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::velocity, Dof::servo};
  m.velocity = {0, 1e-4, 0};
  m.servo[2].target_force = 1e-6;
  w.add_group(top, m);
  w.cycle(500);
  // One file per test: ctest -j runs the two variants at once.
  const std::string path = temp_file(stress_free_bonds ? "asperity_checkpoint_test_stress_free.h5"
                                                       : "asperity_checkpoint_test.h5");
  // The last step's normal forces and overlaps live in the pair records (store/pairs.hpp); the
  // loaded world must report the same contacts and strain energy before it takes a step.
  const std::vector<ContactInfo> saved = w.contacts();
  const double saved_strain = w.energies().strain;
  ASSERT_GT(saved.size(), 10u);
  w.save(path);
  w.cycle(700);

  // Loaded with the kernels of the saved run (on one thread; results do not depend on the count):
  // everything bit for bit, the ledgers too.
  World r = World::load(path, 1, w.simd_architecture());
  const std::vector<ContactInfo> loaded = r.contacts();
  ASSERT_EQ(loaded.size(), saved.size());
  for (std::size_t k = 0; k < saved.size(); ++k) {
    EXPECT_EQ(loaded[k].normal_force, saved[k].normal_force) << k;
    EXPECT_EQ(loaded[k].overlap, saved[k].overlap) << k;
  }
  EXPECT_EQ(r.energies().strain, saved_strain);
  // The still mesh listed its free particles within half the skin; the loaded world knows, so its
  // rebuild rule keeps that list complete (Walls.StillMeshSetMovingCatchesTheSphereItLeftOff).
  ASSERT_TRUE(w.state().walls.walls.back().candidates_within_half_skin);
  EXPECT_TRUE(r.state().walls.walls.back().candidates_within_half_skin);
  EXPECT_EQ(r.step_count() + 700, w.step_count());
  // Loaded with the scalar reference instead: the state evolves bit for bit (the SIMD kernels equal
  // it), but the slip energy of a step is summed per lane by a SIMD kernel, so the friction ledger
  // agrees to rounding only (as Determinism.SimdKernelsEqualTheScalarReferenceBitwise says).
  World q = World::load(path, 1, "scalar");
  r.cycle(700);
  q.cycle(700);
  EXPECT_TRUE(same(w.positions(), r.positions()));
  EXPECT_TRUE(same(w.velocities(), r.velocities()));
  EXPECT_TRUE(same(w.forces(), r.forces()));
  EXPECT_TRUE(same(w.positions(), q.positions()));
  EXPECT_TRUE(same(w.forces(), q.forces()));
  EXPECT_EQ(w.bond_count(), r.bond_count());
  EXPECT_EQ(w.break_events().size(), r.break_events().size());
  EXPECT_GT(w.bond_count(), 0u) << "the scene must hold bonds";
  EXPECT_GT(w.break_events().size(), 0u) << "and break some of them";
  const Energies a = w.energies(), b = r.energies(), c = q.energies();
  EXPECT_EQ(a.friction, b.friction);
  EXPECT_EQ(a.boundary_work, b.boundary_work);
  EXPECT_EQ(a.released, b.released);
  EXPECT_GT(a.friction, 0.0);
  EXPECT_NEAR(c.friction, a.friction, 1e-12 * a.friction);
  EXPECT_EQ(w.group_position(0), r.group_position(0));
  EXPECT_EQ(w.group_position(0), q.group_position(0));
  std::filesystem::remove(path);
}
}  // namespace

TEST(Checkpoint, RestartContinuesBitForBit) { restart_continues_bit_for_bit(false); }

// The rest overlaps of stress-free bonds and of the contacts their breaks leave are saved too.
TEST(Checkpoint, RestartWithStressFreeBondsContinuesBitForBit) { restart_continues_bit_for_bit(true); }

TEST(Checkpoint, MissingOrForeignFileIsAClearError) {
  EXPECT_THROW(World::load("/nonexistent/x.h5"), Error);
  const std::string path = temp_file("asperity_not_a_checkpoint.txt");
  { std::FILE* f = std::fopen(path.c_str(), "w"); std::fputs("hello", f); std::fclose(f); }
  try {
    World::load(path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not an HDF5 file"), std::string::npos);
  }
  std::filesystem::remove(path);
}
