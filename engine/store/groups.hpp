// Rigid groups (PFC clumps, model.md 1): each group's members and motion (Group), and the
// contacts between bodies the servo's stiffness is summed over (ServoContacts).
#pragma once
#include <cstdint>
#include <vector>

#include "asperity/world.hpp"

namespace asperity::detail {

struct Group {
  std::vector<std::int32_t> members;  // current particle indices, moved every step
  std::vector<std::int32_t> inert;    // members moved only when read (see World::set_inert)
  Vec3 inert_shift{0, 0, 0};          // group displacement not yet applied to the inert members
  double inert_mass = 0;
  // A group whose rotation is fixed ("lazy") splits its other members at every neighbour build:
  // `busy` ones have something acting on them (a pair, bond or wall contact, an applied force) and
  // are summed and moved every step; the rest are idle (Caches::idle): their force is zero until
  // the next build, so they are moved lazily like inert ones: a rigid block then costs its
  // interface, not its volume. Groups that may rotate keep every member busy.
  bool lazy = false;
  std::vector<std::int32_t> busy;
  Vec3 idle_shift{0, 0, 0};  // displacement not yet applied to the idle members
  double idle_mass = 0;
  double idle_base = 0;      // bound on the idle members' displacement since the build, before idle_shift
  Vec3 servo_origin{0, 0, 0};         // centre when the motion was set (CNS reference)
  Vec3 servo_integral{0, 0, 0};       // int (F - F_target) dt per servo axis since the motion was set
  double contact_stiffness = 0;       // summed kn of the members' contacts this step (servo gain)
  GroupMotion motion;
  double mass = 0;
  Vec3 centre, velocity, angular_velocity;
  Vec3 applied{0, 0, 0};
  Vec3 force, torque;  // last step: contact + applied on members (torque about the centre)
  Vec3 impulse{0, 0, 0};  // sum of force x dt since the world was made (time averages)
};

// Pairs joining two different bodies (group / group or group / free particle) of the current pair
// list (ascending), for the servo's per-step stiffness; valid while State::rebuilds equals
// pairs_at (a break step's freed pairs are merged into it: insert_pairs). Likewise, per group,
// its ends of the bonds joining two bodies (a joint's platens are tied by a few of its many
// bonds), valid while State::bond_version equals bonds_of (a break step counts its dead bonds
// out: refresh_bond_topology_after_breaks).
struct ServoContacts {
  std::vector<std::uint32_t> pairs;
  std::vector<std::uint32_t> bond_ends;
  std::uint64_t pairs_at = ~std::uint64_t(0);
  std::uint64_t bonds_of = ~std::uint64_t(0);

  // Bond (a, b), if it joins two bodies, counted into bond_ends at each end that is in a group,
  // `by` times (+1 taken, -1 gone).
  template <class Groups>
  void count_bond_ends(const Groups& group, std::int64_t a, std::int64_t b, int by) {
    if (group[a] == group[b]) return;
    for (const std::int64_t i : {a, b})
      if (group[i] >= 0) bond_ends[std::size_t(group[i])] += std::uint32_t(by);
  }
};

}  // namespace asperity::detail
