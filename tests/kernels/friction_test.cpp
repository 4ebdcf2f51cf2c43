// Coulomb friction [3-22]: a sphere (rotation locked) pressed on a plane by N and pulled
// tangentially by T sticks for T < mu N (held by the shear spring at T / ks) and slides for
// T > mu N with acceleration (T - mu N) / m.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "asperity/world.hpp"
#include "report.hpp"

using namespace asperity;
using asperity::test::report;

namespace {
constexpr double kR = 5e-4, kN = 1e-5, kMu = 0.5;

World sphere_on_plane(double tangential, double damping, std::int64_t& id) {
  WorldSettings ws;
  ws.local_damping = damping;
  ws.rotation = false;
  World w(ws);
  w.add_plane({0, 0, 0}, {0, 0, 1});
  id = w.add_particle({0, 0, kR - kN / 0.1}, kR);
  w.set_applied_force(id, {tangential, 0, -kN});
  w.set_dt(0.05 * w.critical_dt());
  return w;
}
}  // namespace

TEST(Friction, SticksBelowTheCoulombLimit) {
  // Applied at once, the load overshoots: with local damping alpha the first peak of the shear
  // spring is (1 + sqrt((1 - alpha) / (1 + alpha))) T = 1.42 T, so T = 0.6 mu N never slips
  // (0.9 mu N does, briefly, and correctly).
  const double T = 0.6 * kMu * kN;
  std::int64_t id;
  World w = sphere_on_plane(T, 0.7, id);
  w.cycle(40000);
  report("stick at T = 0.6 mu N: displacement [m] vs T/ks", w.position(id).x, T / 0.01);
  EXPECT_NEAR(w.position(id).x, T / 0.01, 1e-6 * T / 0.01) << "held by the shear spring at T/ks";
  EXPECT_NEAR(w.velocity(id).x, 0.0, 1e-9);
  EXPECT_NEAR(w.wall_force(0).x, T, 1e-9 * T) << "the plane holds the full tangential force";
  EXPECT_EQ(w.energies().friction, 0.0) << "no slip, no friction dissipation";
}

TEST(Friction, SlidesAboveTheCoulombLimit) {
  const double T = 1.5 * kMu * kN;
  std::int64_t id;
  World w = sphere_on_plane(T, 0.0, id);
  w.cycle(500);  // sliding by now
  const double v1 = w.velocity(id).x, t1 = w.time();
  w.cycle(1000);
  const double v2 = w.velocity(id).x, t2 = w.time();
  EXPECT_NEAR(w.wall_force(0).x, kMu * kN, 1e-12 * kMu * kN) << "shear force capped at mu N";
  const double accel = (T - kMu * kN) / w.mass(id);
  report("slide at T = 1.5 mu N: wall shear force [N] vs mu N", w.wall_force(0).x, kMu * kN);
  report("slide at T = 1.5 mu N: acceleration [m/s^2] vs (T - mu N)/m", (v2 - v1) / (t2 - t1), accel);
  EXPECT_NEAR((v2 - v1) / (t2 - t1), accel, 1e-6 * accel);
  EXPECT_GT(w.energies().friction, 0.0);
}

TEST(Friction, SetFrictionChangesTheBallBallSlipLimit) {
  // Sphere B rests on sphere A (fixed), pressed by N along the line of centres and pulled by
  // T = 0.24 N sideways: it sticks at mu = 0.5 (the undamped shear spring peaks at 2 T < mu N);
  // after set_friction(0.1) it slides with the contact's shear force at 0.1 Fn. Stiff springs keep
  // the overlap and the stick displacement far below R, so the geometry stays put.
  const double k = 100.0;
  WorldSettings ws;
  ws.local_damping = 0.0;
  ws.rotation = false;
  ws.contact = {k, k, kMu};
  World w(ws);
  const std::int64_t a = w.add_particle({0, 0, 0}, kR);
  const std::int64_t b = w.add_particle({0, 0, 2 * kR - kN / k}, kR);
  const std::int64_t fixed[] = {a};
  w.add_group(fixed, GroupMotion{{Dof::fixed, Dof::fixed, Dof::fixed}});
  const double T = 0.24 * kN;
  w.set_applied_force(b, {T, 0, -kN});
  w.set_dt(0.05 * w.critical_dt());
  w.cycle(2000);
  EXPECT_LT(w.position(b).x, 2.01 * T / k) << "mu = 0.5 holds T = 0.24 N";
  EXPECT_EQ(w.energies().friction, 0.0) << "no slip while mu = 0.5";
  EXPECT_THROW(w.set_friction(-0.1), Error);
  w.set_friction(0.1);
  w.cycle(300);
  const auto c = w.contacts();
  ASSERT_EQ(c.size(), 1u);
  const double fs = std::sqrt(c[0].shear_force.x * c[0].shear_force.x +
                              c[0].shear_force.y * c[0].shear_force.y +
                              c[0].shear_force.z * c[0].shear_force.z);
  report("set_friction(0.1): |Fs| [N] vs 0.1 Fn", fs, 0.1 * c[0].normal_force);
  EXPECT_NEAR(fs, 0.1 * c[0].normal_force, 1e-12 * kN) << "sliding at the new limit";
  EXPECT_GT(w.velocity(b).x, 0.0);
  EXPECT_GT(w.energies().friction, 0.0);
}

TEST(Friction, ASpinningSphereShearsItsContactInTheFirstStep) {
  // The pair stage leaves the spin terms out when no particle a pair can reach turns
  // (stages/pairs.cpp); a spin set through the API must still drive the law's relative velocity
  // at once: A turns about x at w, B rests on it along z, so at the contact point
  // V = -la (wA x n) = (0, la w, 0) and the first step's shear force on B is -ks V dt [3-19].
  // An inert spinning particle far away (never in a pair) must not matter either way, nor a crowd
  // of resting particles out of reach (then the stage asks the pairs' particles, not all).
  for (int variant = 0; variant < 3; ++variant) {
    const bool bystander = variant == 1, crowd = variant == 2;
    WorldSettings ws;
    ws.contact = {1e3, 2e2, 0.5};
    ws.reorder_interval = 0;
    World w(ws);
    const double R = 5e-4, U = 1e-5, omega = 0.3;
    const auto a = w.add_particle({0, 0, 0}, R);
    w.add_particle({0, 0, 2 * R - U}, R);
    if (bystander) {
      const auto far = w.add_particle({0.1, 0.1, 0.1}, R);
      w.set_angular_velocity(far, {1, 2, 3});
      const std::vector<std::int64_t> ids{far};
      w.add_group(ids);  // inert particles belong to a rigid body
      w.set_inert(ids);
    }
    if (crowd)
      for (int k = 0; k < 20; ++k) w.add_particle({0.01 * (k + 1), 0.02, 0}, R);
    w.set_angular_velocity(a, {omega, 0, 0});
    const double dt = w.critical_dt() / 10;
    w.set_dt(dt);
    w.cycle(1);
    const auto c = w.contacts();
    ASSERT_EQ(c.size(), 1u);
    const double la = R - 0.5 * U;
    EXPECT_NEAR(c[0].shear_force.y, -ws.contact.ks * (la * omega) * dt, 1e-12 * ws.contact.ks * la * omega * dt)
        << (bystander ? "with an inert spinning particle" : crowd ? "in a crowd" : "alone");
    EXPECT_EQ(c[0].shear_force.x, 0.0);
  }
}
