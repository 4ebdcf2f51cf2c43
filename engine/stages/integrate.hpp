// Stage 5 of a step: the forces gathered per particle and the free particles moved
// (stages/integrate.cpp).
#pragma once
#include "stages/views.hpp"

namespace asperity::detail {

StageLoop integrate_stage(const IntegrateStageView& s);

}  // namespace asperity::detail
