// Stage 5 of a step: the forces gathered per particle and the free particles moved
// (stages/integrate.cpp).
#pragma once
#include "state.hpp"

namespace asperity::detail {

StageLoop integrate_stage(State& s);

}  // namespace asperity::detail
