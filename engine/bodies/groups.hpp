// Rigid groups between steps (bodies/groups.cpp); the step's stage is stages/groups.hpp.
#pragma once
#include "state.hpp"

namespace asperity::detail {

void sync_lazy(State& s);    // bring inert and idle members up to date
void split_idle(State& s);   // busy / idle members of lazy groups
void index_moved(State& s);  // the split's indexes by block and slot, from idle and busy

}  // namespace asperity::detail
