// SIMD pair kernel, compiled once per instruction set (engine/CMakeLists.txt passes
// ASPERITY_SIMD_ARCH and the matching -m flag). Same loop and law as the scalar reference; only
// the loads and stores differ: gathers of the particle columns by pair index, aligned loads and
// stores of the pair columns (blocks start at multiples of kMaxLanes on 64-byte aligned columns).
#include <immintrin.h>

#include <xsimd/xsimd.hpp>

#include "kernels/bond_loop.hpp"
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

}  // namespace

#define ASPERITY_STR2(a) #a
#define ASPERITY_STR(a) ASPERITY_STR2(a)

const KernelSet& ASPERITY_CAT(kernels_, ASPERITY_SIMD_ARCH)() {
  static const KernelSet set{ASPERITY_STR(ASPERITY_SIMD_ARCH), SimdLanes::size, &pair_rot,
                             &pair_norot, &bond_rot, &bond_norot};
  return set;
}

}  // namespace asperity::kernels
