// Stage 2 of a step: ball-ball contact forces (stages/pairs.cpp).
#pragma once
#include "stages/views.hpp"

namespace asperity::detail {

StageLoop pair_stage(const PairStageView& s);
kernels::PairKernelArgs pair_kernel_args(const PairStageView& s);  // its kernel's arguments (perf/ reuses them)

}  // namespace asperity::detail
