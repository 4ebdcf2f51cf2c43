// Run-time choice of the kernel set: the best instruction set the running CPU supports, so one
// binary runs on any x86-64 and still uses AVX-512 where it exists.
#include <vector>

#include "asperity/error.hpp"
#include "asperity/world.hpp"
#include "kernels/kernels.hpp"

#if ASPERITY_HAVE_SIMD
#include <xsimd/config/xsimd_cpuid.hpp>
#endif

namespace asperity::kernels {

#if ASPERITY_HAVE_SIMD
const KernelSet& kernels_sse4_2();
const KernelSet& kernels_avx2();
const KernelSet& kernels_avx512f();
#endif

namespace {
std::vector<const KernelSet*> supported() {
  std::vector<const KernelSet*> out;
#if ASPERITY_HAVE_SIMD
  const auto cpu = xsimd::available_architectures();
  if (cpu.avx512f) out.push_back(&kernels_avx512f());
  if (cpu.avx2) out.push_back(&kernels_avx2());
  if (cpu.sse4_2) out.push_back(&kernels_sse4_2());
#endif
  out.push_back(&scalar_kernels());
  return out;
}
}  // namespace

const KernelSet& select_kernels(const std::string& name) {
  const auto list = supported();
  if (name == "auto") return *list.front();
  std::string valid = "auto";
  for (const auto* k : list) {
    if (name == k->name) return *k;
    valid += std::string(", ") + k->name;
  }
  throw Error("unknown or unsupported SIMD architecture '" + name + "' (valid on this CPU: " +
              valid + ")");
}

}  // namespace asperity::kernels

namespace asperity {
std::vector<std::string> available_simd_architectures() {
  std::vector<std::string> out;
  for (const auto* k : kernels::supported()) out.emplace_back(k->name);
  return out;
}
}  // namespace asperity
