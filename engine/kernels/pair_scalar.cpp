// Scalar reference of the pair kernel: one pair at a time, plain doubles. It is the definition
// the SIMD kernels are tested against, and what a build without SIMD runs.
#include "kernels/gather_loop.hpp"
#include "kernels/kernel_set.hpp"

namespace asperity::kernels {
namespace {

struct ScalarLanes {
  static constexpr bool kOnePass = false;  // pair_loop.hpp
  using Real = double;
  using Index = std::int64_t;
  static constexpr std::size_t size = 1;
  static std::int64_t index(const std::int64_t* p) { return *p; }
  static double gather(const double* col, std::int64_t i) { return col[i]; }
  static double lookup(const double* table, std::int64_t i, std::size_t) { return table[i]; }
  // One lane: the window is the particle itself (a_side.hpp).
  static std::int64_t offsets(std::int64_t i, std::int64_t first) { return i - first; }
  static bool fits(std::int64_t off) { return off == 0; }
  static double window(const double* p, std::int64_t) { return *p; }
  static double load(const double* p) { return *p; }
  static void store_flags(std::uint8_t* p, double v) { *p = v != 0.0; }
  static void store(double* p, double v) { *p = v; }
  static double load_u(const double* p) { return *p; }
  static void store_u(double* p, double v) { *p = v; }
  static std::int64_t index32(const std::int32_t* p) { return *p; }
  static double sum(double v) { return v; }
  template <int Width, bool Stream = false>  // Stream: ignored (plain stores)
  static void store_records(double* rec, const double* v) {
    for (int j = 0; j < Width; ++j) rec[j] = v[j];
  }
  static double iota(double start) { return start; }
  static double lane(double v, std::size_t) { return v; }
  static std::uint64_t bits(bool v) { return v; }  // near_loop.hpp
};

}  // namespace

const KernelSet& scalar_kernels() {
  static const KernelSet set =
      loop_kernels<ScalarLanes>("scalar", &gather_scalar);
  return set;
}

}  // namespace asperity::kernels
