// Stage 6 of a step: rigid groups (stages/groups.cpp). Their members between steps (the lazy
// moves, the busy / idle split) are bodies/groups.hpp.
#pragma once
#include "stages/views.hpp"

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
GroupStages group_stages(const GroupStageView& s);  // empty stages without groups

}  // namespace asperity::detail
