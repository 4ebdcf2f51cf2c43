// The kernel set of one lane type (kernels.hpp, KernelSet): the shared loops instantiated on it.
// The scalar reference (pair_scalar.cpp) and each SIMD translation unit (simd_kernels.cpp) build
// theirs here; only the gather, which has a vector form of its own, is passed in.
#pragma once
#include "kernels/bond_loop.hpp"
#include "kernels/integrate_loop.hpp"
#include "kernels/near_loop.hpp"
#include "kernels/pair_loop.hpp"
#include "kernels/wall_loop.hpp"

namespace asperity::kernels {

template <class Lanes>
KernelSet loop_kernels(const char* name, GatherKernel gather) {
  return {name,
          Lanes::size,
          &pair_loop<Lanes, true>,
          &pair_loop<Lanes, false>,
          &bond_loop<Lanes, true>,
          &bond_loop<Lanes, false>,
          &bond_loop<Lanes, false, false>,
          &bond_loop<Lanes, false, false, false>,
          &integrate_loop<Lanes, true>,
          &integrate_loop<Lanes, false>,
          &plane_wall_loop<Lanes, true>,
          &plane_wall_loop<Lanes, false>,
          gather,
          &near_loop<Lanes>};
}

}  // namespace asperity::kernels
