// The SIMD kernels equal their scalar references bit for bit on every architecture this CPU
// runs, in every state a contact, bond, wall contact or particle can be in.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <numeric>
#include <random>
#include <tuple>
#include <type_traits>
#include <string>

#include "core/aligned.hpp"
#include "kernels/contact_law.hpp"
#include "kernels/kernels.hpp"
#include "kernels/pair_loop.hpp"
#include "scenes.hpp"
#include "neighbor/build.hpp"
#include "state.hpp"


using namespace asperity;

namespace {
// Random pairs in every state: touching, apart, sliding, sticking, spinning, fresh (zero history),
// in either layout of test::kernel_test_pair.
struct RandomPairs {
  std::vector<double, AlignedAllocator<double>> x, y, z, vx, vy, vz, wx, wy, wz, r;
  std::vector<std::int64_t, AlignedAllocator<std::int64_t>> a, b;
  std::vector<double, AlignedAllocator<double>> nx, ny, nz, fsx, fsy, fsz, fn, U, rest;
  std::vector<double, AlignedAllocator<double>> out;  // records fx fy fz U cx cy cz fn per pair
  RandomPairs(std::size_t pairs, unsigned seed, bool shared = false) {
    const std::size_t n = shared ? test::a_particles(pairs) + pairs : 2 * pairs;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto* c : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &r}) c->resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      r[i] = 5e-4 * (1 + 0.3 * u(rng));
      vx[i] = 1e-3 * u(rng); vy[i] = 1e-3 * u(rng); vz[i] = 1e-3 * u(rng);
      wx[i] = u(rng); wy[i] = u(rng); wz[i] = u(rng);
      x[i] = u(rng); y[i] = u(rng); z[i] = u(rng);
    }
    a.resize(pairs); b.resize(pairs);
    for (auto* c : {&nx, &ny, &nz, &fsx, &fsy, &fsz, &fn, &U, &rest}) c->resize(pairs);
    out.assign(8 * pairs, -7.0);  // the kernels must write every slot
    for (std::size_t k = 0; k < pairs; ++k) {
      std::tie(a[k], b[k]) = test::kernel_test_pair(k, pairs, shared);
      const auto ia = std::size_t(a[k]), ib = std::size_t(b[k]);
      Vec3 dir{u(rng), u(rng), u(rng)};
      dir = dir / norm(dir);
      const double d = (r[ia] + r[ib]) * (1 + 0.05 * u(rng));
      x[ib] = x[ia] + d * dir.x; y[ib] = y[ia] + d * dir.y; z[ib] = z[ia] + d * dir.z;
      Vec3 old = dir + Vec3{0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng)};
      old = old / norm(old);
      nx[k] = old.x; ny[k] = old.y; nz[k] = old.z;
      const double s = (k % 5 == 0) ? 0.0 : 1e-5;
      fsx[k] = s * u(rng); fsy[k] = s * u(rng); fsz[k] = s * u(rng);
      // Rest overlaps (stress-free bonds' contacts) on every third pair, around the overlaps.
      rest[k] = (k % 3 == 0) ? 0.05 * r[ia] * (1 + u(rng)) : 0.0;
    }
  }
  kernels::PairKernelArgs args() {
    return {x.data(), y.data(), z.data(), vx.data(), vy.data(), vz.data(), wx.data(), wy.data(),
            wz.data(), r.data(), a.data(), b.data(), nx.data(), ny.data(), nz.data(), fsx.data(),
            fsy.data(), fsz.data(), out.data(), 0.1, 0.01, 0.5, 1e-3, x.size(),
            with_rest ? rest.data() : nullptr};
  }
  // The kernels leave fn and U in the records only (store/pairs.hpp): copied out here.
  void outputs() {
    for (std::size_t k = 0; k < fn.size(); ++k) fn[k] = out[8 * k + 7], U[k] = out[8 * k + 3];
  }
  bool with_rest = false;
};
}  // namespace

TEST(KernelEquivalence, SimdKernelsEqualTheScalarReferenceBitwise) {
  const std::size_t pairs = 4096;
  const auto archs = available_simd_architectures();
  ASSERT_EQ(archs.back(), "scalar");
  for (const auto& arch : archs) {
    const auto& simd = kernels::select_kernels(arch);
    for (bool shared : {false, true})
    for (bool rest : {false, true})
    for (bool rotation : {true, false})
    for (bool stream : {false, true}) {  // records with non-temporal stores (large pair lists)
      RandomPairs ref(pairs, 11, shared), got(pairs, 11, shared);
      ref.with_rest = got.with_rest = rest;
      const auto& sk = kernels::scalar_kernels();
      const double slip_ref = (rotation ? sk.pair : sk.pair_norot)(ref.args(), 0, pairs);
      auto got_args = got.args();
      got_args.stream = stream;
      const double slip_got = (rotation ? simd.pair : simd.pair_norot)(got_args, 0, pairs);
      ref.outputs();
      got.outputs();
      auto same = [&](const auto& u, const auto& v) {
        return std::memcmp(u.data(), v.data(), pairs * sizeof(double)) == 0;
      };
      const std::string what = arch + (shared ? " shared a" : " separate") + (rest ? " rest" : "") +
                               (stream ? " streamed" : "");
      EXPECT_TRUE(same(ref.rest, got.rest)) << what;
      EXPECT_TRUE(same(ref.fn, got.fn)) << what;
      EXPECT_TRUE(same(ref.U, got.U)) << what;
      EXPECT_TRUE(same(ref.nx, got.nx) && same(ref.ny, got.ny) && same(ref.nz, got.nz)) << what;
      EXPECT_TRUE(same(ref.fsx, got.fsx) && same(ref.fsy, got.fsy) && same(ref.fsz, got.fsz)) << what;
      EXPECT_EQ(0, std::memcmp(ref.out.data(), got.out.data(), 8 * pairs * sizeof(double))) << what;
      // The record of each pair: fn n + fs, U, n x fs, fn; fn = kn (U - rest) where U > rest
      // [3-12] (rest: 0 unless given; the kernel resets it where the pair no longer touches).
      for (std::size_t k = 0; k < pairs; k += 97) {
        const double* r = &ref.out[8 * k];
        EXPECT_EQ(r[0], ref.fn[k] * ref.nx[k] + ref.fsx[k]) << what << " pair " << k;
        EXPECT_EQ(r[2], ref.fn[k] * ref.nz[k] + ref.fsz[k]) << what << " pair " << k;
        EXPECT_EQ(r[3], ref.U[k]) << what << " pair " << k;
        EXPECT_EQ(r[5], ref.nz[k] * ref.fsx[k] - ref.nx[k] * ref.fsz[k]) << what << " pair " << k;
        const double u0 = rest ? ref.rest[k] : 0.0;
        EXPECT_EQ(r[7], ref.U[k] > u0 ? 0.1 * (ref.U[k] - u0) : 0.0) << what << " pair " << k;
      }
      // The slip energy is summed per lane first: equal to rounding.
      EXPECT_NEAR(slip_got, slip_ref, 1e-12 * slip_ref) << what;
      ASSERT_GT(slip_ref, 0.0) << "the random pairs must include slipping contacts";
      std::size_t touching = 0;
      for (double u : ref.U) touching += u > 0;
      EXPECT_GT(touching, pairs / 4);
      EXPECT_LT(touching, 3 * pairs / 4);
    }
  }
}

// The pair kernels skip the law for a stage of pairs in which none touches (pair_loop.hpp): on
// pairs of which whole stages miss (as in a bonded specimen, whose touching pairs became bonds)
// and the others touch or miss at random, every kernel must give, pair by pair, the bits of the
// law itself (contact_law.hpp applied to the one pair, the record formed as the kernel forms it),
// whether it computes a stage in one pass or (a stage that did not touch in the last step:
// PairKernelArgs::touched) the geometry first and the kinematics after; and it must say which
// records are live (not all zeros but for the overlap: touching, or pushed by a negative rest
// overlap, PairKernelArgs::live) and how many per stage, which the gather relies on to skip the
// others exactly (GatherArgs::live).
TEST(KernelEquivalence, PairKernelSkipsStagesOfNearMissesWithTheLawsBits) {
  const std::size_t pairs = 4096;
  std::vector<const kernels::KernelSet*> sets{&kernels::scalar_kernels()};
  for (const auto& arch : available_simd_architectures()) sets.push_back(&kernels::select_kernels(arch));
  for (bool rotation : {true, false})
    for (bool rest : {false, true}) {
      RandomPairs base(pairs, 23);
      base.with_rest = rest;
      std::size_t misses = 0;
      for (std::size_t k = 0; k < pairs; ++k) {
        const auto ia = std::size_t(base.a[k]), ib = std::size_t(base.b[k]);
        if ((k / kernels::kPairStage) % 2 == 0) {  // b moved out to 1.02 .. 1.1 (Ra + Rb)
          const double dx = base.x[ib] - base.x[ia], dy = base.y[ib] - base.y[ia], dz = base.z[ib] - base.z[ia];
          const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
          const double f = (base.r[ia] + base.r[ib]) * (1.06 + 0.04 * std::sin(double(k))) / d;
          base.x[ib] = base.x[ia] + f * dx; base.y[ib] = base.y[ia] + f * dy; base.z[ib] = base.z[ia] + f * dz;
          // A negative rest overlap deeper than the gap: a normal force without touching (the
          // engine clamps a freed contact's rest overlap at 0, the kernel does not rely on it).
          if (k % 40 == 1) base.rest[k] = -0.12 * (base.r[ia] + base.r[ib]);
        }
      }
      // The law, pair by pair.
      RandomPairs law = base;
      const kernels::LawParams<double> lp{0.1, 0.01, 0.5, 1e-3};
      double slip_law = 0;
      for (std::size_t k = 0; k < pairs; ++k) {
        const auto ia = std::size_t(law.a[k]), ib = std::size_t(law.b[k]);
        double nx, ny, nz, U, la, lb, fn;
        kernels::ball_ball_geometry(law.x[ia], law.y[ia], law.z[ia], law.x[ib], law.y[ib], law.z[ib],
                                    law.r[ia], law.r[ib], nx, ny, nz, U, la, lb);
        misses += U <= 0;
        const double u0 = rest ? law.rest[k] : 0.0;
        double fx = law.fsx[k], fy = law.fsy[k], fz = law.fsz[k];
        auto law_of = [&](auto spin) {  // the law with or without its spin terms (w unread)
          return kernels::contact_forces<double, decltype(spin)::value>(
              nx, ny, nz, U, la, lb, law.vx[ia], law.vy[ia], law.vz[ia], law.wx[ia], law.wy[ia],
              law.wz[ia], law.vx[ib], law.vy[ib], law.vz[ib], law.wx[ib], law.wy[ib], law.wz[ib],
              law.nx[k], law.ny[k], law.nz[k], u0, fx, fy, fz, fn, lp);
        };
        slip_law += rotation ? law_of(std::true_type{}) : law_of(std::false_type{});
        if (rest) law.rest[k] = U > 0 ? u0 : 0.0;
        law.nx[k] = nx; law.ny[k] = ny; law.nz[k] = nz;
        law.fsx[k] = fx; law.fsy[k] = fy; law.fsz[k] = fz;
        const double rec[8] = {fn * nx + fx, fn * ny + fy, fn * nz + fz, U,
                               ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx, fn};
        std::copy(rec, rec + 8, law.out.begin() + std::ptrdiff_t(8 * k));
      }
      std::vector<std::uint8_t> live(pairs), live_count(pairs / kernels::kPairStage, 0),
          touching(pairs / kernels::kPairStage, 0);
      std::size_t pushed = 0;
      for (std::size_t k = 0; k < pairs; ++k) {
        live[k] = law.out[8 * k + 3] > 0 || law.out[8 * k + 7] != 0;
        live_count[k / kernels::kPairStage] += live[k];
        touching[k / kernels::kPairStage] |= law.out[8 * k + 3] > 0;
        pushed += live[k] && !(law.out[8 * k + 3] > 0);
      }
      if (rest) {
        ASSERT_GT(pushed, 10u) << "live records of pairs that do not touch";
      }
      ASSERT_GT(misses, pairs / 2) << "most pairs miss";
      ASSERT_LT(misses, pairs - pairs / 8) << "some touch";
      for (const kernels::KernelSet* ks : sets)
      for (int last_step : {-1, 0, 1})  // touched not kept; no stage touched; every stage did
      for (bool with_flags : {false, true}) {
        RandomPairs got = base;
        std::vector<std::uint8_t> touched(pairs / kernels::kPairStage, std::uint8_t(last_step == 1));
        std::vector<std::uint8_t> flags(pairs, 7);
        auto args = got.args();
        if (last_step >= 0) args.touched = touched.data();
        if (with_flags) args.live = flags.data();
        const double slip = (rotation ? ks->pair : ks->pair_norot)(args, 0, pairs);
        const std::string what = std::string(ks->name) + (rotation ? " spin" : " no spin") +
                                 (rest ? " rest" : "") + " last step " + std::to_string(last_step) +
                                 (with_flags ? " live flags" : "");
        if (last_step >= 0) {
          EXPECT_EQ(touched, with_flags ? live_count : touching) << what;
        }
        if (with_flags) {
          EXPECT_EQ(flags, live) << what;
          // The same step again, the flags now the last step's: a batch dead both times keeps
          // its records (here a sentinel), every other record and all the history as the law's.
          RandomPairs again = base;
          std::fill(again.out.begin(), again.out.end(), -123.0);
          std::vector<std::uint8_t> touched2(pairs / kernels::kPairStage, 1);
          auto args2 = again.args();
          args2.touched = touched2.data();
          args2.live = flags.data();
          args2.keep_dead_records = true;
          (rotation ? ks->pair : ks->pair_norot)(args2, 0, pairs);
          std::size_t kept = 0, written = 0;
          for (std::size_t first = 0; first < pairs; first += ks->lanes) {
            bool dead = true;
            for (std::size_t k = first; k < first + ks->lanes; ++k) dead = dead && !live[k];
            (dead ? kept : written) += 1;
            for (std::size_t k = first; k < first + ks->lanes; ++k)
              for (std::size_t j = 0; j < 8; ++j)
                ASSERT_EQ(again.out[8 * k + j], dead ? -123.0 : law.out[8 * k + j]) << what << " pair " << k;
          }
          EXPECT_GT(kept, 10u) << what;
          EXPECT_GT(written, 10u) << what;
          for (auto c : {&RandomPairs::nx, &RandomPairs::ny, &RandomPairs::nz, &RandomPairs::fsx,
                         &RandomPairs::fsy, &RandomPairs::fsz, &RandomPairs::rest})
            EXPECT_EQ(0, std::memcmp((again.*c).data(), (law.*c).data(), pairs * sizeof(double))) << what;
        }
        EXPECT_NEAR(slip, slip_law, 1e-12 * slip_law) << what;
        EXPECT_GT(slip_law, 0.0);
        EXPECT_EQ(0, std::memcmp(got.out.data(), law.out.data(), 8 * pairs * sizeof(double))) << what;
        for (auto c : {&RandomPairs::nx, &RandomPairs::ny, &RandomPairs::nz, &RandomPairs::fsx,
                       &RandomPairs::fsy, &RandomPairs::fsz, &RandomPairs::rest})
          EXPECT_EQ(0, std::memcmp((got.*c).data(), (law.*c).data(), pairs * sizeof(double))) << what;
      }
    }
}

// Where no particle spins (every w is +0), the stages take the kernels that leave the spin terms
// out (pair_norot; bonds.cpp's bond_norot likewise). They must give the values of the full law
// at w = +0: bit for bit on the random pairs, and value for value (-0 == +0) where relative
// velocities vanish exactly, the one case in which the sign of a zero may differ.
TEST(KernelEquivalence, PairKernelWithoutSpinIsTheFullLawAtZeroSpin) {
  const std::size_t pairs = 4096;
  for (bool still : {false, true}) {
    for (const auto& arch : available_simd_architectures()) {
      const auto& ks = kernels::select_kernels(arch);
      RandomPairs full(pairs, 13), cut(pairs, 13);
      for (RandomPairs* q : {&full, &cut}) {
        for (auto* c : {&q->wx, &q->wy, &q->wz}) std::fill(c->begin(), c->end(), 0.0);
        if (still)  // at rest, some velocities -0
          for (auto* c : {&q->vx, &q->vy, &q->vz})
            for (std::size_t i = 0; i < c->size(); ++i) (*c)[i] = (i % 3 == 0) ? -0.0 : 0.0;
      }
      const double slip_full = ks.pair(full.args(), 0, pairs);
      const double slip_cut = ks.pair_norot(cut.args(), 0, pairs);
      full.outputs();
      cut.outputs();
      const std::string what = arch + (still ? " at rest" : " moving");
      EXPECT_EQ(slip_full, slip_cut) << what;
      if (!still) {
        EXPECT_EQ(0, std::memcmp(full.out.data(), cut.out.data(), 8 * pairs * sizeof(double))) << what;
        for (auto c : {&RandomPairs::nx, &RandomPairs::ny, &RandomPairs::nz, &RandomPairs::fsx,
                       &RandomPairs::fsy, &RandomPairs::fsz})
          EXPECT_EQ(0, std::memcmp((full.*c).data(), (cut.*c).data(), pairs * sizeof(double))) << what;
      } else {
        for (std::size_t j = 0; j < 8 * pairs; ++j)
          ASSERT_EQ(full.out[j], cut.out[j]) << what << " slot " << j;
        for (std::size_t k = 0; k < pairs; ++k) {
          ASSERT_EQ(full.fsx[k], cut.fsx[k]) << what << " pair " << k;
          ASSERT_EQ(full.fsy[k], cut.fsy[k]) << what << " pair " << k;
          ASSERT_EQ(full.fsz[k], cut.fsz[k]) << what << " pair " << k;
        }
      }
    }
  }
}

namespace {
// Random particles for the integrate kernel: free, in a group (not moved), rotation locked, one
// non-finite velocity; damping on, gravity and applied forces; n not a multiple of the lanes.
struct RandomParticles {
  static constexpr std::size_t n = 1021, padded = 1024;
  using Col = std::vector<double, AlignedAllocator<double>>;
  Col x, y, z, vx, vy, vz, wx, wy, wz, fx, fy, fz, tx, ty, tz, x0, y0, z0, m, im, I, iI, r, ax, ay, az,
      free, spin;
  explicit RandomParticles(unsigned seed, bool with_nan) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto* c : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz, &x0, &y0,
                    &z0, &m, &im, &I, &iI, &r, &ax, &ay, &az, &free, &spin})
      c->assign(padded, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      r[i] = 5e-4 * (1 + 0.3 * u(rng));
      m[i] = 2500 * 4.18879 * r[i] * r[i] * r[i];
      im[i] = 1 / m[i];
      I[i] = 0.4 * m[i] * r[i] * r[i];
      iI[i] = 1 / I[i];
      x[i] = u(rng); y[i] = u(rng); z[i] = u(rng);
      x0[i] = x[i] + 1e-5 * u(rng); y0[i] = y[i]; z0[i] = z[i];
      vx[i] = 1e-3 * u(rng); vy[i] = (i % 7 == 0) ? 0.0 : 1e-3 * u(rng); vz[i] = 1e-3 * u(rng);
      wx[i] = u(rng); wy[i] = u(rng); wz[i] = u(rng);
      fx[i] = 1e-5 * u(rng); fy[i] = 1e-5 * u(rng); fz[i] = 1e-5 * u(rng);
      tx[i] = 1e-9 * u(rng); ty[i] = 1e-9 * u(rng); tz[i] = 1e-9 * u(rng);
      ax[i] = 1e-6 * u(rng); ay[i] = 0; az[i] = 1e-6 * u(rng);
      free[i] = (i % 11 == 3) ? 0.0 : 1.0;
      spin[i] = (free[i] != 0 && i % 5 != 1) ? 1.0 : 0.0;
    }
    if (with_nan) vz[517] = std::numeric_limits<double>::quiet_NaN();
  }
  kernels::IntegrateArgs args() {
    return {x.data(), y.data(), z.data(), vx.data(), vy.data(), vz.data(), wx.data(), wy.data(),
            wz.data(), fx.data(), fy.data(), fz.data(), tx.data(), ty.data(), tz.data(), x0.data(),
            y0.data(), z0.data(), m.data(), im.data(), I.data(), iI.data(), r.data(), ax.data(),
            ay.data(), az.data(), free.data(), spin.data(), 1e-4, 0.7, 0.0, 0.0, -9.81};
  }
};
}  // namespace

TEST(KernelEquivalence, SimdIntegrateEqualsTheScalarReferenceBitwise) {
  const auto& sk = kernels::scalar_kernels();
  for (const auto& arch : available_simd_architectures()) {
    const auto& simd = kernels::select_kernels(arch);
    for (bool rotation : {true, false})
      for (bool with_nan : {false, true}) {
        RandomParticles ref(5, with_nan), got(5, with_nan);
        kernels::IntegrateSums sr, sg;
        (rotation ? sk.integrate : sk.integrate_norot)(ref.args(), 0, RandomParticles::padded, sr);
        (rotation ? simd.integrate : simd.integrate_norot)(got.args(), 0, RandomParticles::padded, sg);
        auto same = [](const auto& u, const auto& v) {
          return std::memcmp(u.data(), v.data(), u.size() * sizeof(double)) == 0;
        };
        for (auto c : {&RandomParticles::x, &RandomParticles::y, &RandomParticles::z,
                       &RandomParticles::vx, &RandomParticles::vy, &RandomParticles::vz,
                       &RandomParticles::wx, &RandomParticles::wy, &RandomParticles::wz})
          EXPECT_TRUE(same(ref.*c, got.*c)) << arch;
        // Particles that are not free keep their state; locked ones keep their spin.
        RandomParticles before(5, with_nan);
        EXPECT_EQ(got.x[3], before.x[3]);
        EXPECT_EQ(got.vx[14], before.vx[14]);
        EXPECT_EQ(got.wx[1], before.wx[1]);
        EXPECT_EQ(got.x[RandomParticles::n], 0.0) << "padding untouched";
        if (rotation) EXPECT_NE(got.wx[0], before.wx[0]);
        else EXPECT_EQ(got.wx[0], before.wx[0]);
        // Sums are per lane, then over lanes: equal to rounding. The extremes are exact.
        for (auto [a, b] : {std::pair{sr.damping, sg.damping}, {sr.gravity, sg.gravity},
                            {sr.applied, sg.applied}, {sr.kinetic, sg.kinetic}}) {
          if (with_nan) continue;
          EXPECT_NEAR(b, a, 1e-12 * std::abs(a)) << arch;
          EXPECT_NE(a, 0.0);
        }
        if (with_nan) {
          EXPECT_EQ(sr.worst, 517);
          EXPECT_TRUE(std::isnan(sr.worst_step));
          EXPECT_TRUE(std::isnan(sr.max_disp2));
        } else {
          EXPECT_GT(sr.damping, 0.0) << "local damping dissipates";
          EXPECT_EQ(sg.max_disp2, sr.max_disp2) << arch;
          EXPECT_EQ(sg.worst_step, sr.worst_step) << arch;
        }
        EXPECT_EQ(sg.worst, sr.worst) << arch;
        EXPECT_TRUE(std::isnan(sg.max_disp2) == with_nan) << arch;
      }
  }
}

// The integrate stage runs a block in which no particle may turn (spin mask all 0: a bonded
// specimen) through the kernel without rotation: it must give the bits of the kernel with it,
// state and sums, on every architecture.
TEST(KernelEquivalence, IntegrateWithoutSpinIsTheFullKernelWhereNothingTurns) {
  std::vector<const kernels::KernelSet*> sets{&kernels::scalar_kernels()};
  for (const auto& arch : available_simd_architectures()) sets.push_back(&kernels::select_kernels(arch));
  for (const kernels::KernelSet* ks : sets) {
    for (bool with_nan : {false, true}) {
      RandomParticles full(9, with_nan), norot(9, with_nan);
      for (auto* p : {&full, &norot}) std::fill(p->spin.begin(), p->spin.end(), 0.0);
      kernels::IntegrateSums sf, sn;
      ks->integrate(full.args(), 0, RandomParticles::padded, sf);
      ks->integrate_norot(norot.args(), 0, RandomParticles::padded, sn);
      for (auto c : {&RandomParticles::x, &RandomParticles::y, &RandomParticles::z,
                     &RandomParticles::vx, &RandomParticles::vy, &RandomParticles::vz,
                     &RandomParticles::wx, &RandomParticles::wy, &RandomParticles::wz})
        EXPECT_EQ(0, std::memcmp((full.*c).data(), (norot.*c).data(), RandomParticles::padded * sizeof(double)))
            << ks->name;
      auto bits = [](double v) {
        std::uint64_t u;
        std::memcpy(&u, &v, sizeof u);
        return u;
      };
      for (auto [a, b] : {std::pair{sf.damping, sn.damping}, {sf.gravity, sn.gravity},
                          {sf.applied, sn.applied}, {sf.kinetic, sn.kinetic},
                          {sf.max_disp2, sn.max_disp2}, {sf.worst_step, sn.worst_step}})
        EXPECT_EQ(bits(a), bits(b)) << ks->name << (with_nan ? " with a NaN" : "");
      EXPECT_EQ(sf.worst, sn.worst) << ks->name;
      if (!with_nan) {
        EXPECT_GT(sf.damping, 0.0) << "the block does move and dissipate";
      }
    }
  }
}

namespace {
// Random ball-plane contacts in every state: touching or not, fresh (zero stored normal) or
// carrying a shear force that sticks or slides, spinning, on moving planes of different
// materials; a count that is not a multiple of the lanes. tables: the per-wall columns padded
// with zeros to 8 entries and their count given (PlaneWallArgs::walls), so that kernels with at
// least as many lanes as walls permute them instead of gathering.
struct RandomPlaneContacts {
  static constexpr std::size_t n = 1003, particles = 700;
  std::size_t walls;
  bool tables;
  std::vector<double> x, y, z, vx, vy, vz, wx, wy, wz, r;
  std::vector<std::int32_t> particle, wall;
  std::vector<double> nx, ny, nz, fsx, fsy, fsz, fn, U, slip;
  std::vector<double> px, py, pz, pnx, pny, pnz, pvx, pvy, pvz, kn, ks, mu;
  explicit RandomPlaneContacts(unsigned seed, std::size_t wall_count = 5, bool padded = false)
      : walls(wall_count), tables(padded) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t w = 0; w < walls; ++w) {
      Vec3 m{u(rng), u(rng), u(rng)};
      m = m / norm(m);
      pnx.push_back(m.x); pny.push_back(m.y); pnz.push_back(m.z);
      px.push_back(u(rng)); py.push_back(u(rng)); pz.push_back(u(rng));
      const double speed = w % 2 ? 1e-3 : 0.0;
      pvx.push_back(speed * u(rng)); pvy.push_back(speed * u(rng)); pvz.push_back(speed * u(rng));
      kn.push_back(0.1 * (1 + w)); ks.push_back(0.03 * (1 + w)); mu.push_back(0.2 + 0.1 * w);
    }
    for (std::size_t i = 0; i < particles; ++i) {
      r.push_back(5e-4 * (1 + 0.3 * u(rng)));
      vx.push_back(1e-3 * u(rng)); vy.push_back(1e-3 * u(rng)); vz.push_back(1e-3 * u(rng));
      wx.push_back(u(rng)); wy.push_back(u(rng)); wz.push_back(u(rng));
      x.push_back(0); y.push_back(0); z.push_back(0);
    }
    for (std::size_t k = 0; k < n; ++k) {
      const auto i = std::int32_t(k % particles), w = std::int32_t(k % walls);
      particle.push_back(i);
      wall.push_back(w);
      // The centre at a distance of 0.95 .. 1.05 R from the plane (the last contact of a
      // particle sets its position; its earlier contact sees it wherever it ends up).
      const double d = r[i] * (1 + 0.05 * u(rng));
      const Vec3 t = cross(Vec3{pnx[w], pny[w], pnz[w]}, Vec3{u(rng), u(rng), u(rng)});  // in the plane
      x[i] = px[w] + d * pnx[w] + t.x;
      y[i] = py[w] + d * pny[w] + t.y;
      z[i] = pz[w] + d * pnz[w] + t.z;
      const bool fresh = k % 4 == 0;
      Vec3 o{pnx[w] + 0.01 * u(rng), pny[w] + 0.01 * u(rng), pnz[w] + 0.01 * u(rng)};
      o = o / norm(o);
      nx.push_back(fresh ? 0.0 : o.x); ny.push_back(fresh ? 0.0 : o.y); nz.push_back(fresh ? 0.0 : o.z);
      const double s = fresh ? 0.0 : (k % 3 ? 1e-6 : 1e-4);  // sticking or sliding
      fsx.push_back(s * u(rng)); fsy.push_back(s * u(rng)); fsz.push_back(s * u(rng));
    }
    fn.assign(n, -1); U.assign(n, -1); slip.assign(n, -1);
    if (tables)
      for (auto* c : {&px, &py, &pz, &pnx, &pny, &pnz, &pvx, &pvy, &pvz, &kn, &ks, &mu})
        c->resize(std::max<std::size_t>(walls, 8), 0.0);
  }
  kernels::PlaneWallArgs args() {
    return {x.data(), y.data(), z.data(), vx.data(), vy.data(), vz.data(), wx.data(), wy.data(),
            wz.data(), r.data(), particle.data(), wall.data(), nx.data(), ny.data(), nz.data(),
            fsx.data(), fsy.data(), fsz.data(), fn.data(), U.data(), slip.data(), px.data(),
            py.data(), pz.data(), pnx.data(), pny.data(), pnz.data(), pvx.data(), pvy.data(),
            pvz.data(), kn.data(), ks.data(), mu.data(), 1e-3, tables ? walls : 0};
  }
};
}  // namespace

TEST(KernelEquivalence, SimdPlaneWallKernelEqualsTheScalarReferenceBitwise) {
  using C = RandomPlaneContacts;
  for (const auto& arch : available_simd_architectures()) {
    const auto& simd = kernels::select_kernels(arch);
    // Gathered tables, and permuted ones where the lanes hold every wall (3 <= 4 lanes of AVX2,
    // 5 <= 8 of AVX-512; 12 walls are gathered on every architecture).
    for (auto [walls, tables] : {std::pair<std::size_t, bool>{5, false}, {5, true}, {3, true}, {12, true}})
    for (bool rotation : {true, false}) {
      C ref(5, walls, tables), got(5, walls, tables);
      const auto& sk = kernels::scalar_kernels();
      (rotation ? sk.plane_walls : sk.plane_walls_norot)(ref.args(), 0, C::n);
      // Whole batches from an odd start, as the wall stage calls it on runs of plane contacts;
      // the scalar reference does the ends.
      const std::size_t begin = 3, whole = begin + (C::n - begin) / simd.lanes * simd.lanes;
      (rotation ? sk.plane_walls : sk.plane_walls_norot)(got.args(), 0, begin);
      (rotation ? simd.plane_walls : simd.plane_walls_norot)(got.args(), begin, whole);
      (rotation ? sk.plane_walls : sk.plane_walls_norot)(got.args(), whole, C::n);
      const std::string what = arch + (rotation ? " rotation" : " no rotation") + ", " +
                               std::to_string(walls) + (tables ? " walls in tables" : " walls");
      auto same = [](const std::vector<double>& u, const std::vector<double>& v) {
        return std::memcmp(u.data(), v.data(), u.size() * sizeof(double)) == 0;
      };
      for (auto [name, r, g] : {std::tuple{"nx", &ref.nx, &got.nx}, {"ny", &ref.ny, &got.ny},
                                {"nz", &ref.nz, &got.nz}, {"fsx", &ref.fsx, &got.fsx},
                                {"fsy", &ref.fsy, &got.fsy}, {"fsz", &ref.fsz, &got.fsz},
                                {"fn", &ref.fn, &got.fn}, {"overlap", &ref.U, &got.U},
                                {"slip", &ref.slip, &got.slip}})
        EXPECT_TRUE(same(*r, *g)) << what << ": " << name;
      // The scene covers the states: contacts and gaps, slipping and sticking.
      std::size_t touching = 0, slipping = 0, sticking = 0;
      for (std::size_t k = 0; k < C::n; ++k) {
        touching += ref.U[k] > 0;
        slipping += ref.slip[k] > 0;
        sticking += ref.U[k] > 0 && ref.slip[k] == 0 && ref.fsx[k] != 0;
        // The plane's normal, and the overlap from the centre's distance to the plane.
        ASSERT_EQ(ref.nx[k], ref.pnx[ref.wall[k]]);
        if (!(ref.U[k] > 0)) {
          EXPECT_TRUE(ref.fn[k] == 0 && ref.fsx[k] == 0 && ref.slip[k] == 0) << k;
        }
      }
      EXPECT_GT(touching, C::n / 4);
      EXPECT_LT(touching, 3 * C::n / 4);
      EXPECT_GT(slipping, 10u);
      EXPECT_GT(sticking, 10u);
    }
    // Without rotation the kernel leaves out the spin terms (contact_law.hpp): at w = +0 it gives
    // the full law's values bit for bit.
    C full(5), cut(5);
    for (C* c : {&full, &cut})
      for (auto* w : {&c->wx, &c->wy, &c->wz}) std::fill(w->begin(), w->end(), 0.0);
    simd.plane_walls(full.args(), 0, C::n / simd.lanes * simd.lanes);
    simd.plane_walls_norot(cut.args(), 0, C::n / simd.lanes * simd.lanes);
    for (auto [name, f, c] : {std::tuple{"nx", &full.nx, &cut.nx}, {"fsx", &full.fsx, &cut.fsx},
                              {"fsy", &full.fsy, &cut.fsy}, {"fsz", &full.fsz, &cut.fsz},
                              {"fn", &full.fn, &cut.fn}, {"slip", &full.slip, &cut.slip}})
      EXPECT_EQ(0, std::memcmp(f->data(), c->data(), f->size() * sizeof(double))) << arch << " " << name;
  }
}

// The gather kernel: random pairs and bonds with random records, some particles inert or idle
// (never written), some with no pairs; the pairs' sums and then the bonds' terms in one pass, as
// the stage runs it, and the pairs alone (a scene without bonds). Every architecture equals the
// scalar reference bit for bit, and that equals the direct sums of model.md 4 and 5 in incidence
// order.
TEST(KernelEquivalence, SimdGatherEqualsTheScalarReferenceBitwise) {
  const std::size_t n = 777, count = 2500;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  // A sorted list of `count` random (a, b), a < b, its incidence and random records.
  struct List {
    std::vector<std::int64_t> a, b;
    detail::Incidence inc;
    std::vector<double, AlignedAllocator<double>> records;
  };
  auto make = [&](std::size_t width) {
    List l;
    std::vector<std::pair<std::int64_t, std::int64_t>> ab(count);
    for (auto& [i, j] : ab) {
      i = std::int64_t(rng() % (n - 1));
      j = std::int64_t(rng() % n);
      if (j == i) j = i + 1;
      if (j < i) std::swap(i, j);
    }
    std::sort(ab.begin(), ab.end());
    for (auto [i, j] : ab) l.a.push_back(i), l.b.push_back(j);
    detail::build_incidence(n, l.a.data(), l.b.data(), count, l.inc);
    l.records.resize(width * count);
    for (std::size_t k = 0; k < count; ++k) {
      for (std::size_t j = 0; j < width; ++j) l.records[width * k + j] = u(rng);
      l.records[width * k + 3] = 1e-5 * u(rng);  // the overlap
      l.records[width * k + 7] = 0;
      if (width == 12) l.records[width * k + 11] = 0;
    }
    return l;
  };
  const List pairs = make(8), bonds = make(12);
  std::vector<double> radius(n);
  std::vector<std::uint8_t> inert(n, 0), idle(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    radius[i] = 5e-4 * (1 + 0.3 * u(rng));
    inert[i] = i % 11 == 0;
    idle[i] = i % 13 == 0;
  }
  using Columns = std::array<std::vector<double>, 6>;  // fx fy fz tx ty tz
  auto run = [&](const kernels::KernelSet& ks, bool with_bonds, const List& bonds,
                 kernels::BondRecord layout = kernels::BondRecord::moments) {
    Columns o;
    for (auto& c : o) c.assign(n, -7.0);
    kernels::GatherArgs g{pairs.inc.start.data(), pairs.inc.entry.data(), pairs.records.data(),
                          radius.data(), inert.data(), idle.data(), o[0].data(), o[1].data(),
                          o[2].data(), o[3].data(), o[4].data(), o[5].data()};
    kernels::GatherArgs gb = g;
    gb.start = bonds.inc.start.data();
    gb.entry = bonds.inc.entry.data();
    gb.records = bonds.records.data();
    gb.bond_record = layout;
    for (auto [first, end] : {std::pair<std::size_t, std::size_t>{0, 400}, {400, n}}) {  // two blocks
      ks.gather(g, with_bonds ? &gb : nullptr, first, end);
    }
    return o;
  };
  const Columns ref = run(kernels::scalar_kernels(), true, bonds);
  const Columns ref_pairs = run(kernels::scalar_kernels(), false, bonds);
  // Bonds whose beams carry no moment (State::bond_moments_zero): the kernel without moments
  // writes records of 8, without the moment, and the gather leaves its terms out; the sums are
  // those of the records of 12 with a zero moment (the sign of an exact zero sum aside).
  // Where besides no end of a bond turns, the kernel writes records of 4 (BondRecord::forces):
  // the forces are those of the records of 12, the torques the pairs' alone.
  List unbent = bonds, unbent8 = bonds, unbent4 = bonds;
  unbent8.records.assign(8 * count, 0.0);
  unbent4.records.assign(4 * count, 0.0);
  for (std::size_t k = 0; k < count; ++k) {
    for (std::size_t j = 8; j < 11; ++j) unbent.records[12 * k + j] = 0.0;
    for (std::size_t j = 0; j < 7; ++j) unbent8.records[8 * k + j] = bonds.records[12 * k + j];
    for (std::size_t j = 0; j < 4; ++j) unbent4.records[4 * k + j] = bonds.records[12 * k + j];
  }
  const Columns ref_unbent = run(kernels::scalar_kernels(), true, unbent);
  const Columns ref_unbent_cut = run(kernels::scalar_kernels(), true, unbent8, kernels::BondRecord::levers);
  const Columns ref_forces = run(kernels::scalar_kernels(), true, unbent4, kernels::BondRecord::forces);
  for (int c = 0; c < 6; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(ref_unbent[c][i], ref_unbent_cut[c][i]) << c << " " << i;
      ASSERT_EQ(c < 3 ? ref_unbent[c][i] : ref_pairs[c][i], ref_forces[c][i]) << "forces only: " << c << " " << i;
    }
  EXPECT_NE(0, std::memcmp(ref_unbent[5].data(), ref[5].data(), n * sizeof(double)))
      << "the moments do reach the torques";
  std::size_t checked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (inert[i] || idle[i]) {
      EXPECT_EQ(ref[0][i], -7.0) << "a skipped particle is not written";
      continue;
    }
    double fx = 0, tz = 0;
    for (const List* l : {&pairs, &bonds}) {
      if (l == &bonds) {  // the pairs' sums so far: what the kernel gives without bonds
        EXPECT_EQ(ref_pairs[0][i], fx) << i;
        EXPECT_EQ(ref_pairs[5][i], tz) << i;
      }
      const std::size_t width = l == &pairs ? 8 : 12;
      for (std::int32_t e = l->inc.start[i]; e < l->inc.start[i + 1]; ++e) {
        const std::size_t k = std::size_t(l->inc.entry[e] >> 1);
        const bool is_b = l->inc.entry[e] & 1;
        EXPECT_EQ(is_b ? l->b[k] : l->a[k], std::int64_t(i));
        const double* r = &l->records[width * k];
        const double sgn = is_b ? 1.0 : -1.0;
        fx += sgn * r[0];
        const double lever = radius[i] - 0.5 * r[3];
        if (width == 8) tz -= lever * r[6];
        else tz += sgn * r[10] - lever * r[6];  // the beam moment acts on b, its negative on a
      }
    }
    EXPECT_EQ(ref[0][i], fx) << i;
    EXPECT_EQ(ref[5][i], tz) << i;
    checked += bonds.inc.start[i + 1] > bonds.inc.start[i] && pairs.inc.start[i + 1] > pairs.inc.start[i];
  }
  EXPECT_GT(checked, n / 2);
  for (const auto& arch : available_simd_architectures()) {
    const Columns got = run(kernels::select_kernels(arch), true, bonds);
    const Columns got_pairs = run(kernels::select_kernels(arch), false, bonds);
    const Columns got_unbent_cut = run(kernels::select_kernels(arch), true, unbent8, kernels::BondRecord::levers);
    const Columns got_forces = run(kernels::select_kernels(arch), true, unbent4, kernels::BondRecord::forces);
    for (int c = 0; c < 6; ++c) {
      EXPECT_EQ(0, std::memcmp(ref[c].data(), got[c].data(), n * sizeof(double)))
          << arch << " column " << c;
      EXPECT_EQ(0, std::memcmp(ref_pairs[c].data(), got_pairs[c].data(), n * sizeof(double)))
          << arch << " pairs alone, column " << c;
      EXPECT_EQ(0, std::memcmp(ref_unbent_cut[c].data(), got_unbent_cut[c].data(), n * sizeof(double)))
          << arch << " bonds without moments, column " << c;
      EXPECT_EQ(0, std::memcmp(ref_forces[c].data(), got_forces[c].data(), n * sizeof(double)))
          << arch << " bonds' forces only, column " << c;
    }
  }
}

// The gather skips the pair records the pair kernel flagged dead (GatherArgs::live): a pair that
// neither touches nor carries a normal force has the record (0 nx + 0, 0 ny + 0, 0 nz + 0, U,
// ny 0 - nz 0, nz 0 - nx 0, nx 0 - ny 0, 0) with U <= 0, signed zeros and all. Leaving those
// terms out must give every column bit for bit (memcmp tells -0 from +0), on particles with
// live and dead pairs, with only dead ones, and with bonds after; and a flag must be obeyed (a
// live record marked dead is left out).
TEST(KernelEquivalence, GatherSkipsDeadPairRecordsBitwise) {
  const std::size_t n = 600, count = 2400;
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1, 1);
  auto list = [&](std::size_t width, std::vector<std::int64_t>& a, std::vector<std::int64_t>& b,
                  detail::Incidence& inc, std::vector<double, AlignedAllocator<double>>& rec) {
    std::vector<std::pair<std::int64_t, std::int64_t>> ab(count);
    for (auto& [i, j] : ab) {
      i = std::int64_t(rng() % (n - 1));
      j = std::int64_t(i + 1 + rng() % 40) % std::int64_t(n);
      if (j <= i) j = i + 1;
    }
    std::sort(ab.begin(), ab.end());
    for (auto [i, j] : ab) a.push_back(i), b.push_back(j);
    detail::build_incidence(n, a.data(), b.data(), count, inc);
    rec.assign(width * count, 0.0);
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t j = 0; j < width; ++j) rec[width * k + j] = u(rng);
  };
  std::vector<std::int64_t> pa, pb, ba, bb;
  detail::Incidence pinc, binc;
  std::vector<double, AlignedAllocator<double>> prec, brec;
  list(8, pa, pb, pinc, prec);
  list(12, ba, bb, binc, brec);
  std::vector<std::uint8_t> live(count);
  std::size_t dead = 0;
  for (std::size_t k = 0; k < count; ++k) {
    double* r = &prec[8 * k];
    // Live: touching (U > 0); dead: the kernel's record of a near miss (fn = +0, Fs = +0).
    live[k] = (pa[k] % 7 == 0) || rng() % 10 == 0;  // every pair of some particles is live
    const double nx = u(rng), ny = u(rng), nz = u(rng), fn = live[k] ? 0.5 + u(rng) : 0.0;
    const double fx = live[k] ? u(rng) : 0.0, fy = live[k] ? u(rng) : 0.0, fz = live[k] ? u(rng) : 0.0;
    const double U = live[k] ? 1e-5 * (1.5 + u(rng)) : -1e-5 * (1.5 + u(rng));
    const double v[8] = {fn * nx + fx, fn * ny + fy, fn * nz + fz, U,
                         ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx, fn};
    std::copy(v, v + 8, r);
    dead += !live[k];
  }
  ASSERT_GT(dead, count / 2);
  std::vector<double> radius(n);
  for (auto& r : radius) r = 5e-4 * (1 + 0.3 * u(rng));
  using Columns = std::array<std::vector<double>, 6>;
  auto run = [&](const kernels::KernelSet& ks, const std::uint8_t* flags, bool with_bonds) {
    Columns o;
    for (auto& c : o) c.assign(n, -7.0);
    kernels::GatherArgs g{pinc.start.data(), pinc.entry.data(), prec.data(), radius.data(),
                          nullptr, nullptr, o[0].data(), o[1].data(), o[2].data(),
                          o[3].data(), o[4].data(), o[5].data()};
    g.live = flags;
    kernels::GatherArgs gb = g;
    gb.live = nullptr;
    gb.start = binc.start.data();
    gb.entry = binc.entry.data();
    gb.records = brec.data();
    ks.gather(g, with_bonds ? &gb : nullptr, 0, n);
    return o;
  };
  std::size_t only_dead = 0, mixed = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t l = 0, d = 0;
    for (std::int32_t e = pinc.start[i]; e < pinc.start[i + 1]; ++e) (live[std::size_t(pinc.entry[e] >> 1)] ? l : d)++;
    only_dead += d > 0 && l == 0;
    mixed += d > 0 && l > 0;
  }
  EXPECT_GT(only_dead, 10u);
  EXPECT_GT(mixed, 100u);
  std::vector<const kernels::KernelSet*> sets{&kernels::scalar_kernels()};
  for (const auto& arch : available_simd_architectures()) sets.push_back(&kernels::select_kernels(arch));
  std::vector<std::uint8_t> wrong = live;
  std::size_t flipped = 0;
  for (std::size_t k = 0; k < count && flipped < 5; ++k)
    if (live[k]) wrong[k] = 0, ++flipped;
  for (const kernels::KernelSet* ks : sets)
    for (bool with_bonds : {false, true}) {
      const Columns all = run(*ks, nullptr, with_bonds), skipped = run(*ks, live.data(), with_bonds);
      for (int c = 0; c < 6; ++c)
        EXPECT_EQ(0, std::memcmp(all[c].data(), skipped[c].data(), n * sizeof(double)))
            << ks->name << (with_bonds ? " with bonds" : "") << " column " << c;
      const Columns off = run(*ks, wrong.data(), with_bonds);
      EXPECT_NE(0, std::memcmp(all[0].data(), off[0].data(), n * sizeof(double))) << ks->name;
    }
}


// The neighbour search's kernel (near_loop.hpp): runs of every length from every start over
// random columns (centres near and far, a NaN centre, indices on both sides of `after`), on every
// architecture, find the entries a plain loop with the same test finds, in the same order.
TEST(KernelEquivalence, NeighbourRunKernelFindsWhatAPlainLoopFinds) {
  constexpr std::int32_t n = 64;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> x(n + kMaxLanes, 0.0), y(x), z(x), r(x);
  std::vector<std::int32_t> index(n + kMaxLanes, -1);
  for (std::int32_t t = 0; t < n; ++t) {
    x[t] = 1.2e-3 * u(rng); y[t] = 1.2e-3 * u(rng); z[t] = 1.2e-3 * u(rng);
    r[t] = 5e-4 * (1 + 0.5 * u(rng));
    index[t] = std::int32_t(rng() % 100);
  }
  x[17] = std::numeric_limits<double>::quiet_NaN();
  const kernels::NearArgs args{x.data(), y.data(), z.data(), r.data(), index.data(), 1e-4, -2e-4, 3e-4, 6e-4, 50};
  auto plain = [&](std::int32_t first, std::int32_t last) {
    std::vector<std::int32_t> out;
    for (std::int32_t t = first; t < last; ++t) {
      const double dx = x[t] - args.cx, dy = y[t] - args.cy, dz = z[t] - args.cz;
      const double cut = args.reach + r[t];
      if (dx * dx + dy * dy + dz * dz < cut * cut && index[t] > args.after) out.push_back(t);
    }
    return out;
  };
  EXPECT_GT(plain(0, n).size(), 3u);
  EXPECT_LT(plain(0, n).size(), std::size_t(n) / 2);
  std::vector<const kernels::KernelSet*> sets{&kernels::scalar_kernels()};
  for (const auto& arch : available_simd_architectures()) sets.push_back(&kernels::select_kernels(arch));
  std::vector<std::int32_t> hits(n);
  for (const auto* set : sets)
    for (std::int32_t first = 0; first <= n; ++first)
      for (std::int32_t last = first; last <= n; ++last) {
        const std::int32_t run[2] = {first, last};
        const std::size_t found = set->near(args, run, 1, hits.data());
        const std::vector<std::int32_t> want = plain(first, last);
        ASSERT_EQ(std::vector<std::int32_t>(hits.begin(), hits.begin() + std::ptrdiff_t(found)), want)
            << set->name << " [" << first << ", " << last << ")";
      }
  // Several runs in one call, as the search passes a particle's rows: their hits run after run.
  std::mt19937 pick(3);
  for (const auto* set : sets)
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<std::int32_t> runs, want;
      const std::size_t count = pick() % 19;
      for (std::size_t m = 0; m < count; ++m) {
        const std::int32_t a = std::int32_t(pick() % (n + 1)), b = std::int32_t(pick() % (n + 1));
        runs.insert(runs.end(), {std::min(a, b), std::max(a, b)});
        const auto part = plain(std::min(a, b), std::max(a, b));
        want.insert(want.end(), part.begin(), part.end());
      }
      std::vector<std::int32_t> all(count * n + 1);
      const std::size_t found = set->near(args, runs.data(), count, all.data());
      ASSERT_EQ(std::vector<std::int32_t>(all.begin(), all.begin() + std::ptrdiff_t(found)), want)
          << set->name << ", trial " << trial;
    }
}
