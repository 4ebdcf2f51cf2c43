// Stage 2 of a step: ball-ball contact forces (stages/pairs.cpp).
#pragma once
#include "state.hpp"

namespace asperity::detail {

StageLoop pair_stage(State& s);
kernels::PairKernelArgs pair_kernel_args(State& s);  // its kernel's arguments (perf/ reuses them)

}  // namespace asperity::detail
