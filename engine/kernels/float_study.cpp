// Single-precision force laws, for issue 7's run-time-against-error study: the kernel set
// "float" (`simd = "float"`). It measures how far the joint's and the REV's results move when
// the contact and bond laws run in float (perf/README.md: ten times below the 1 % tolerance on
// the joint; a sixteen-lane float SIMD kernel built on that was then measured and did not pay).
//
// What runs in float, and what does not, is what such a kernel would do:
// - the geometry (centre distance, normal, overlap, lever arms) in double, from the double
//   positions: in float the difference of two positions ~1e-2 m apart would lose the overlap's
//   leading digits (ulp 2e-9 m against overlaps of 1e-7 .. 1e-5 m);
// - every other operation of the laws (contact_law.hpp, bond_law.hpp: velocities, the carry of
//   the shear force and beam moments, the increments, the slip cap, the bond stresses and the
//   criterion) in float, each operation rounded to float as a float kernel would;
// - the history (normals, shear forces, beam forces and moments) loaded from and stored back to
//   the double columns, so it holds float values between steps; the gather, the integration
//   and everything else stay in double.
// The kernels are the scalar loops of pair_loop.hpp and bond_loop.hpp instantiated on a float
// number type: slower than the double SIMD kernels, exact as a model of float arithmetic.
#include <cmath>

#include "kernels/bond_loop.hpp"
#include "kernels/pair_loop.hpp"

namespace asperity::kernels {
namespace {

// A float, with the double it was loaded from (read only by the double geometry below). Every
// operation rounds to float: double literals of the laws (0.5, 1.0 / 12, ...) are rounded to
// float first, as they would be in a float kernel.
struct F32 {
  float v = 0;
  double loaded = 0;
  F32() = default;
  F32(double d) : v(float(d)), loaded(d) {}
  static F32 of(float f) {
    F32 r;
    r.v = f;
    r.loaded = f;
    return r;
  }
};
inline F32 operator+(const F32& a, const F32& b) { return F32::of(a.v + b.v); }
inline F32 operator-(const F32& a, const F32& b) { return F32::of(a.v - b.v); }
inline F32 operator*(const F32& a, const F32& b) { return F32::of(a.v * b.v); }
inline F32 operator/(const F32& a, const F32& b) { return F32::of(a.v / b.v); }
inline F32 operator+(const F32& a, double b) { return F32::of(a.v + float(b)); }
inline F32 operator-(const F32& a, double b) { return F32::of(a.v - float(b)); }
inline F32 operator*(const F32& a, double b) { return F32::of(a.v * float(b)); }
inline F32 operator/(const F32& a, double b) { return F32::of(a.v / float(b)); }
inline F32 operator+(double a, const F32& b) { return F32::of(float(a) + b.v); }
inline F32 operator-(double a, const F32& b) { return F32::of(float(a) - b.v); }
inline F32 operator*(double a, const F32& b) { return F32::of(float(a) * b.v); }
inline F32 operator/(double a, const F32& b) { return F32::of(float(a) / b.v); }
inline F32 operator-(const F32& a) { return F32::of(-a.v); }
inline bool operator<(const F32& a, const F32& b) { return a.v < b.v; }
inline bool operator>(const F32& a, const F32& b) { return a.v > b.v; }
inline bool operator<=(const F32& a, const F32& b) { return a.v <= b.v; }
inline bool operator>=(const F32& a, const F32& b) { return a.v >= b.v; }
inline bool operator!=(const F32& a, const F32& b) { return a.v != b.v; }
inline F32 select(bool m, const F32& a, const F32& b) { return m ? a : b; }
inline F32 sqrt(const F32& a) { return F32::of(std::sqrt(a.v)); }

// [3-10, 3-11] in double from the loaded positions and radii (found by argument-dependent
// lookup in pair_loop and bond_loop, preferred to the template of contact_law.hpp).
inline void ball_ball_geometry(const F32& xa, const F32& ya, const F32& za, const F32& xb,
                               const F32& yb, const F32& zb, const F32& ra, const F32& rb,
                               F32& nx, F32& ny, F32& nz, F32& U, F32& la, F32& lb) {
  double dnx, dny, dnz, dU, dla, dlb;
  kernels::ball_ball_geometry(xa.loaded, ya.loaded, za.loaded, xb.loaded, yb.loaded, zb.loaded,
                              ra.loaded, rb.loaded, dnx, dny, dnz, dU, dla, dlb);
  nx = F32(dnx);
  ny = F32(dny);
  nz = F32(dnz);
  U = F32(dU);
  la = F32(dla);
  lb = F32(dlb);
}

struct FloatLanes {
  static constexpr bool kOnePass = false;  // pair_loop.hpp
  using Real = F32;
  using Index = std::int64_t;
  static constexpr std::size_t size = 1;
  static std::int64_t index(const std::int64_t* p) { return *p; }
  static F32 gather(const double* col, std::int64_t i) { return F32(col[i]); }
  static std::int64_t offsets(std::int64_t i, std::int64_t first) { return i - first; }
  static bool fits(std::int64_t off) { return off == 0; }
  static F32 window(const double* p, std::int64_t) { return F32(*p); }
  static F32 load(const double* p) { return F32(*p); }
  static void store(double* p, const F32& v) { *p = double(v.v); }
  static double sum(const F32& v) { return double(v.v); }
  static void store_flags(std::uint8_t* p, const F32& v) { *p = v.v != 0.0f; }
  template <int Width, bool Stream = false>  // Stream: ignored (plain stores)
  static void store_records(double* rec, const F32* v) {
    for (int j = 0; j < Width; ++j) rec[j] = double(v[j].v);
  }
};

}  // namespace

const KernelSet& float_study_kernels() {
  // The integration, the plane walls and the gather are the scalar reference's, in double.
  static const KernelSet set{"float", 1, &pair_loop<FloatLanes, true>, &pair_loop<FloatLanes, false>,
                             &bond_loop<FloatLanes, true>, &bond_loop<FloatLanes, false>,
                             &bond_loop<FloatLanes, false, false>,
                             scalar_kernels().integrate, scalar_kernels().integrate_norot,
                             scalar_kernels().plane_walls, scalar_kernels().plane_walls_norot,
                             scalar_kernels().gather};
  return set;
}

}  // namespace asperity::kernels
