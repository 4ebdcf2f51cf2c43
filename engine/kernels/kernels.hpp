// Kernel entry points and their run-time dispatch. A pair kernel processes pairs [begin, end) of
// the pair list (begin and end multiples of kMaxLanes) and returns the slip energy it dissipated.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace asperity::kernels {

struct PairKernelArgs {
  const double* x; const double* y; const double* z;
  const double* vx; const double* vy; const double* vz;
  const double* wx; const double* wy; const double* wz;
  const double* radius;
  const std::int64_t* a; const std::int64_t* b;
  double* nx; double* ny; double* nz;
  double* fsx; double* fsy; double* fsz;
  double* fn; double* overlap;
  double kn, ks, friction, dt;
};

using PairKernel = double (*)(const PairKernelArgs&, std::size_t begin, std::size_t end);

// Bond kernel: bonds [begin, end) of the bond list; sets broken[k] = 1 where the elliptic
// criterion is met (only when strength > 0). Returns the number of bonds broken.
struct BondKernelArgs {
  const double* x; const double* y; const double* z;
  const double* vx; const double* vy; const double* vz;
  const double* wx; const double* wy; const double* wz;
  const double* radius;
  const std::int64_t* a; const std::int64_t* b;
  const double* beam_radius;
  double* nx; double* ny; double* nz;
  double* fsx; double* fsy; double* fsz; double* fn; double* overlap;
  double* fbn; double* fbsx; double* fbsy; double* fbsz;
  double* mbn; double* mbsx; double* mbsy; double* mbsz;
  double* broken;
  double kn, ks, beam_kn, beam_ks, dt, strength;
};

using BondKernel = double (*)(const BondKernelArgs&, std::size_t begin, std::size_t end);

struct KernelSet {
  const char* name;        // "scalar", "sse4_2", "avx2", "avx512f"
  std::size_t lanes;       // doubles per batch
  PairKernel pair;         // with rotation
  PairKernel pair_norot;   // every particle's rotation locked: w is not read
  BondKernel bond;
  BondKernel bond_norot;
};

const KernelSet& scalar_kernels();
// The kernel set for `name` ("auto": the best the CPU supports). Throws asperity::Error for an
// unknown or unsupported name, listing the valid ones.
const KernelSet& select_kernels(const std::string& name);

}  // namespace asperity::kernels
