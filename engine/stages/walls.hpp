// Stage 4 of a step: ball-wall contact forces (stages/walls.cpp).
#pragma once
#include "stages/views.hpp"

namespace asperity::detail {

StageLoop wall_stage(const WallStageView& s);

}  // namespace asperity::detail
