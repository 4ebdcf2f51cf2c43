// Stage 4 of a step: ball-wall contact forces (stages/walls.cpp).
#pragma once
#include "state.hpp"

namespace asperity::detail {

StageLoop wall_stage(State& s);

}  // namespace asperity::detail
