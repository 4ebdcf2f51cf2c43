// Checkpoints: a run restarted from a checkpoint continues bit for bit.
#include <algorithm>
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
  EXPECT_TRUE(test::same_bits(w.positions(), r.positions()));
  EXPECT_TRUE(test::same_bits(w.velocities(), r.velocities()));
  EXPECT_TRUE(test::same_bits(w.forces(), r.forces()));
  EXPECT_TRUE(test::same_bits(w.positions(), q.positions()));
  EXPECT_TRUE(test::same_bits(w.forces(), q.forces()));
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
  // The platen's impulse goes on from its saved sum, so a resumed run's interval means are those
  // of the unbroken run.
  EXPECT_NE(w.group_impulse(0).z, 0.0);
  EXPECT_EQ(w.group_impulse(0), r.group_impulse(0));
  std::filesystem::remove(path);
}
}  // namespace

TEST(Checkpoint, RestartContinuesBitForBit) { restart_continues_bit_for_bit(false); }

// The rest overlaps of stress-free bonds and of the contacts their breaks leave are saved too.
TEST(Checkpoint, RestartWithStressFreeBondsContinuesBitForBit) { restart_continues_bit_for_bit(true); }

// Saving changes nothing of the run that saves, so a run resumed from a save is the run that was
// never interrupted: a block on a plane whose lower layers form a platen driven sideways (its
// rotation fixed: the members that touch only each other are idle, moved lazily), saved between
// two neighbour builds with the idle members' shift pending, runs on as a twin never saved does,
// and as the world loaded from the save does.
TEST(Checkpoint, SavingChangesNothingOfTheRun) {
  auto scene = [](World& w) {
    const double r = 1e-3;
    std::vector<std::int64_t> platen;
    for (int k = 0; k < 6; ++k)
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
          const double jitter = 1e-6 * ((i * 7 + j * 13 + k * 29) % 11);
          const auto id = w.add_particle({2 * r * i + jitter, 2 * r * j, r + 1.999 * r * k}, r);
          if (k < 4) platen.push_back(id);
        }
    w.add_plane({0, 0, 0}, {0, 0, 1});
    // Bonded, so the platen holds bonds inside it (left out of the step while it does not turn,
    // State::frozen_bonds), some between a busy member and an idle one.
    BondMaterial bm;
    bm.breakable = false;
    ASSERT_GT(w.install_bonds(bm, 2.5e-6), 0u);
    GroupMotion m;
    m.translation = {Dof::velocity, Dof::fixed, Dof::fixed};
    m.velocity = {2e-3, 0, 0};
    w.add_group(platen, m);
    w.cycle(300);
  };
  WorldSettings ws;
  ws.dt = 2e-4;
  World w(ws), u(ws);
  scene(w);
  scene(u);
  ASSERT_GT(w.state().frozen_bonds.n, 0u) << "the scene needs bonds inside the platen";
  ASSERT_TRUE(w.state().groups[0].lazy);
  const auto& idle = w.state().cache.idle;
  ASSERT_TRUE(std::any_of(idle.begin(), idle.end(), [](auto f) { return f != 0; })) << "the scene needs idle members";
  // A step after which the idle members' shift is pending (no build at it).
  while (w.state().groups[0].idle_shift == Vec3{}) {
    w.cycle(1);
    u.cycle(1);
  }
  const std::string path = temp_file("asperity_checkpoint_test_saving.h5");
  w.save(path);
  World r = World::load(path, 1, w.simd_architecture());
  for (World* x : {&w, &u, &r}) x->cycle(1);
  // The platen's force (what a servo or a load cell reads) at the first step after the load.
  EXPECT_EQ(w.group_force(0), u.group_force(0));
  EXPECT_EQ(r.group_force(0), u.group_force(0));
  for (World* x : {&w, &u, &r}) x->cycle(2000);
  EXPECT_EQ(r.group_force(0), u.group_force(0));
  EXPECT_GT(w.state().rebuilds, 1u);
  EXPECT_TRUE(test::same_bits(w.positions(), u.positions())) << "saving changed the run";
  EXPECT_TRUE(test::same_bits(w.velocities(), u.velocities()));
  EXPECT_TRUE(test::same_bits(r.positions(), u.positions())) << "the loaded world parts from the run it was saved from";
  EXPECT_TRUE(test::same_bits(r.forces(), u.forces()));
  EXPECT_EQ(r.state().rebuilds, u.state().rebuilds);
  EXPECT_EQ(r.energies().boundary_work, u.energies().boundary_work);
  std::filesystem::remove(path);
}

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

namespace {
std::string read_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  std::string s;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}
void write_file(const std::string& path, const std::string& s) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fwrite(s.data(), 1, s.size(), f);
  std::fclose(f);
}
std::string load_error(const std::string& path) {
  try {
    World::load(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(loaded)";
}

// A scene with a bit of everything a checkpoint holds: pairs, bonds, a mesh, a group.
World busy_scene() {
  WorldSettings ws;
  ws.dt = 5e-4;
  World w = test::random_box(80, ws);
  std::vector<Vec3> v{{0, 0, 1e-3}, {0.012, 0, 1e-3}, {0, 0.012, 1e-3}, {0.012, 0.012, 1e-3}};
  std::vector<std::array<int, 3>> t{{0, 1, 3}, {0, 3, 2}};
  w.add_mesh(v, t);
  w.cycle(600);
  BondMaterial bm;
  bm.tensile_strength = 1;
  w.install_bonds(bm, 2e-5);
  w.add_group(std::vector<std::int64_t>{0, 1, 2}, GroupMotion{});
  w.cycle(50);
  return w;
}
}  // namespace

// A flipped byte anywhere, or a truncated file, is refused by the checksum before HDF5 reads it.
TEST(Checkpoint, DamagedOrTruncatedFileIsRefused) {
  World w = busy_scene();
  const std::string path = temp_file("asperity_checkpoint_flipped.h5");
  w.save(path);
  const std::string good = read_file(path);
  ASSERT_GT(good.size(), 4096u);
  for (std::size_t at : {std::size_t(30), std::size_t(600), good.size() / 3, good.size() - 1}) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    write_file(path, bad);
    const std::string e = load_error(path);
    EXPECT_TRUE(e.find("damaged") != std::string::npos || e.find("header") != std::string::npos) << at << ": " << e;
  }
  write_file(path, good.substr(0, good.size() / 2));
  EXPECT_NE(load_error(path).find("truncated or damaged"), std::string::npos);
  write_file(path, good);
  EXPECT_EQ(World::load(path).particle_count(), w.particle_count());
  std::filesystem::remove(path);
}

// A file whose checksum is right but whose contents are not (here: saved from a damaged state) is
// refused by the checks after loading, which name what is wrong, before a step can use it.
TEST(Checkpoint, InconsistentContentsAreRefusedByName) {
  const World base = busy_scene();
  ASSERT_GT(base.state().pairs.n, 0u);
  ASSERT_GT(base.state().bonds.n, 0u);
  const std::string path = temp_file("asperity_checkpoint_inconsistent.h5");
  struct Case {
    const char* message;
    void (*damage)(detail::State&);
  };
  const Case cases[] = {
      {"particles/id and index_of_id", [](detail::State& s) { s.p.id[0] = s.p.id[1]; }},
      {"non-finite state of particle", [](detail::State& s) { s.p.wx[3] = std::nan(""); }},
      {"radius, mass or inertia", [](detail::State& s) { s.p.inertia[2] = 0; }},
      {"pairs: entry 0 refers to no particle", [](detail::State& s) { s.pairs.a[0] = std::int32_t(s.p.n + 7); }},
      {"bonds: entry 0 refers to no particle", [](detail::State& s) { s.bonds.b[0] = -1; }},
      {"mesh triangle refers to no vertex", [](detail::State& s) { s.walls.meshes[0].triangles[1][2] = 99; }},
      {"particles/group", [](detail::State& s) { s.p.group[5] = 7; }},
      {"settings/dt_interval", [](detail::State& s) { s.settings.dt_interval = 0; }},
  };
  for (const Case& c : cases) {
    World w = World::load([&] { base.save(path); return path; }());
    c.damage(w.state());
    w.save(path);
    const std::string e = load_error(path);
    EXPECT_NE(e.find("is damaged"), std::string::npos) << c.message << ": " << e;
    EXPECT_NE(e.find(c.message), std::string::npos) << c.message << ": " << e;
  }
  std::filesystem::remove(path);
}

namespace {
// A valid value other than v, by the field's range, for every type a settings table holds.
double other_value(const Field& f, double v) {
  for (double c : {v * 1.1, v * 0.9, v + 1, f.range.lo + 1, 0.5 * (f.range.lo + f.range.hi)})
    if (c != v && std::isfinite(c) && f.range.contains(c)) return c;
  return v;
}
int other_value(const Field& f, int v) { return f.range.contains(v + 1) ? v + 1 : v - 1; }
bool other_value(const Field&, bool v) { return !v; }
Vec3 other_value(const Field&, const Vec3& v) { return v + Vec3{0.5, -0.25, 0.125}; }
std::string other_value(const Field&, const std::string& v) { return v; }
ContactMaterial other_value(const Field&, ContactMaterial m) {
  for_each_field(m, [](const Field& f, double& v) { v = other_value(f, v); });
  return m;
}
}  // namespace

// Every setting the table marks as stored comes back from a checkpoint with the value it was
// saved with (each set away from its default, so a field the checkpoint forgot would come back
// as the default); the loader's own (threads, simd) are not taken from the file.
TEST(Checkpoint, EveryStoredSettingComesBackFromTheTable) {
  WorldSettings ws;
  for_each_setting(ws, [](const Field& f, auto& v) { v = other_value(f, v); });
  ws.threads = 1;
  World w(ws);
  w.add_particle({0, 0, 0}, 1e-3);
  const std::string path = temp_file("asperity_checkpoint_settings.h5");
  w.save(path);
  const World back = World::load(path);
  const WorldSettings& got = back.settings();
  const WorldSettings defaults;
  int stored = 0;
  for_each_setting(ws, [&](const Field& f, const auto& v) {
    if (f.stored == nullptr) return;
    ++stored;
    // The same member of the loaded settings, by its offset in the struct.
    const auto offset = reinterpret_cast<const char*>(&v) - reinterpret_cast<const char*>(&ws);
    const auto& loaded = *reinterpret_cast<const std::decay_t<decltype(v)>*>(reinterpret_cast<const char*>(&got) + offset);
    const auto& fallback = *reinterpret_cast<const std::decay_t<decltype(v)>*>(reinterpret_cast<const char*>(&defaults) + offset);
    EXPECT_TRUE(loaded == v) << f.name;
    EXPECT_FALSE(v == fallback) << f.name << " was not moved away from its default";
  });
  EXPECT_GE(stored, 14);
  std::filesystem::remove(path);
}
