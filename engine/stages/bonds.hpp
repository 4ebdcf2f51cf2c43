// Stage 3 of a step: bond forces and break flags (stages/bonds.cpp); the breaks and the rest of
// the bond list's life are bond_list.hpp.
#pragma once
#include "stages/views.hpp"

namespace asperity::detail {

StageLoop bond_stage(const BondStageView& s);
// Its kernel's arguments (perf/ reuses them).
kernels::BondKernelArgs bond_kernel_args(const BondStageView& s);

}  // namespace asperity::detail
