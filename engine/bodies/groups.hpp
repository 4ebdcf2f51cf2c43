// Stage 6 of a step: rigid groups (bodies/groups.cpp).
#pragma once
#include "state.hpp"

namespace asperity::detail {

// Stage `groups` in three loops that run in the step's parallel region after the gather:
// `servo` (the servo's stiffness, one block, while a servo acts), `motion` (one block per group:
// its force and torque summed in member order, its degrees of freedom advanced) and `moves` (the
// members moved, by particle block, on the thread that gathered the block). The finish of moves
// adds the ledgers and kinetic energy in the order of a serial loop over groups and members, so
// the results are bitwise those of one.
struct GroupStages {
  StageLoop servo, motion, moves;
};
GroupStages group_stages(State& s);     // empty stages without groups
void update_servo_stiffness(State& s);  // every step while a servo acts
void sync_lazy(State& s);               // bring inert and idle members up to date
void split_idle(State& s);              // busy / idle members of lazy groups
void index_moved(State& s);             // the split's indexes by block and slot, from idle and busy

}  // namespace asperity::detail
