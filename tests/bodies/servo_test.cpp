// Loading control (model.md 7): the CNL and CNS servo on a group's normal degree of freedom,
// inert members of a rigid body, and contact summaries between tagged particle sets.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <cstdio>
#include <utility>
#include <numbers>

#include "asperity/world.hpp"
#include "state.hpp"

using namespace asperity;

namespace {
constexpr double kR = 5e-4;

// A 4 x 4 x 3 lattice of spheres on a floor plane, under a 5 x 5 platen group.
struct Column {
  World w;
  int platen;
  std::vector<std::int64_t> bed, top, cover;
};

// With `cover`, a second platen layer above the first: it can never touch anything.
Column column(GroupMotion motion, bool cover = false) {
  WorldSettings ws;
  ws.rotation = false;
  Column c{World(ws), -1, {}, {}, {}};
  c.w.add_plane({0, 0, 0}, {0, 0, 1});
  const double a = 1.98 * kR;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k)
        c.bed.push_back(c.w.add_particle({(i + 0.5) * a, (j + 0.5) * a, kR + k * a}, kR));
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      c.top.push_back(c.w.add_particle({i * a, j * a, kR + 2 * a + 2.02 * kR}, kR));
  std::vector<std::int64_t> members = c.top;
  if (cover)
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j) {
        c.cover.push_back(c.w.add_particle({i * a, j * a, kR + 3 * a + 2.02 * kR}, kR));
        members.push_back(c.cover.back());
      }
  c.platen = c.w.add_group(members, motion);
  return c;
}

// A 5 x 5 platen group over a floor plane (its members at height `z`), dt 1e-3 s: the scene of
// the servo dynamics tests below.
struct PlatenOnFloor {
  World w;
  int floor;
  int platen;
};

PlatenOnFloor platen_on_floor(const GroupMotion& motion, double z, int dt_interval = 100) {
  WorldSettings ws;
  ws.rotation = false;
  ws.dt = 1e-3;
  ws.dt_interval = dt_interval;
  PlatenOnFloor f{World(ws), -1, -1};
  f.floor = f.w.add_plane({0, 0, 0}, {0, 0, 1});
  std::vector<std::int64_t> members;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) members.push_back(f.w.add_particle({i * 2.2 * kR, j * 2.2 * kR, z}, kR));
  f.platen = f.w.add_group(members, motion);
  return f;
}

GroupMotion servo_z(double target, double stiffness = 0) {
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::fixed, Dof::servo};
  m.servo[2].target_force = target;
  m.servo[2].stiffness = stiffness;
  m.servo[2].max_velocity = 1e-4;
  return m;
}
}  // namespace

TEST(Servo, ConstantNormalLoadIsHeldWithinOnePercent) {
  const double target = 2e-5;
  Column c = column(servo_z(target));
  c.w.cycle(20000);
  EXPECT_NEAR(c.w.group_force(c.platen).z, target, 0.001 * target) << "settled on the target";
  EXPECT_NEAR(c.w.wall_force(0).z, -target, 0.01 * target) << "the floor carries the load";
  // Double the load: the servo follows, and stays within 1 % once there.
  GroupMotion m = servo_z(2 * target);
  c.w.set_group_motion(c.platen, m);
  c.w.cycle(20000);
  double worst = 0;
  for (int k = 0; k < 50; ++k) {
    c.w.cycle(100);
    worst = std::max(worst, std::fabs(c.w.group_force(c.platen).z / (2 * target) - 1));
  }
  EXPECT_LT(worst, 0.01);
  // The impulse is the sum of group_force x dt: its change over a stretch of steps, divided by the
  // elapsed time, is the mean force the platen carried, what a filtered load cell reads.
  const Vec3 j0 = c.w.group_impulse(c.platen);
  const double t0 = c.w.time();
  double sum = 0;
  for (int k = 0; k < 500; ++k) {
    c.w.cycle(1);
    sum += c.w.group_force(c.platen).z * c.w.dt();
  }
  const double mean = (c.w.group_impulse(c.platen).z - j0.z) / (c.w.time() - t0);
  // Equal up to the rounding of 500 additions to the running total (which is larger than `sum`).
  const double total = std::fabs(c.w.group_impulse(c.platen).z);
  EXPECT_NEAR(c.w.group_impulse(c.platen).z - j0.z, sum, 500 * std::numeric_limits<double>::epsilon() * total);
  EXPECT_GT(std::fabs(sum), 1e-3 * total) << "the stretch is not lost in the rounding of the total";
  EXPECT_NEAR(mean, 2 * target, 0.01 * target);
}

TEST(Servo, ConstantNormalStiffnessTargetFollowsTheDisplacement) {
  const double F0 = 1e-5, K = 0.05;
  Column c = column(servo_z(F0, K));
  const double z0 = c.w.group_position(c.platen).z;
  c.w.cycle(30000);
  const double dz = c.w.group_position(c.platen).z - z0;
  EXPECT_LT(dz, 0) << "the platen moved down onto the bed";
  EXPECT_NEAR(c.w.group_force(c.platen).z, F0 + K * dz, 0.002 * F0);
}

// A platen pressed on a floor that sinks at a steady rate u (the way a dilating joint asks the
// platen to rise): the proportional servo must move at u, so it lags by e = u / G with
// G = relaxation / (K dt) [model.md 7]; integral action removes the lag.
TEST(Servo, IntegralActionRemovesTheLagOfASteadyRamp) {
  // A gentle gain (relaxation 0.2), whose proportional lag is over 1 % of the target.
  const double target = 2e-5, u = 3e-5, relaxation = 0.2;
  auto run = [&](double integral_steps) {
    GroupMotion m = servo_z(target);
    m.servo[2].relaxation = relaxation;
    m.servo[2].integral_time = integral_steps * 1e-3;
    auto [w, floor, platen] = platen_on_floor(m, 0.99 * kR);
    w.cycle(20000);  // settle on the target
    w.set_wall_velocity(floor, {0, 0, -u});
    w.cycle(20000);
    double lo = 1e300, hi = -1e300;
    for (int k = 0; k < 100; ++k) {
      w.cycle(10);
      const double e = w.group_force(platen).z - target;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    EXPECT_NEAR(w.group_velocity(platen).z, -u, 1e-3 * u) << "the platen follows the floor";
    return std::make_pair(lo, hi);
  };
  const double K = 25 * 0.1, G = relaxation / (K * 1e-3);  // 25 wall contacts of kn = 0.1 N/m
  const auto [plo, phi] = run(0);
  EXPECT_NEAR(plo, -u / G, 1e-6 * u / G) << "proportional servo: steady lag u / G";
  EXPECT_NEAR(phi, -u / G, 1e-6 * u / G);
  EXPECT_GT(u / G, 0.01 * target) << "a lag of more than 1 %: the case integral action is for";
  double pi_dev = 0;
  for (double steps : {2.0, 20.0}) {
    const auto [lo, hi] = run(steps);
    const double dev = std::max(std::fabs(lo), std::fabs(hi));
    EXPECT_LT(dev, 1e-6 * target) << "integral time " << steps << " steps";
    if (steps == 2.0) pi_dev = dev / target;
  }
  std::printf("[figure] servo on a floor sinking at u: lag P-only %.4g of the target (u/G = %.4g); "
              "with integral time 2 steps: %.2g\n", -plo / target, u / G / target, pi_dev);
}

// The automatic gain needs the stiffness the platen meets at this step. Estimated only with the
// time step (every dt_interval steps), it was zero from before the touch: the servo ran at
// +-max_velocity, ringing between 28 % and 102 % of the load (the rigid joint's hold).
TEST(Servo, GainFollowsTheContactsOfEveryStep) {
  const double target = 2e-5;
  GroupMotion m = servo_z(target);
  m.servo[2].max_velocity = 1e-2;  // 1e-5 m per step: more than the 8e-6 m overlap of the target
  // Estimates (every dt_interval steps) far apart: the servo must not wait for them.
  auto [w, floor, platen] = platen_on_floor(m, kR + 5e-5, 1000);
  w.cycle(60);  // out of contact for a few steps, then touching
  double worst = 0;
  for (int k = 0; k < 40; ++k) {
    w.cycle(1);
    worst = std::max(worst, std::fabs(w.group_force(platen).z / target - 1));
  }
  EXPECT_LT(worst, 1e-3) << "settled within 60 steps and held";
}

// The stiffness the servo's gain divides by (stages/groups.cpp): per body, kn for each touching
// contact with another body, kn + beam_kn for each bond to another body, the wall's kn for each
// wall contact. A 3 x 3 platen (servo) pressed 1 % onto a 3 x 3 layer held as a second body, which
// rests on a third free layer; five of the nine pairs of each interface bonded, and a side wall
// touching both bodies. Both bodies' sums equal the counts over the world's contacts and bonds.
TEST(Servo, StiffnessCountsEveryContactAndBondWithAnotherBody) {
  WorldSettings ws;
  ws.rotation = false;
  World w(ws);
  const double a = 2 * kR;
  std::vector<std::int64_t> platen, middle, bottom, half;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      bottom.push_back(w.add_particle({i * a, j * a, kR}, kR));
      middle.push_back(w.add_particle({i * a, j * a, kR + 0.99 * a}, kR));
      platen.push_back(w.add_particle({i * a, j * a, kR + 1.98 * a}, kR));
      if ((i + j) % 2 == 0) half.insert(half.end(), {bottom.back(), middle.back(), platen.back()});
    }
  w.add_plane({0, 0, 0}, {0, 0, 1});
  ContactMaterial wall_material;
  wall_material.kn = 0.37;
  w.add_plane({-0.99 * kR, 0, 0}, {1, 0, 0}, wall_material);  // touches the column i = 0 of each layer
  BondMaterial bm;
  bm.beam_kn = 0.23;
  bm.tensile_strength = 1e9;
  ASSERT_GT(w.install_bonds(bm, 1e-6, half), 0u);
  const int top = w.add_group(platen, servo_z(2e-5));
  GroupMotion held;
  held.translation = {Dof::fixed, Dof::fixed, Dof::fixed};
  const int mid = w.add_group(middle, held);
  auto body = [&](std::int64_t id) {
    for (auto p : platen) if (p == id) return top;
    for (auto p : middle) if (p == id) return mid;
    return -1;
  };
  auto expected = [&](int g) {
    const double kn = ws.contact.kn;
    double K = 3 * wall_material.kn;  // the side wall's contacts (three members of either body)
    for (const ContactInfo& c : w.contacts())
      if (body(c.id_a) != body(c.id_b) && (body(c.id_a) == g || body(c.id_b) == g)) K += kn;
    for (const BondInfo& b : w.bonds())
      if (body(b.id_a) != body(b.id_b) && (body(b.id_a) == g || body(b.id_b) == g)) K += kn + bm.beam_kn;
    return K;
  };
  w.cycle(1);
  const auto& groups = w.state().groups;
  EXPECT_NEAR(groups[top].contact_stiffness, expected(top), 1e-12);
  EXPECT_NEAR(groups[mid].contact_stiffness, expected(mid), 1e-12);
  // Not vacuous: both interfaces hold contacts and bonds, and the side wall touches three
  // members of each body.
  EXPECT_NEAR(expected(top), 9 * ws.contact.kn + 5 * bm.beam_kn + 3 * wall_material.kn, 1e-12);
  EXPECT_NEAR(expected(mid), 18 * ws.contact.kn + 10 * bm.beam_kn + 3 * wall_material.kn, 1e-12);
  EXPECT_EQ(w.stats().wall_contacts, 9u) << "the side wall touches column i = 0 of the three layers";
}

// Setting the motion again with the servo unchanged (as a shear test does when it changes the
// shear velocity) keeps the integral: the platen on a sinking floor stays on its target. Changing
// the target restarts it.
TEST(Servo, ResettingAnUnchangedServoKeepsItsIntegral) {
  const double target = 2e-5, u = 3e-5;
  GroupMotion m = servo_z(target);
  m.servo[2].integral_time = 2e-3;                 // two steps
  m.translation[0] = Dof::velocity;  // x: the "shear" axis, velocity changed below
  auto [w, floor, platen] = platen_on_floor(m, 0.99 * kR);
  w.set_wall_velocity(floor, {0, 0, -u});
  w.cycle(20000);
  auto worst_after = [&](const GroupMotion& again) {
    w.set_group_motion(platen, again);
    double worst = 0;
    for (int k = 0; k < 50; ++k) {
      w.cycle(1);
      worst = std::max(worst, std::fabs(w.group_force(platen).z / again.servo[2].target_force - 1));
    }
    return worst;
  };
  GroupMotion same = m;
  same.velocity = {1e-6, 0, 0};
  EXPECT_LT(worst_after(same), 1e-6) << "integral kept";
  GroupMotion other = same;
  other.servo[2].target_force = 1.001 * target;
  w.cycle(100);
  EXPECT_GT(worst_after(other), 1e-3) << "a new target starts the integral again (lag u / G > 1 %)";
}

TEST(Servo, BadServoParametersAreRefused) {
  GroupMotion m = servo_z(1e-5);
  m.servo[2].max_velocity = 0;
  EXPECT_THROW(column(m), Error);
  m = servo_z(1e-5);
  m.servo[2].relaxation = 2;
  EXPECT_THROW(column(m), Error);
  m = servo_z(1e-5);
  m.servo[2].integral_time = -1;
  EXPECT_THROW(column(m), Error);
}

TEST(Inert, InteriorOfARigidBodyIsNeitherSearchedNorChanged) {
  // The platen's upper members cannot touch anything: made inert, the run is the same to
  // rounding, they follow the group exactly, and they are not in the neighbour list.
  GroupMotion m;
  m.translation = {Dof::fixed, Dof::fixed, Dof::velocity};
  m.velocity = {0, 0, -2e-6};
  auto build = [&](bool inert) {
    Column c = column(m, true);
    if (inert) c.w.set_inert(c.cover);
    std::vector<std::int64_t> corners{c.cover[0], c.cover[24]};
    return std::make_pair(std::move(c), corners);
  };
  auto [plain, corners] = build(false);
  auto [lazy, corners2] = build(true);
  EXPECT_EQ(lazy.w.inert_count(), 25u);
  const Vec3 p0 = lazy.w.position(corners[0]);
  const double g0 = lazy.w.group_position(lazy.platen).z;
  plain.w.cycle(3000);
  lazy.w.cycle(3000);
  EXPECT_EQ(lazy.w.stats().pairs, plain.w.stats().pairs);
  EXPECT_NEAR(lazy.w.group_force(lazy.platen).z, plain.w.group_force(plain.platen).z,
              1e-9 * std::fabs(plain.w.group_force(plain.platen).z));
  const Vec3 p1 = lazy.w.position(corners[0]);
  EXPECT_NEAR(p1.z - p0.z, lazy.w.group_position(lazy.platen).z - g0, 1e-15)
      << "inert members follow the group when read";
  EXPECT_NEAR(p1.z, plain.w.position(corners[0]).z, 1e-15);
  EXPECT_THROW(lazy.w.set_inert(std::vector<std::int64_t>{lazy.bed[0]}), Error)
      << "only group members can be inert";
}

TEST(ContactSummary, CountsAreaAndForceBetweenTags) {
  World w;
  const auto a = w.add_particle({0, 0, 0}, kR);
  const auto b = w.add_particle({0, 0, 1.9 * kR}, 1.2 * kR);  // overlap U = 0.3 R
  const auto c = w.add_particle({5e-3, 0, 0}, kR);
  w.set_tag(std::vector<std::int64_t>{b}, 1);
  w.set_flags(std::vector<std::int64_t>{a}, 2);
  (void)c;
  w.set_dt(1e-9);
  w.cycle(1);
  const ContactSummary s = w.contact_summary(0, 1, 2);
  ASSERT_EQ(s.count, 1u);
  const double U = 0.3 * kR, Rm = 1.1 * kR;
  EXPECT_NEAR(s.area, std::numbers::pi * (Rm * U - U * U / 4), 1e-18);  // [4-1]
  EXPECT_NEAR(s.force.z, 0.1 * U, 1e-12) << "pushes the tag-1 particle up";
  EXPECT_EQ(s.flagged_count, 1u);
  EXPECT_EQ(w.contact_summary(1, 0).force.z, -s.force.z);
  EXPECT_EQ(w.contact_summary(0, 2).count, 0u);
}
