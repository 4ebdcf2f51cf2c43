// One step (step.cpp): the stages in order, the time step, the health checks and the energies.
#pragma once
#include <initializer_list>

#include "stages/views.hpp"
#include "state.hpp"

namespace asperity::detail {

void step_once(State& s);
// The loops of several stages in one parallel region, each stage's blocks in order.
void run_stages(State& s, std::initializer_list<StageLoop*> stages);
double estimate_critical_dt(const State& s);
// The deepest contact overlap relative to the radius of the smaller body it joins (a wall counts
// as infinitely large), over touching pairs, wall contacts and bonds; particle -1 and ratio 0
// when nothing overlaps. turning_only: only the contacts with a particle that turns freely, the
// ones whose contact point and lever arm [3-11] enter the motion.
struct OverlapRatio {
  double ratio = 0;
  std::int64_t particle = -1;
};
OverlapRatio deepest_overlap(const State& s, bool turning_only = false);
// The torque particle i's bonds gave it in the last step that the gather left out (records of
// kernels::BondRecord::forces: it does not turn), from the bonds as the step left them; zero
// where the records held it.
Vec3 bond_torque_left_out(const State& s, std::size_t i);
Energies compute_energies(const State& s);
void watch_load(State& s);  // StepContext::load_limit, for automatic threads

// What each stage reads and writes of the State (stages/views.hpp), as the step hands it out.
PairStageView pair_view(State& s);
BondStageView bond_view(State& s);
WallStageView wall_view(State& s);
IntegrateStageView integrate_view(State& s);
GroupStageView group_view(State& s);

}  // namespace asperity::detail
