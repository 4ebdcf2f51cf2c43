// The pair and bond gathers (kernels.hpp, GatherKernel): the scalar references, and the same sums
// with one 256-bit vector per quarter of a record on AVX2 and AVX-512. Per incidence the
// references do
//   pairs: f += s * (fx, fy, fz),   t -= (R - U/2) * (cx, cy, cz)
//   bonds: f += s * (fx, fy, fz),   t += s * (mx, my, mz) - (R - U/2) * (cx, cy, cz)
// with s = +1 on b, -1 on a, and the vector versions do exactly these operations on lanes 0-2
// of the record's quarters (lane 3, the overlap or the padding, is computed and dropped), so the
// sums are equal bit for bit. About 12 instructions per pair incidence against ~25
// (perf/README.md).
#pragma once
#include <cstdint>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "kernels/kernels.hpp"

namespace asperity::kernels {

inline bool gather_skips(const GatherArgs& g, std::size_t i) {
  return (g.inert && g.inert[i]) || (g.idle && g.idle[i]);
}

// Bonds = false: the pair list (records of 8), its sums written to fx..tz[i]; true: the bond
// list (records of 12), its terms added to them (a particle without bonds is left as it is).
template <bool Bonds>
inline void gather_scalar(const GatherArgs& g, std::size_t begin, std::size_t end) {
  constexpr std::size_t width = Bonds ? 12 : 8;
  for (std::size_t i = begin; i < end; ++i) {
    if (gather_skips(g, i) || (Bonds && g.start[i] == g.start[i + 1])) continue;
    const double R = g.radius[i];
    double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
    if constexpr (Bonds) {
      fx = g.fx[i]; fy = g.fy[i]; fz = g.fz[i];
      tx = g.tx[i]; ty = g.ty[i]; tz = g.tz[i];
    }
    for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
      const double* r = g.records + width * std::size_t(g.entry[e] >> 1);
      const double sgn = (g.entry[e] & 1) ? 1.0 : -1.0;
      fx += sgn * r[0];
      fy += sgn * r[1];
      fz += sgn * r[2];
      const double lever = R - 0.5 * r[3];
      if constexpr (Bonds) {  // the beam's moment acts on b, its negative on a
        tx += sgn * r[8] - lever * r[4];
        ty += sgn * r[9] - lever * r[5];
        tz += sgn * r[10] - lever * r[6];
      } else {
        tx -= lever * r[4];
        ty -= lever * r[5];
        tz -= lever * r[6];
      }
    }
    g.fx[i] = fx; g.fy[i] = fy; g.fz[i] = fz;
    g.tx[i] = tx; g.ty[i] = ty; g.tz[i] = tz;
  }
}

#if defined(__AVX2__)
template <bool Bonds>
inline void gather_vector(const GatherArgs& g, std::size_t begin, std::size_t end) {
  constexpr std::size_t width = Bonds ? 12 : 8;
  static const double sign[2] = {-1.0, 1.0};  // by the entry's "is b" bit
  const __m256d half = _mm256_set1_pd(0.5);
  constexpr std::size_t ahead = 8;  // particles (GatherArgs::prefetch)
  for (std::size_t i = begin; i < end; ++i) {
    if (g.prefetch && i + ahead < end)
      for (std::int32_t e = g.start[i + ahead]; e < g.start[i + ahead + 1]; ++e)
        _mm_prefetch(reinterpret_cast<const char*>(g.records + width * std::size_t(g.entry[e] >> 1)),
                     _MM_HINT_T0);
    if (gather_skips(g, i) || (Bonds && g.start[i] == g.start[i + 1])) continue;
    const __m256d R = _mm256_set1_pd(g.radius[i]);
    __m256d f = _mm256_setzero_pd(), t = _mm256_setzero_pd();
    if constexpr (Bonds) {
      f = _mm256_setr_pd(g.fx[i], g.fy[i], g.fz[i], 0.0);
      t = _mm256_setr_pd(g.tx[i], g.ty[i], g.tz[i], 0.0);
    }
    for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
      const std::int64_t entry = g.entry[e];
      const double* r = g.records + width * std::size_t(entry >> 1);
      const __m256d s = _mm256_broadcast_sd(sign + (entry & 1));
      const __m256d lever = _mm256_sub_pd(R, _mm256_mul_pd(half, _mm256_broadcast_sd(r + 3)));
      f = _mm256_add_pd(f, _mm256_mul_pd(s, _mm256_load_pd(r)));
      if constexpr (Bonds)
        t = _mm256_add_pd(t, _mm256_sub_pd(_mm256_mul_pd(s, _mm256_load_pd(r + 8)),
                                           _mm256_mul_pd(lever, _mm256_load_pd(r + 4))));
      else
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
