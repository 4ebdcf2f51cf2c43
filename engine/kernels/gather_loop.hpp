// The pair and bond gathers (kernels.hpp, GatherKernel): the scalar references, and the same sums
// with one 256-bit vector per quarter of a record on AVX2 and AVX-512. Per incidence the
// references do
//   pairs: f += s * (fx, fy, fz),   t -= (R - U/2) * (cx, cy, cz)
//   bonds: f += s * (fx, fy, fz),   t += s * (mx, my, mz) - (R - U/2) * (cx, cy, cz)
// with s = +1 on b, -1 on a, the bonds' terms as far as their BondRecord holds them; the vector
// versions do exactly these operations on lanes 0-2 of the record's quarters (lane 3, the
// overlap or the padding, is computed and dropped), so the sums are equal bit for bit, in about
// half the instructions per incidence.
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

// A pair whose record the pair kernel flagged dead: zeros but for its overlap (GatherArgs::live).
inline bool skips_record(const GatherArgs& g, std::int64_t entry) {
  return g.live && !g.live[std::size_t(entry >> 1)];
}

// Bonds = false: the pair list (records of 8); true: the bond list, in the layout Layout
// (BondRecord): with the beam's moment, which acts on b and its negative on a; without (every
// moment zero: t - lever C is what t + (s 0 - lever C) gives); or forces only (no end turns: no
// torque term).
template <bool Bonds, BondRecord Layout = BondRecord::moments>
inline constexpr std::size_t record_width = Bonds ? std::size_t(Layout) : 8;

template <bool Bonds, BondRecord Layout = BondRecord::moments>
inline void add_incidences_scalar(const GatherArgs& g, std::size_t i, double R, double f[3],
                                  double t[3]) {
  constexpr std::size_t width = record_width<Bonds, Layout>;
  for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
    if (!Bonds && skips_record(g, g.entry[e])) continue;
    const double* r = g.records + width * std::size_t(g.entry[e] >> 1);
    const double sgn = (g.entry[e] & 1) ? 1.0 : -1.0;
    f[0] += sgn * r[0];
    f[1] += sgn * r[1];
    f[2] += sgn * r[2];
    if constexpr (Bonds && Layout == BondRecord::forces) continue;
    const double lever = R - 0.5 * r[3];
    if constexpr (Bonds && Layout == BondRecord::moments) {
      t[0] += sgn * r[8] - lever * r[4];
      t[1] += sgn * r[9] - lever * r[5];
      t[2] += sgn * r[10] - lever * r[6];
    } else {
      t[0] -= lever * r[4];
      t[1] -= lever * r[5];
      t[2] -= lever * r[6];
    }
  }
}

// The scalar reference: each particle's pair sums, then (bonds not null) its bond terms added to
// them, written once to fx..tz[i].
inline void gather_scalar(const GatherArgs& pairs, const GatherArgs* bonds, std::size_t begin,
                          std::size_t end) {
  const GatherArgs& g = pairs;
  for (std::size_t i = begin; i < end; ++i) {
    if (gather_skips(g, i)) continue;
    const double R = g.radius[i];
    double f[3] = {0, 0, 0}, t[3] = {0, 0, 0};
    add_incidences_scalar<false>(pairs, i, R, f, t);
    if (bonds && bonds->bond_record == BondRecord::moments)
      add_incidences_scalar<true, BondRecord::moments>(*bonds, i, R, f, t);
    else if (bonds && bonds->bond_record == BondRecord::levers)
      add_incidences_scalar<true, BondRecord::levers>(*bonds, i, R, f, t);
    else if (bonds)
      add_incidences_scalar<true, BondRecord::forces>(*bonds, i, R, f, t);
    g.fx[i] = f[0]; g.fy[i] = f[1]; g.fz[i] = f[2];
    g.tx[i] = t[0]; g.ty[i] = t[1]; g.tz[i] = t[2];
  }
}

#if defined(__AVX2__)
// Records of the particle this many ahead (GatherArgs::prefetch): far enough that the lines
// arrive before the gather reaches them, and farther with AVX-512, whose gather gets through the
// particles faster. Both distances are the best of trials, not derived.
#if defined(__AVX512F__)
inline constexpr std::size_t kGatherAhead = 32;
#else
inline constexpr std::size_t kGatherAhead = 8;
#endif

template <bool Bonds, BondRecord Layout = BondRecord::moments>
inline void prefetch_records(const GatherArgs& g, std::size_t i) {
  constexpr std::size_t width = record_width<Bonds, Layout>;
  for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e)
    if (!skips_record(g, g.entry[e]))
      _mm_prefetch(reinterpret_cast<const char*>(g.records + width * std::size_t(g.entry[e] >> 1)),
                 _MM_HINT_T0);
}

template <bool Bonds, BondRecord Layout = BondRecord::moments>
inline void add_incidences_vector(const GatherArgs& g, std::size_t i, __m256d R, __m256d& f,
                                  __m256d& t) {
  constexpr std::size_t width = record_width<Bonds, Layout>;
  static const double sign[2] = {-1.0, 1.0};  // by the entry's "is b" bit
  const __m256d half = _mm256_set1_pd(0.5);
  for (std::int32_t e = g.start[i]; e < g.start[i + 1]; ++e) {
    const std::int64_t entry = g.entry[e];
    if (!Bonds && skips_record(g, entry)) continue;
    const double* r = g.records + width * std::size_t(entry >> 1);
    const __m256d s = _mm256_broadcast_sd(sign + (entry & 1));
    f = _mm256_add_pd(f, _mm256_mul_pd(s, _mm256_load_pd(r)));
    if constexpr (Bonds && Layout == BondRecord::forces) continue;
    const __m256d lever = _mm256_sub_pd(R, _mm256_mul_pd(half, _mm256_broadcast_sd(r + 3)));
    if constexpr (Bonds && Layout == BondRecord::moments)
      t = _mm256_add_pd(t, _mm256_sub_pd(_mm256_mul_pd(s, _mm256_load_pd(r + 8)),
                                         _mm256_mul_pd(lever, _mm256_load_pd(r + 4))));
    else
      t = _mm256_sub_pd(t, _mm256_mul_pd(lever, _mm256_load_pd(r + 4)));
  }
}

// The same sums with one 256-bit vector per quarter record. Pairs and bonds in one pass: the
// particle's sums stay in two registers from its first pair to its last bond instead of being
// stored by a pair gather and loaded back by a bond gather.
template <bool Bonds, BondRecord Layout = BondRecord::moments>
inline void gather_vector(const GatherArgs& pairs, const GatherArgs* bonds, std::size_t begin,
                          std::size_t end) {
  const GatherArgs& g = pairs;
  for (std::size_t i = begin; i < end; ++i) {
    if (i + kGatherAhead < end) {
      if (pairs.prefetch) prefetch_records<false>(pairs, i + kGatherAhead);
      if (Bonds && bonds->prefetch) prefetch_records<true, Layout>(*bonds, i + kGatherAhead);
    }
    if (gather_skips(g, i)) continue;
    const __m256d R = _mm256_set1_pd(g.radius[i]);
    __m256d f = _mm256_setzero_pd(), t = _mm256_setzero_pd();
    add_incidences_vector<false>(pairs, i, R, f, t);
    if constexpr (Bonds) add_incidences_vector<true, Layout>(*bonds, i, R, f, t);
    alignas(32) double fo[4], to[4];
    _mm256_store_pd(fo, f);
    _mm256_store_pd(to, t);
    g.fx[i] = fo[0]; g.fy[i] = fo[1]; g.fz[i] = fo[2];
    g.tx[i] = to[0]; g.ty[i] = to[1]; g.tz[i] = to[2];
  }
}

// The kernel: bonds null where the scene has none.
inline void gather_vector_kernel(const GatherArgs& pairs, const GatherArgs* bonds,
                                 std::size_t begin, std::size_t end) {
  if (bonds && bonds->bond_record == BondRecord::moments)
    gather_vector<true, BondRecord::moments>(pairs, bonds, begin, end);
  else if (bonds && bonds->bond_record == BondRecord::levers)
    gather_vector<true, BondRecord::levers>(pairs, bonds, begin, end);
  else if (bonds)
    gather_vector<true, BondRecord::forces>(pairs, bonds, begin, end);
  else
    gather_vector<false>(pairs, nullptr, begin, end);
}
#endif

}  // namespace asperity::kernels
