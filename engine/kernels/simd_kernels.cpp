// SIMD pair kernel, compiled once per instruction set (engine/CMakeLists.txt passes
// ASPERITY_SIMD_ARCH and the matching -m flag). Same loop and law as the scalar reference; only
// the loads and stores differ: gathers of the particle columns by pair index, aligned loads and
// stores of the pair columns (blocks start at multiples of kMaxLanes on 64-byte aligned columns).
#include <immintrin.h>

#include <xsimd/xsimd.hpp>

#include "kernels/bond_loop.hpp"
#include "kernels/integrate_loop.hpp"
#include "kernels/pair_loop.hpp"

#define ASPERITY_CAT2(a, b) a##b
#define ASPERITY_CAT(a, b) ASPERITY_CAT2(a, b)

namespace asperity::kernels {
namespace {

using Arch = xsimd::ASPERITY_SIMD_ARCH;

struct SimdLanes {
  using Real = xsimd::batch<double, Arch>;
  using Index = xsimd::batch<std::int64_t, Arch>;
  static constexpr std::size_t size = Real::size;
  static Index index(const std::int64_t* p) { return Index::load_aligned(p); }
  // xsimd 8's batch::gather passes two explicit template arguments to its kernels, which rules
  // out its own AVX2 / AVX-512 double overloads and falls back to inserting lane by lane (a
  // quarter of the lattice step's time). Call the hardware gathers directly where they exist.
  static Real gather(const double* col, const Index& i) {
#if defined(__AVX512F__)
    return _mm512_i64gather_pd(i, col, 8);
#elif defined(__AVX2__)
    return _mm256_i64gather_pd(col, i, 8);
#else
    return Real::gather(col, i);
#endif
  }
  static Real load(const double* p) { return Real::load_aligned(p); }
  static void store(double* p, const Real& v) { v.store_aligned(p); }
  static double sum(const Real& v) { return xsimd::hadd(v); }
  static Real iota(double start) {
    alignas(64) double l[size];
    for (std::size_t j = 0; j < size; ++j) l[j] = start + double(j);
    return Real::load_aligned(l);
  }
  static double lane(const Real& v, std::size_t j) {
    alignas(64) double l[size];
    v.store_aligned(l);
    return l[j];
  }
};

double pair_rot(const PairKernelArgs& k, std::size_t b, std::size_t e) {
  return pair_loop<SimdLanes, true>(k, b, e);
}
double pair_norot(const PairKernelArgs& k, std::size_t b, std::size_t e) {
  return pair_loop<SimdLanes, false>(k, b, e);
}
double bond_rot(const BondKernelArgs& k, std::size_t b, std::size_t e) {
  return bond_loop<SimdLanes, true>(k, b, e);
}
double bond_norot(const BondKernelArgs& k, std::size_t b, std::size_t e) {
  return bond_loop<SimdLanes, false>(k, b, e);
}

void integrate_rot(const IntegrateArgs& k, std::size_t b, std::size_t e, IntegrateSums& out) {
  integrate_loop<SimdLanes, true>(k, b, e, out);
}
void integrate_norot(const IntegrateArgs& k, std::size_t b, std::size_t e, IntegrateSums& out) {
  integrate_loop<SimdLanes, false>(k, b, e, out);
}

}  // namespace

#define ASPERITY_STR2(a) #a
#define ASPERITY_STR(a) ASPERITY_STR2(a)

const KernelSet& ASPERITY_CAT(kernels_, ASPERITY_SIMD_ARCH)() {
  static const KernelSet set{ASPERITY_STR(ASPERITY_SIMD_ARCH), SimdLanes::size, &pair_rot,
                             &pair_norot, &bond_rot, &bond_norot,
                             &integrate_rot, &integrate_norot};
  return set;
}

}  // namespace asperity::kernels
