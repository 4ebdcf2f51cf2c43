// Energy (model.md 8): an undamped elastic system keeps its total energy bounded with no drift;
// a quasi-static compression closes the balance W = dEk + dEs + E_friction + E_damping.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "asperity/world.hpp"
#include "report.hpp"

using namespace asperity;
using asperity::test::report;

namespace {
// n^3 spheres on a compressed simple cubic lattice inside six planes.
World lattice(int n, double damping, double friction, bool rotation, double jiggle) {
  WorldSettings ws;
  ws.local_damping = damping;
  ws.contact.friction = friction;
  ws.rotation = rotation;
  World w(ws);
  const double R = 5e-4, a = 0.99 * 2 * R, L = n * a;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const auto id = w.add_particle({(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a}, R);
        w.set_velocity(id, {jiggle * u(rng), jiggle * u(rng), jiggle * u(rng)});
      }
  for (int d = 0; d < 3; ++d) {
    Vec3 nrm{0, 0, 0};
    if (d == 0) nrm.x = 1;
    if (d == 1) nrm.y = 1;
    if (d == 2) nrm.z = 1;
    w.add_plane({0, 0, 0}, nrm, ws.contact);
    w.add_plane(nrm * L, -nrm, ws.contact);
  }
  return w;
}
}  // namespace

namespace {
// Largest relative deviation of Ek + Es from its start over `steps`, and the relative change of
// its mean between the first and the last tenth of the run.
void measure(World& w, int steps, double& worst, double& drift) {
  w.cycle(1);
  const Energies e0 = w.energies();
  const double total0 = e0.kinetic + e0.strain;
  ASSERT_GT(total0, 0);
  const int samples = 1000, every = steps / samples;
  double first = 0, last = 0;
  worst = 0;
  for (int k = 0; k < samples; ++k) {
    w.cycle(every);
    const Energies e = w.energies();
    const double total = (e.kinetic + e.strain) / total0;
    worst = std::max(worst, std::fabs(total - 1));
    if (k < samples / 10) first += total / (samples / 10);
    if (k >= samples - samples / 10) last += total / (samples / 10);
  }
  drift = std::fabs(last / first - 1);
}
}  // namespace

TEST(Energy, UndampedFrictionlessSystemDoesNotDrift) {
  // Leapfrog conserves a shadow energy: the measured Ek + Es oscillates by O((omega dt)^2) around
  // a constant and does not drift. Checked at the automatic step and at a quarter of it, where the
  // oscillation must be about 16 times smaller (second order), over 1e5 steps each.
  World w = lattice(3, 0.0, 0.0, false, 2e-4);
  double worst, drift;
  measure(w, 100000, worst, drift);
  report("undamped Ek+Es, largest deviation over 1e5 steps at 0.8 x estimate", worst, 0);
  report("undamped Ek+Es, drift of the mean (first vs last tenth)", drift, 0);
  EXPECT_LT(worst, 0.05) << "bounded at dt = 0.8 x estimate";
  EXPECT_LT(drift, 2e-3) << "no drift";
  World fine = lattice(3, 0.0, 0.0, false, 2e-4);
  fine.set_dt(w.dt() / 4);
  double worst4, drift4;
  measure(fine, 100000, worst4, drift4);
  report("undamped Ek+Es, largest deviation at 0.2 x estimate", worst4, 0);
  report("undamped Ek+Es, drift at 0.2 x estimate", drift4, 0);
  EXPECT_LT(worst4, worst / 10) << "second order: a quarter of the step, 1/16 of the error";
  EXPECT_LT(drift4, 2e-4);
  EXPECT_EQ(w.energies().friction, 0.0);
}

TEST(Energy, QuasiStaticCompressionClosesTheBalance) {
  World w = lattice(4, 0.7, 0.5, true, 0.0);
  w.cycle(10);
  const Energies e0 = w.energies();
  w.set_wall_velocity(5, {0, 0, -2e-5});  // the top plane moves down
  w.cycle(20000);
  const Energies e = w.energies();
  const double input = e.boundary_work - e0.boundary_work;
  ASSERT_GT(input, 0);
  EXPECT_LT(std::fabs(e.balance_error(e0)), 0.01 * input)
      << "input " << input << " kinetic " << e.kinetic - e0.kinetic << " strain "
      << e.strain - e0.strain << " friction " << e.friction - e0.friction << " damping "
      << e.damping - e0.damping;
  EXPECT_GT(w.wall_force(5).z, 0.0) << "the particles push the top wall up";
}
