// SIMD pair kernel, compiled once per instruction set (engine/CMakeLists.txt passes
// ASPERITY_SIMD_ARCH and the matching -m flag). Same loop and law as the scalar reference; only
// the loads and stores differ: gathers of the particle columns by pair index, aligned loads and
// stores of the pair columns (blocks start at multiples of kMaxLanes on 64-byte aligned columns).
#include <immintrin.h>

#include <xsimd/xsimd.hpp>

#include "kernels/gather_loop.hpp"
#include "kernels/kernel_set.hpp"

#define ASPERITY_CAT2(a, b) a##b
#define ASPERITY_CAT(a, b) ASPERITY_CAT2(a, b)

namespace asperity::kernels {
namespace {

using Arch = xsimd::ASPERITY_SIMD_ARCH;

struct SimdLanes {
  using Real = xsimd::batch<double, Arch>;
  using Index = xsimd::batch<std::int64_t, Arch>;
  static constexpr std::size_t size = Real::size;
  // The pair loop in one pass over touching stages on AVX-512 machines, two on the others
  // (pair_loop.hpp says why).
  static constexpr bool kOnePass = size == 8;
  static Index index(const std::int64_t* p) { return Index::load_aligned(p); }
  // xsimd 8's batch::gather passes two explicit template arguments to its kernels, which rules
  // out its own AVX2 / AVX-512 double overloads and falls back to inserting lane by lane, slowly.
  // The hardware gathers lose to scalar loads as well on AMD's cores (Zen 2 and 3 microcode the
  // AVX2 gather; on Zen 5 eight scalar loads beat the AVX-512 one), so the lanes are loaded one
  // by one and inserted here. Same values, bit for bit.
  static Real gather(const double* col, const Index& i) {
#if defined(__AVX512F__)
    alignas(64) std::int64_t k[8];
    _mm512_store_si512(k, i);
    const __m256d lo = four_loads(col, k), hi = four_loads(col, k + 4);
    return _mm512_insertf64x4(_mm512_castpd256_pd512(lo), hi, 1);
#elif defined(__AVX2__)
    alignas(32) std::int64_t k[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(k), i);
    return four_loads(col, k);
#else
    return Real::gather(col, i);
#endif
  }
#if defined(__AVX2__)
  // col[k[0..3]] by four scalar loads, as one 256-bit vector.
  static __m256d four_loads(const double* col, const std::int64_t* k) {
    const __m128d lo = _mm_loadh_pd(_mm_load_sd(col + k[0]), col + k[1]);
    const __m128d hi = _mm_loadh_pd(_mm_load_sd(col + k[2]), col + k[3]);
    return _mm256_insertf128_pd(_mm256_castpd128_pd256(lo), hi, 1);
  }
#endif
  // Entry i of a small table (wall_loop.hpp: a column per wall, readable to kMaxLanes entries
  // when `entries` > 0): a lane permutation of the whole table where it has no more entries than
  // lanes (AVX2, AVX-512), else a gather. The same values.
  static Real lookup(const double* table, const Index& i, std::size_t entries) {
#if defined(__AVX2__)
    if (entries > 0 && entries <= size) return window(table, i);
#else
    (void)entries;
#endif
    return gather(table, i);
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
  // A byte per lane, 1 where v is not zero (PairKernelArgs::live).
  static void store_flags(std::uint8_t* p, const Real& v) {
#if defined(__AVX512F__)
    const __mmask8 m = _mm512_cmp_pd_mask(v, _mm512_setzero_pd(), _CMP_NEQ_UQ);
    _mm512_mask_cvtepi64_storeu_epi8(p, 0xFF, _mm512_maskz_set1_epi64(m, 1));
#else
    alignas(64) double l[size];
    v.store_aligned(l);
    for (std::size_t j = 0; j < size; ++j) p[j] = l[j] != 0.0;
#endif
  }
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
  // Records (store/pairs.hpp, store/bonds.hpp): v[j] holds value j of the batch's pairs or bonds;
  // the Width values of item p go to rec[Width p .. Width p + Width - 1]. A transpose of the rows,
  // then full-line stores per item (half lines on AVX2, quarters on SSE; two items a line for
  // Width 4 on AVX-512). rec is 64-byte aligned for Width 8, 32-byte aligned for Widths 4 and 12.
  // Stream: non-temporal stores (record arrays past the caches, whose lines then need no read
  // for ownership: pairs.cpp) on AVX2 and, for records of 8, AVX-512; plain ones elsewhere.
  template <int Width, bool Stream = false>
  static void store_records(double* rec, const Real* v) {
    static_assert(Width == 4 || Width == 8 || Width == 12, "records of 4, 8 or 12 values");
#if defined(__AVX512F__)
    // Four rows of values (r[0..3]) -> q[0] = those values of items 0 and 4, q[1] of items 1 and
    // 5, q[2] of 2 and 6, q[3] of 3 and 7: rows -> pairs of two-element runs -> half records.
    auto quarters = [](const Real* r, __m512d (&q)[4]) {
      const __m512d t0 = _mm512_unpacklo_pd(r[0], r[1]), t1 = _mm512_unpackhi_pd(r[0], r[1]);
      const __m512d t2 = _mm512_unpacklo_pd(r[2], r[3]), t3 = _mm512_unpackhi_pd(r[2], r[3]);
      // t0 = r0_0 r1_0 r0_2 r1_2 r0_4 r1_4 r0_6 r1_6 (rj_p: row j of item p); t1 the odd items.
      const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
      const __m512i hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
      q[0] = _mm512_permutex2var_pd(t0, lo, t2);
      q[1] = _mm512_permutex2var_pd(t1, lo, t3);
      q[2] = _mm512_permutex2var_pd(t0, hi, t2);
      q[3] = _mm512_permutex2var_pd(t1, hi, t3);
    };
    __m512d u[4];  // values 0..3
    quarters(v, u);
    if constexpr (Width == 4) {  // the low halves of u[0] and u[1] are items 0 and 1: one line
      _mm512_storeu_pd(rec, _mm512_shuffle_f64x2(u[0], u[1], 0x44));
      _mm512_storeu_pd(rec + 8, _mm512_shuffle_f64x2(u[2], u[3], 0x44));
      _mm512_storeu_pd(rec + 16, _mm512_shuffle_f64x2(u[0], u[1], 0xEE));
      _mm512_storeu_pd(rec + 24, _mm512_shuffle_f64x2(u[2], u[3], 0xEE));
    } else {
      __m512d w[4];  // values 4..7
      quarters(v + 4, w);
      for (int p = 0; p < 4; ++p) {
        if constexpr (Stream && Width == 8) {  // whole 64-byte lines, 64-byte aligned
          _mm512_stream_pd(rec + Width * p, _mm512_shuffle_f64x2(u[p], w[p], 0x44));
          _mm512_stream_pd(rec + Width * (p + 4), _mm512_shuffle_f64x2(u[p], w[p], 0xEE));
        } else {
          _mm512_storeu_pd(rec + Width * p, _mm512_shuffle_f64x2(u[p], w[p], 0x44));
          _mm512_storeu_pd(rec + Width * (p + 4), _mm512_shuffle_f64x2(u[p], w[p], 0xEE));
        }
      }
      if constexpr (Width == 12) {  // values 8..11: quarter lines
        __m512d x[4];
        quarters(v + 8, x);
        for (int p = 0; p < 4; ++p) {
          _mm256_store_pd(rec + Width * p + 8, _mm512_castpd512_pd256(x[p]));
          _mm256_store_pd(rec + Width * (p + 4) + 8, _mm512_extractf64x4_pd(x[p], 1));
        }
      }
    }
#elif defined(__AVX2__)
    for (int h = 0; h < Width; h += 4) {  // values h..h+3: a 4 x 4 transpose each
      const __m256d t0 = _mm256_unpacklo_pd(v[h], v[h + 1]), t1 = _mm256_unpackhi_pd(v[h], v[h + 1]);
      const __m256d t2 = _mm256_unpacklo_pd(v[h + 2], v[h + 3]), t3 = _mm256_unpackhi_pd(v[h + 2], v[h + 3]);
      auto put = [](double* p, __m256d r) {
        if constexpr (Stream) _mm256_stream_pd(p, r);
        else _mm256_store_pd(p, r);
      };
      put(rec + h, _mm256_permute2f128_pd(t0, t2, 0x20));
      put(rec + Width + h, _mm256_permute2f128_pd(t1, t3, 0x20));
      put(rec + 2 * Width + h, _mm256_permute2f128_pd(t0, t2, 0x31));
      put(rec + 3 * Width + h, _mm256_permute2f128_pd(t1, t3, 0x31));
    }
#else
    static_assert(size == 2, "SSE: two lanes");
    for (int j = 0; j < Width; j += 2) {
      _mm_store_pd(rec + j, _mm_unpacklo_pd(v[j], v[j + 1]));
      _mm_store_pd(rec + Width + j, _mm_unpackhi_pd(v[j], v[j + 1]));
    }
#endif
  }
  static Real iota(double start) {
    alignas(64) double l[size];
    for (std::size_t j = 0; j < size; ++j) l[j] = start + double(j);
    return Real::load_aligned(l);
  }
  // Bit j set where lane j holds (near_loop.hpp).
  static std::uint64_t bits(const xsimd::batch_bool<double, Arch>& m) {
#if defined(__AVX512F__)
    return std::uint64_t(__mmask8(m));  // the batch_bool is the mask register
#elif defined(__AVX2__)
    return std::uint64_t(unsigned(_mm256_movemask_pd(m)));
#else
    return std::uint64_t(unsigned(_mm_movemask_pd(m)));
#endif
  }
  static std::uint64_t bits(const xsimd::batch_bool<std::int64_t, Arch>& m) {
#if defined(__AVX512F__)
    return std::uint64_t(__mmask8(m));
#elif defined(__AVX2__)
    return std::uint64_t(unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(m))));
#else
    return std::uint64_t(unsigned(_mm_movemask_pd(_mm_castsi128_pd(m))));
#endif
  }
  static double lane(const Real& v, std::size_t j) {
    alignas(64) double l[size];
    v.store_aligned(l);
    return l[j];
  }
};

#if defined(__AVX2__)
constexpr GatherKernel gather = &gather_vector_kernel;
#else  // SSE: two lanes do not beat the scalar loop here
constexpr GatherKernel gather = &gather_scalar;
#endif

}  // namespace

#define ASPERITY_STR2(a) #a
#define ASPERITY_STR(a) ASPERITY_STR2(a)

const KernelSet& ASPERITY_CAT(kernels_, ASPERITY_SIMD_ARCH)() {
  static const KernelSet set =
      loop_kernels<SimdLanes>(ASPERITY_STR(ASPERITY_SIMD_ARCH), gather);
  return set;
}

}  // namespace asperity::kernels
