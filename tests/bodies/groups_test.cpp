// Rigid groups (model.md 1): prescribed, fixed and free degrees of freedom; member contacts
// excluded; boundary work of the agent that drives them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <random>

#include "asperity/world.hpp"

using namespace asperity;

namespace {
std::vector<std::int64_t> slab(World& w, int n, double z, double R) {
  std::vector<std::int64_t> ids;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) ids.push_back(w.add_particle({i * 1.9 * R, j * 1.9 * R, z}, R));
  return ids;  // neighbours overlap by 0.1 R: their contacts must not be computed
}

// A 3 x 3 slab driven along -x at v towards a free sphere `gap` away; rotation Dof::fixed lets
// the slab's members that touch nothing move lazily (Dof::velocity at zero: never lazy).
struct SlabAndBall {
  std::vector<std::int64_t> slab;
  std::int64_t ball;
  int group;
};
SlabAndBall slab_driven_at_ball(World& w, double R, double v, double gap, Dof rotation) {
  SlabAndBall s;
  s.slab = slab(w, 3, 0, R);
  s.ball = w.add_particle({-2 * R - gap, 0, 0}, R);
  GroupMotion m;
  m.translation = {Dof::velocity, Dof::fixed, Dof::fixed};
  m.velocity = {-v, 0, 0};
  m.rotation = rotation;
  s.group = w.add_group(s.slab, m);
  return s;
}
}  // namespace

TEST(Groups, MemberContactsAreNeverComputed) {
  World w;
  const auto ids = slab(w, 4, 0, 5e-4);
  w.add_group(ids, GroupMotion{{Dof::fixed, Dof::fixed, Dof::fixed}});
  w.cycle(10);
  EXPECT_EQ(w.stats().pairs, 0u);
  EXPECT_EQ(w.contact_count(), 0u);
}

// The neighbour search skips the cells that hold only members of the searching particle's own
// group (neighbor/build.cpp). Two bodies of random spheres that interpenetrate in a band, a few
// free spheres among them: the list must hold exactly the pairs within reach (Ra + Rb + skin)
// that join two different bodies or a free sphere, as a search of every pair finds them.
TEST(Groups, NeighbourListHoldsEveryPairBetweenBodiesAndNoneWithinOne) {
  WorldSettings ws;
  ws.skin = 2e-4;
  World w(ws);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::int64_t> lower, upper, all;
  std::vector<Vec3> at;
  std::vector<double> radius;
  std::vector<int> body;
  for (int k = 0; k < 900; ++k) {
    const Vec3 c{0.006 * u(rng), 0.006 * u(rng), 0.006 * u(rng)};
    const double R = 2e-4 * (1 + 0.5 * u(rng));
    const auto id = w.add_particle(c, R);
    // Lower body below z = 2.5 mm, upper above 3.5 mm (either in the band), free: one in 30.
    const int b = k % 30 == 0 ? -1 : (c.z < 0.0025 ? 0 : c.z > 0.0035 ? 1 : int(k % 2));
    if (b == 0) lower.push_back(id);
    if (b == 1) upper.push_back(id);
    at.push_back(c);
    radius.push_back(R);
    body.push_back(b);
  }
  const GroupMotion fixed{{Dof::fixed, Dof::fixed, Dof::fixed}};
  w.add_group(lower, fixed);
  w.add_group(upper, fixed);
  w.cycle(1);  // the list is built on the positions above, before the step moves anything
  std::size_t expected = 0;
  for (std::size_t i = 0; i < at.size(); ++i)
    for (std::size_t j = i + 1; j < at.size(); ++j) {
      if (body[i] >= 0 && body[i] == body[j]) continue;
      const Vec3 d = at[j] - at[i];
      const double reach = radius[i] + radius[j] + ws.skin;
      expected += dot(d, d) < reach * reach;
    }
  ASSERT_GT(expected, 200u);
  EXPECT_EQ(w.stats().pairs, expected);
}

TEST(Groups, PrescribedVelocityIsFollowedExactly) {
  World w;
  const auto ids = slab(w, 3, 0, 5e-4);
  GroupMotion m;
  m.translation = {Dof::velocity, Dof::fixed, Dof::velocity};
  m.velocity = {2e-5, 7, -1e-5};  // y is fixed: its velocity is ignored
  const int g = w.add_group(ids, m);
  const Vec3 c0 = w.group_position(g), p0 = w.position(ids[4]);
  w.cycle(1000);
  const double t = w.time();
  EXPECT_NEAR(w.group_position(g).x - c0.x, 2e-5 * t, 1e-15);
  EXPECT_EQ(w.group_position(g).y, c0.y);
  EXPECT_NEAR(w.group_position(g).z - c0.z, -1e-5 * t, 1e-15);
  EXPECT_NEAR(w.position(ids[4]).x - p0.x, 2e-5 * t, 1e-15) << "members move with the group";
  EXPECT_EQ(w.velocity(ids[4]).x, 2e-5);
}

// A platen set in motion at rest carries kinetic energy that no boundary work put in; the runaway
// check must take it as the script's doing (as set_velocity does), not as energy created by the
// integration: a fixed platen in an unloaded world, then driven at constant velocity.
TEST(Groups, SettingAPrescribedVelocityIsNotEnergyCreated) {
  World w;
  const auto ids = slab(w, 3, 0, 5e-4);
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  const int g = w.add_group(ids, m);
  w.cycle(300);  // past the first energy check: the reference is the platen at rest
  m.translation = {Dof::fixed, Dof::fixed, Dof::velocity};
  m.velocity = {0, 0, -6e-5};
  w.set_group_motion(g, m);
  EXPECT_NO_THROW(w.cycle(1000));
  EXPECT_LT(w.velocity(ids[0]).z, 0.0);
}

// A group whose rotation is fixed moves its members that touch nothing lazily (issue 7: a rigid
// joint moves its interface, not its volume). They must still be found, at their true positions,
// when something comes within reach: a slab driven into a free sphere gives the same collision as
// a slab whose rotation is prescribed at zero (every member moved every step), to rounding.
TEST(Groups, IdleMembersAreFoundWhenSomethingComes) {
  const double R = 5e-4, v = 1e-3, gap = 2e-4;  // the gap closes after a rebuild (skin 0.4 R)
  struct Run {
    std::vector<double> x, vx;  // the sphere, per step
    std::size_t first_contact = 0;
    Vec3 member;                // a far member of the slab at the end
    Vec3 expected;              // where the prescribed motion puts it
  };
  auto run = [&](Dof rotation) {
    World w;
    const auto [ids, ball, g] = slab_driven_at_ball(w, R, v, gap, rotation);
    const Vec3 far0 = w.position(ids.back());
    Run r;
    for (int k = 1; k <= 400; ++k) {
      w.cycle(1);
      if (r.first_contact == 0 && w.contact_count() > 0) r.first_contact = w.step_count();
      if (k % 100 == 0) {  // reading positions brings idle members up to date: rarely
        r.x.push_back(w.position(ball).x);
        r.vx.push_back(w.velocity(ball).x);
      }
    }
    r.member = w.position(ids.back());
    r.expected = far0 + Vec3{-v * w.time(), 0, 0};
    EXPECT_EQ(w.group_velocity(g).x, -v);
    return r;
  };
  const Run lazy = run(Dof::fixed), eager = run(Dof::velocity);
  ASSERT_GT(lazy.first_contact, 0u) << "the slab reached the sphere";
  EXPECT_EQ(lazy.first_contact, eager.first_contact);
  for (std::size_t k = 0; k < lazy.x.size(); ++k) {
    ASSERT_NEAR(lazy.x[k], eager.x[k], 1e-12 * R) << "step " << 100 * (k + 1);
    ASSERT_NEAR(lazy.vx[k], eager.vx[k], 1e-9 * v) << "step " << 100 * (k + 1);
  }
  EXPECT_LT(lazy.vx.back(), -0.5 * v) << "the sphere was pushed along";
  EXPECT_NEAR(lazy.member.x, lazy.expected.x, 1e-15) << "an idle member read back where the group put it";
  EXPECT_EQ(lazy.member.y, lazy.expected.y);
}

// Reading the energies is no observation that moves anything: a run that reads them at every step
// ends bit for bit where one that never does ends (bringing the idle members up to date at every
// read would round their moves differently). The same slab pushing a sphere, lazily moved.
TEST(Groups, ReadingTheEnergiesDoesNotChangeTheRun) {
  const double R = 5e-4, v = 1e-3, gap = 2e-4;
  auto run = [&](bool read) {
    World w;
    const auto [ids, ball, g] = slab_driven_at_ball(w, R, v, gap, Dof::fixed);
    double kinetic = 0;
    for (int k = 0; k < 400; ++k) {
      w.cycle(1);
      if (read) kinetic += w.energies().kinetic;
    }
    if (read) {
      EXPECT_GT(kinetic, 0.0);
    }
    std::vector<double> out;
    for (auto id : ids) out.push_back(w.position(id).x);
    out.push_back(w.position(ball).x);
    out.push_back(w.velocity(ball).x);
    return out;
  };
  EXPECT_EQ(run(true), run(false));
}

// Two rigid bodies: a pair missed by a build needs them to close a whole skin between them, so a
// body approaching a still one may move a whole skin between builds (free particles: skin / 2
// each), and two approaching bodies half a skin each. Either way the contact must begin on the
// step the gap closes.
TEST(Groups, RigidBodiesRebuildWhenTheyHaveClosedTheSkin) {
  const double R = 5e-4, skin = 2e-4, gap = 1.5 * skin, v = 1e-3;
  auto approach = [&](double v_lower, std::uint64_t& rebuilds) {
    World w;
    w.set_skin(skin);
    const auto lower = slab(w, 3, 0, R), upper = slab(w, 3, 2 * R + gap, R);
    GroupMotion up{{Dof::fixed, Dof::fixed, Dof::velocity}}, low = up;
    up.velocity = {0, 0, -v};
    low.velocity = {0, 0, v_lower};
    const int gl = w.add_group(lower, low), gu = w.add_group(upper, up);
    std::uint64_t closed = 0, first_contact = 0;
    for (int k = 0; k < 400 && first_contact == 0; ++k) {
      w.cycle(1);
      if (w.contact_count() > 0) first_contact = w.step_count(), rebuilds = w.stats().rebuilds;
      if (closed == 0 && w.group_position(gu).z - w.group_position(gl).z < 2 * R) closed = w.step_count();
    }
    // The overlaps a step reports are those of the positions it started from (forces, then
    // motion): one step after the gap closed.
    ASSERT_GT(closed, 0u);
    EXPECT_EQ(first_contact, closed + 1) << "lower body at " << v_lower << " m/s";
  };
  std::uint64_t rebuilds = 0;
  approach(0, rebuilds);
  EXPECT_EQ(rebuilds, 2u) << "the first build and one after a whole skin (skin / 2 would need three)";
  approach(v, rebuilds);
}

// The automatic skin is 0.4 x the mean radius at a build; set_skin(0) returns to it. Two spheres
// 0.3 R apart are one pair within it, none within a skin of 0.1 R.
TEST(Groups, SkinZeroIsAutomaticAgain) {
  const double R = 5e-4;
  World w;
  w.add_particle({0, 0, 0}, R);
  w.add_particle({2.3 * R, 0, 0}, R);
  w.cycle(1);
  EXPECT_EQ(w.stats().pairs, 1u) << "automatic skin 0.4 R";
  w.set_skin(0.1 * R);
  w.cycle(1);
  EXPECT_EQ(w.stats().pairs, 0u) << "skin 0.1 R";
  w.set_skin(0);
  EXPECT_EQ(w.settings().skin, 0.0);
  w.cycle(1);
  EXPECT_EQ(w.stats().pairs, 1u) << "automatic again";
  EXPECT_THROW(w.set_skin(-R), Error);
}

TEST(Groups, FreeGroupFallsWithGravityAndPlatenForceIsTheContactSum) {
  WorldSettings ws;
  ws.gravity = {0, 0, -0.01};
  ws.local_damping = 0;
  World w(ws);
  const auto ids = slab(w, 3, 0, 5e-4);
  const int g = w.add_group(ids);
  const double z0 = w.group_position(g).z;
  const int n = 500;
  w.cycle(n);
  // Leapfrog from rest: z_n = z_0 - g dt^2 n (n + 1) / 2 exactly.
  const double drop = 0.01 * w.dt() * w.dt() * n * (n + 1) / 2;
  EXPECT_NEAR(w.group_position(g).z - z0, -drop, 1e-12 * drop);
  EXPECT_NEAR(w.group_velocity(g).z, -0.01 * w.dt() * n, 1e-12);
  EXPECT_NEAR(w.group_mass(g), 9 * w.mass(ids[0]), 1e-20);
}

TEST(Groups, PlatenPressingASphereOnAFloor) {
  // A platen group pushed down by an applied force onto a sphere lying on a floor: at rest, the
  // group's contact force balances the applied force and the floor carries it.
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  const double R = 5e-4;
  w.add_plane({0, 0, 0}, {0, 0, 1});
  w.add_particle({0, 0, R}, R);
  const auto ids = slab(w, 3, 3 * R, R);
  std::vector<std::int64_t> centred;
  for (auto id : ids) centred.push_back(id);
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::fixed, Dof::free};
  const int g = w.add_group(centred, m);
  // Centre the platen over the sphere.
  (void)g;
  w.set_group_applied_force(g, {0, 0, -2e-5});
  w.cycle(20000);
  EXPECT_NEAR(w.group_force(g).z, 0.0, 1e-9) << "contact force balances the applied force";
  EXPECT_NEAR(w.wall_force(0).z, -2e-5, 1e-9);
}

TEST(Groups, DrivenGroupEnergyBalance) {
  // A platen pushed at constant velocity into a column of spheres on a floor: the agent's work
  // equals what is stored and dissipated.
  WorldSettings ws;
  World w(ws);
  const double R = 5e-4;
  w.add_plane({0, 0, 0}, {0, 0, 1});
  for (int k = 0; k < 4; ++k) w.add_particle({0, 0, R + k * 2 * R * 0.999}, R);
  const auto platen = slab(w, 2, 9.01 * R, R);  // just above the top sphere
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::fixed, Dof::velocity};
  m.velocity = {0, 0, -2e-6};
  const int g = w.add_group(platen, m);
  w.cycle(5);
  const Energies e0 = w.energies();
  w.cycle(30000);
  const Energies e = w.energies();
  const double input = e.boundary_work - e0.boundary_work;
  ASSERT_GT(input, 0);
  EXPECT_LT(std::fabs(e.balance_error(e0)), 0.01 * input);
  EXPECT_GT(w.group_force(g).z, 0) << "the column pushes back";
}

// A group whose members run away stops the run naming one of them (step.cpp, bookkeep, from the
// moves stage's record of each moved member): a free slab whose members each carry the largest
// finite force has an infinite resultant, hence a position that is not finite after the first step.
TEST(Groups, ARunawayGroupStopsTheRunNamingAMember) {
  World w;
  const auto ids = slab(w, 4, 0, 5e-4);
  const int g = w.add_group(ids, GroupMotion{});
  for (auto id : ids) w.set_applied_force(id, {std::numeric_limits<double>::max(), 0, 0});
  try {
    w.cycle(2);
    FAIL() << "a group at a non-finite position must stop the run";
  } catch (const HealthError& e) {
    EXPECT_EQ(e.step, 1u);
    EXPECT_EQ(e.quantity, "x");
    EXPECT_NE(std::find(ids.begin(), ids.end(), e.particle_id), ids.end()) << e.particle_id;
    EXPECT_NE(std::string(e.what()).find("non-finite position"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::isfinite(w.group_position(g).x));
}

TEST(Groups, BadInputIsRefusedWithAReason) {
  World w;
  const auto a = w.add_particle({0, 0, 0}, 5e-4);
  w.add_group(std::vector<std::int64_t>{a});
  try {
    w.add_group(std::vector<std::int64_t>{a});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("already belongs to group 0"), std::string::npos);
  }
  EXPECT_THROW(w.add_group(std::vector<std::int64_t>{42}), Error);
  EXPECT_THROW(w.group_force(3), Error);
  EXPECT_THROW(w.set_velocity(a, {1, 0, 0}), Error) << "members move with their group";
}

namespace {
// A small bonded joint: two platens (rigid groups of 4 x 4 spheres) and two free layers between,
// every touching pair bonded. The upper platen shears along x under a servo-held normal force.
struct BondedSandwich {
  World w;
  std::vector<std::int64_t> bottom, top, free;
  int g_bottom = -1, g_top = -1;
};

BondedSandwich bonded_sandwich(bool bonds_before_groups, Dof top_rotation = Dof::fixed) {
  const double R = 5e-4, h = 1.9 * R;  // neighbours overlap by 0.1 R
  WorldSettings ws;
  ws.dt = 2e-4;
  BondedSandwich s{World(ws), {}, {}, {}};
  for (int layer = 0; layer < 4; ++layer)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const auto id = s.w.add_particle({i * h, j * h, layer * h}, R);
        (layer == 0 ? s.bottom : layer == 3 ? s.top : s.free).push_back(id);
      }
  BondMaterial bm;
  bm.breakable = false;
  GroupMotion fixed{{Dof::fixed, Dof::fixed, Dof::fixed}};
  // The upper platen's load is servo-held: its motion follows the sum of its members' forces.
  GroupMotion shear{{Dof::velocity, Dof::fixed, Dof::servo}, {2e-4, 0, 0}};
  shear.servo[2].target_force = 2e-5;
  shear.rotation = top_rotation;
  // The first build renumbers the particles: made here, before the groups, in both variants, so
  // that both number them alike (members come after free particles once groups exist).
  s.w.rebuild_neighbors();
  if (bonds_before_groups) s.w.install_bonds(bm);
  s.g_bottom = s.w.add_group(s.bottom, fixed);
  s.g_top = s.w.add_group(s.top, shear);
  if (!bonds_before_groups) s.w.install_bonds(bm);  // members of one group are never paired
  return s;
}
}  // namespace

// A bond with both ends in one rigid group that does not turn cannot deform, and its forces cancel
// within the body: the step leaves it out (State::frozen_bonds). The same joint bonded before the
// groups were made (platens bonded inside) and after (no bond inside a platen) must then move
// bit for bit alike, while the first still reports every bond.
TEST(Groups, BondsInsideAStillGroupLeaveTheStepAndChangeNothing) {
  BondedSandwich inside = bonded_sandwich(true), without = bonded_sandwich(false);
  const std::size_t per_platen = 2 * 4 * 3;  // a 4 x 4 square's touching neighbours
  ASSERT_EQ(inside.w.bond_count(), without.w.bond_count() + 2 * per_platen);
  const std::vector<BondInfo> before = inside.w.bonds();
  inside.w.cycle(400);
  without.w.cycle(400);
  EXPECT_EQ(inside.w.stats().frozen_bonds, 2 * per_platen);
  EXPECT_EQ(without.w.stats().frozen_bonds, 0u);
  EXPECT_EQ(inside.w.bond_count(), without.w.bond_count() + 2 * per_platen);
  const auto xi = inside.w.positions(), xw = without.w.positions();
  ASSERT_EQ(xi.size(), xw.size());
  for (std::size_t k = 0; k < xi.size(); ++k) ASSERT_EQ(xi[k], xw[k]) << "coordinate " << k;
  EXPECT_EQ(inside.w.group_force(inside.g_top), without.w.group_force(without.g_top));
  EXPECT_GT(std::abs(without.w.group_force(without.g_top).x), 0.0) << "the free layers resist";
  EXPECT_NE(inside.w.group_position(inside.g_top).z, 3 * 1.9 * 5e-4) << "the servo moved the platen";
  // A frozen bond keeps the state it had: a platen's inner bond reads as installed.
  const std::vector<BondInfo> after = inside.w.bonds();
  ASSERT_EQ(after.size(), before.size());
  std::size_t platen_bonds = 0;
  for (std::size_t k = 0; k < after.size(); ++k) {
    const int ga = inside.w.group_of(after[k].id_a), gb = inside.w.group_of(after[k].id_b);
    if (ga < 0 || ga != gb) continue;
    ++platen_bonds;
    EXPECT_EQ(after[k].normal_force, before[k].normal_force);
    EXPECT_EQ(after[k].shear_force, before[k].shear_force);
  }
  EXPECT_EQ(platen_bonds, 2 * per_platen);
}

// A group that may turn computes its inner bonds again (their forces turn with it); a checkpoint
// holds frozen and computed bonds in one list and the loaded run freezes the same ones.
TEST(Groups, FrozenBondsThawWhenTheGroupMayTurnAndSurviveACheckpoint) {
  BondedSandwich s = bonded_sandwich(true);
  s.w.cycle(100);
  ASSERT_EQ(s.w.stats().frozen_bonds, 48u);
  const std::string path =
      (std::filesystem::temp_directory_path() / "asperity_frozen_bonds_test.h5").string();
  s.w.save(path);
  World r = World::load(path, 1, s.w.simd_architecture());
  std::filesystem::remove(path);
  EXPECT_EQ(r.bond_count(), s.w.bond_count());
  s.w.cycle(200);
  r.cycle(200);
  EXPECT_EQ(r.stats().frozen_bonds, 48u);
  EXPECT_EQ(r.positions(), s.w.positions());

  GroupMotion turning = s.w.group_motion(s.g_top);
  turning.rotation = Dof::free;
  s.w.set_group_motion(s.g_top, turning);
  s.w.cycle(1);
  EXPECT_EQ(s.w.stats().frozen_bonds, 24u) << "the bottom platen's stay frozen";
  s.w.cycle(200);
  EXPECT_EQ(s.w.bond_count(), r.bond_count());
  for (double x : s.w.positions()) ASSERT_TRUE(std::isfinite(x));
}
