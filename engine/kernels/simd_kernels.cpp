// SIMD pair kernel, compiled once per instruction set (engine/CMakeLists.txt passes
// ASPERITY_SIMD_ARCH and the matching -m flag). Same loop and law as the scalar reference; only
// the loads and stores differ: gathers of the particle columns by pair index, aligned loads and
// stores of the pair columns (blocks start at multiples of kMaxLanes on 64-byte aligned columns).
#include <immintrin.h>

#include <xsimd/xsimd.hpp>

#include "kernels/bond_loop.hpp"
#include "kernels/integrate_loop.hpp"
#include "kernels/pair_loop.hpp"
#include "kernels/wall_loop.hpp"

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
  // a_side.hpp: lane offsets from the batch's first a, whether all lie in [0, size), and the
  // window load permuted by them. SSE has no variable double permutation: it always gathers.
  static Index offsets(const Index& i, std::int64_t first) { return i - Index(first); }
  static bool fits(const Index& off) {
#if defined(__AVX512F__)
    return _mm512_cmplt_epu64_mask(off, _mm512_set1_epi64(std::int64_t(size))) == 0xFF;
#elif defined(__AVX2__)
    const __m256i v = off;
    const __m256i out = _mm256_or_si256(_mm256_cmpgt_epi64(_mm256_setzero_si256(), v),
                                        _mm256_cmpgt_epi64(v, _mm256_set1_epi64x(std::int64_t(size) - 1)));
    return _mm256_testz_si256(out, out);
#else
    (void)off;
    return false;
#endif
  }
  static Real window(const double* p, const Index& off) {
#if defined(__AVX512F__)
    return _mm512_permutexvar_pd(off, _mm512_loadu_pd(p));
#elif defined(__AVX2__)
    // No 64-bit variable permutation in AVX2: move 32-bit halves, lane j taking elements
    // 2 off_j and 2 off_j + 1.
    const __m256i twice = _mm256_slli_epi64(off, 1);
    const __m256i idx = _mm256_add_epi64(
        twice, _mm256_slli_epi64(_mm256_add_epi64(twice, _mm256_set1_epi64x(1)), 32));
    return _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(_mm256_loadu_pd(p)), idx));
#else
    (void)off;
    return Real::load_unaligned(p);  // never called: fits() is false
#endif
  }
  static Real load(const double* p) { return Real::load_aligned(p); }
  static void store(double* p, const Real& v) { v.store_aligned(p); }
  // The wall contact list's columns (std::vector, any alignment) and its 32-bit indices.
  static Real load_u(const double* p) { return Real::load_unaligned(p); }
  static void store_u(double* p, const Real& v) { v.store_unaligned(p); }
  static Index index32(const std::int32_t* p) {
#if defined(__AVX512F__)
    return _mm512_cvtepi32_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
#elif defined(__AVX2__)
    return _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
#else
    return _mm_cvtepi32_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
#endif
  }
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

void plane_walls_rot(const PlaneWallArgs& k, std::size_t b, std::size_t e) {
  plane_wall_loop<SimdLanes, true>(k, b, e);
}
void plane_walls_norot(const PlaneWallArgs& k, std::size_t b, std::size_t e) {
  plane_wall_loop<SimdLanes, false>(k, b, e);
}

}  // namespace

#define ASPERITY_STR2(a) #a
#define ASPERITY_STR(a) ASPERITY_STR2(a)

const KernelSet& ASPERITY_CAT(kernels_, ASPERITY_SIMD_ARCH)() {
  static const KernelSet set{ASPERITY_STR(ASPERITY_SIMD_ARCH), SimdLanes::size, &pair_rot,
                             &pair_norot, &bond_rot, &bond_norot,
                             &integrate_rot, &integrate_norot, &plane_walls_rot,
                             &plane_walls_norot};
  return set;
}

}  // namespace asperity::kernels
