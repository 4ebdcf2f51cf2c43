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

struct KernelSet {
  const char* name;        // "scalar", "sse4_2", "avx2", "avx512f"
  std::size_t lanes;       // doubles per batch
  PairKernel pair;         // with rotation
  PairKernel pair_norot;   // every particle's rotation locked: w is not read
};

const KernelSet& scalar_kernels();
// The kernel set for `name` ("auto": the best the CPU supports). Throws asperity::Error for an
// unknown or unsupported name, listing the valid ones.
const KernelSet& select_kernels(const std::string& name);

}  // namespace asperity::kernels
