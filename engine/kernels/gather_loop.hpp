// The pair gather (kernels.hpp, PairGatherKernel): the scalar reference, and the same sums with
// one 256-bit vector per half record on AVX2 and AVX-512. Per incidence the reference does
//   f += s * (fx, fy, fz),   t -= (R - U/2) * (cx, cy, cz),   s = +1 on b, -1 on a,
// and the vector version does exactly these operations on lanes 0-2 of the record's halves
// (lane 3, the overlap or the padding, is computed and dropped), so the sums are equal bit for
// bit. It issues about 12 instructions per incidence against the reference's ~25 (perf/README.md).
#pragma once
#include <cstdint>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "kernels/kernels.hpp"

namespace asperity::kernels {

inline bool gather_skips(const PairGatherArgs& g, std::size_t i) {
  return (g.inert && g.inert[i]) || (g.idle && g.idle[i]);
}

inline void gather_pairs_scalar(const PairGatherArgs& g, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) {
    if (gather_skips(g, i)) continue;
    const double R = g.radius[i];
    double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
    for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
      const double* r = g.records + 8 * std::size_t(g.entry[e] >> 1);
      const double sgn = (g.entry[e] & 1) ? 1.0 : -1.0;
      fx += sgn * r[0];
      fy += sgn * r[1];
      fz += sgn * r[2];
      const double lever = R - 0.5 * r[3];
      tx -= lever * r[4];
      ty -= lever * r[5];
      tz -= lever * r[6];
    }
    g.fx[i] = fx; g.fy[i] = fy; g.fz[i] = fz;
    g.tx[i] = tx; g.ty[i] = ty; g.tz[i] = tz;
  }
}

#if defined(__AVX2__)
inline void gather_pairs_vector(const PairGatherArgs& g, std::size_t begin, std::size_t end) {
  static const double sign[2] = {-1.0, 1.0};  // by the entry's "is b" bit
  const __m256d half = _mm256_set1_pd(0.5);
  for (std::size_t i = begin; i < end; ++i) {
    if (gather_skips(g, i)) continue;
    const __m256d R = _mm256_set1_pd(g.radius[i]);
    __m256d f = _mm256_setzero_pd(), t = _mm256_setzero_pd();
    for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
      const std::int64_t entry = g.entry[e];
      const double* r = g.records + 8 * std::size_t(entry >> 1);
      const __m256d s = _mm256_broadcast_sd(sign + (entry & 1));
      const __m256d lever = _mm256_sub_pd(R, _mm256_mul_pd(half, _mm256_broadcast_sd(r + 3)));
      f = _mm256_add_pd(f, _mm256_mul_pd(s, _mm256_load_pd(r)));
      t = _mm256_sub_pd(t, _mm256_mul_pd(lever, _mm256_load_pd(r + 4)));
    }
    alignas(32) double fo[4], to[4];
    _mm256_store_pd(fo, f);
    _mm256_store_pd(to, t);
    g.fx[i] = fo[0]; g.fy[i] = fo[1]; g.fz[i] = fo[2];
    g.tx[i] = to[0]; g.ty[i] = to[1]; g.tz[i] = to[2];
  }
}
#endif

}  // namespace asperity::kernels
