// Two-body contact against its closed form (model.md 4): a head-on collision of two equal spheres
// with a linear spring lasts half a period of the reduced-mass oscillator, pi sqrt(m_eff / kn),
// and without damping the spheres leave with the speed they came in with.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "asperity/world.hpp"
#include "report.hpp"

using namespace asperity;
using asperity::test::report;

namespace {
struct CollisionResult {
  double duration;
  double rebound_speed;
  double dt;
};

CollisionResult collide(double speed, Vec3 axis, bool rotation) {
  WorldSettings ws;
  ws.local_damping = 0;
  ws.rotation = rotation;
  World w(ws);
  const double R = 5e-4;
  const Vec3 u = axis / norm(axis);
  const auto a = w.add_particle(u * -0.6e-3, R);
  const auto b = w.add_particle(u * 0.6e-3, R);
  w.set_velocity(a, u * speed);
  w.set_velocity(b, u * -speed);
  const double m_eff = w.mass(a) / 2;
  const double T = std::numbers::pi * std::sqrt(m_eff / ws.contact.kn);
  w.set_dt(T / 1000);
  double first = -1, last = -1;
  for (int k = 0; k < 20000; ++k) {
    w.cycle(1);
    if (w.contact_count() > 0) {
      if (first < 0) first = w.time();
      last = w.time();
    } else if (first >= 0) {
      break;
    }
  }
  return {last - first + w.dt(), norm(w.velocity(b)), w.dt()};
}
}  // namespace

TEST(Collision, DurationAndReboundMatchTheLinearSpring) {
  const double speed = 1e-3;
  const auto r = collide(speed, {1, 0, 0}, true);
  const double m = 2500 * 4.0 / 3.0 * std::numbers::pi * std::pow(5e-4, 3);
  const double expected = std::numbers::pi * std::sqrt(m / 2 / 0.1);
  report("contact duration [s] vs pi sqrt(m_eff/kn)", r.duration, expected);
  report("rebound speed / impact speed", r.rebound_speed / speed, 1.0);
  EXPECT_NEAR(r.duration, expected, r.dt) << "contact duration vs pi sqrt(m_eff/kn)";
  EXPECT_NEAR(r.rebound_speed / speed, 1.0, 1e-4) << "rebound speed / impact speed";
}

TEST(Collision, ObliqueAxisAndNoRotationGiveTheSameClosedForm) {
  const double speed = 2e-3;
  const auto r = collide(speed, {1, 2, -3}, false);
  const double m = 2500 * 4.0 / 3.0 * std::numbers::pi * std::pow(5e-4, 3);
  EXPECT_NEAR(r.duration, std::numbers::pi * std::sqrt(m / 2 / 0.1), r.dt);
  EXPECT_NEAR(r.rebound_speed / speed, 1.0, 1e-4);
}

TEST(Collision, NormalForceIsSpringTimesOverlapAndActsOnB) {
  WorldSettings ws;
  ws.local_damping = 0;
  World w(ws);
  const auto a = w.add_particle({0, 0, 0}, 5e-4);
  const auto b = w.add_particle({0, 0, 0.9e-3}, 5e-4);  // overlap 0.1 mm
  w.set_dt(1e-12);  // so short that nothing moves measurably during the step
  w.cycle(1);
  const auto c = w.contacts();
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].overlap, 1e-4, 1e-15);
  EXPECT_NEAR(c[0].normal_force, 0.1 * 1e-4, 1e-18);
  EXPECT_NEAR(c[0].normal.z, 1.0, 1e-15);
  EXPECT_NEAR(w.force(b).z, 1e-5, 1e-18);   // pushed away from a: +z
  EXPECT_NEAR(w.force(a).z, -1e-5, 1e-18);
  EXPECT_NEAR(c[0].point.z, 0.45e-3, 1e-15);  // [3-11]: xA + (RA - U/2) n
}
