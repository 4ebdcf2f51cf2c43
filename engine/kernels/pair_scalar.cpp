// Scalar reference of the pair kernel: one pair at a time, plain doubles. It is the definition
// the SIMD kernels are tested against, and what a build without SIMD runs.
#include "kernels/bond_loop.hpp"
#include "kernels/gather_loop.hpp"
#include "kernels/integrate_loop.hpp"
#include "kernels/pair_loop.hpp"
#include "kernels/wall_loop.hpp"

namespace asperity::kernels {
namespace {

struct ScalarLanes {
  using Real = double;
  using Index = std::int64_t;
  static constexpr std::size_t size = 1;
  static std::int64_t index(const std::int64_t* p) { return *p; }
  static double gather(const double* col, std::int64_t i) { return col[i]; }
  // One lane: the window is the particle itself (a_side.hpp).
  static std::int64_t offsets(std::int64_t i, std::int64_t first) { return i - first; }
  static bool fits(std::int64_t off) { return off == 0; }
  static double window(const double* p, std::int64_t) { return *p; }
  static double load(const double* p) { return *p; }
  static void store(double* p, double v) { *p = v; }
  static double load_u(const double* p) { return *p; }
  static void store_u(double* p, double v) { *p = v; }
  static std::int64_t index32(const std::int32_t* p) { return *p; }
  static double sum(double v) { return v; }
  template <int Width>
  static void store_records(double* rec, const double* v) {
    for (int j = 0; j < Width; ++j) rec[j] = v[j];
  }
  static double iota(double start) { return start; }
  static double lane(double v, std::size_t) { return v; }
};

double pair_rot(const PairKernelArgs& k, std::size_t b, std::size_t e) {
  return pair_loop<ScalarLanes, true>(k, b, e);
}
double pair_norot(const PairKernelArgs& k, std::size_t b, std::size_t e) {
  return pair_loop<ScalarLanes, false>(k, b, e);
}
double bond_rot(const BondKernelArgs& k, std::size_t b, std::size_t e) {
  return bond_loop<ScalarLanes, true>(k, b, e);
}
double bond_norot(const BondKernelArgs& k, std::size_t b, std::size_t e) {
  return bond_loop<ScalarLanes, false>(k, b, e);
}

void integrate_rot(const IntegrateArgs& k, std::size_t b, std::size_t e, IntegrateSums& out) {
  integrate_loop<ScalarLanes, true>(k, b, e, out);
}
void integrate_norot(const IntegrateArgs& k, std::size_t b, std::size_t e, IntegrateSums& out) {
  integrate_loop<ScalarLanes, false>(k, b, e, out);
}

void plane_walls_rot(const PlaneWallArgs& k, std::size_t b, std::size_t e) {
  plane_wall_loop<ScalarLanes, true>(k, b, e);
}
void plane_walls_norot(const PlaneWallArgs& k, std::size_t b, std::size_t e) {
  plane_wall_loop<ScalarLanes, false>(k, b, e);
}

void gather_pairs(const GatherArgs& g, std::size_t b, std::size_t e) {
  gather_scalar<false>(g, b, e);
}
void gather_bonds(const GatherArgs& g, std::size_t b, std::size_t e) {
  gather_scalar<true>(g, b, e);
}

}  // namespace

const KernelSet& scalar_kernels() {
  static const KernelSet set{"scalar", 1, &pair_rot, &pair_norot, &bond_rot, &bond_norot,
                             &integrate_rot, &integrate_norot, &plane_walls_rot,
                             &plane_walls_norot, &gather_pairs, &gather_bonds};
  return set;
}

}  // namespace asperity::kernels
