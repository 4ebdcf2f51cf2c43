// Stage `groups`: rigid groups (PFC clumps, model.md 1). Members' forces were summed by the
// gather; here they are reduced to a force and a torque about the centre of mass, each degree of
// freedom is advanced according to its mode (free: leapfrog with local damping; fixed;
// velocity-prescribed), and the members are moved rigidly.
//
// Energy (model.md 8): the agent that holds a fixed or prescribed degree of freedom does the work
// needed to make the group follow its prescription, F_agent = M dV/dt - F; that work is boundary
// work. Gyroscopic terms of free rotation are neglected (quasi-static loading).
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "stages/groups.hpp"

namespace asperity::detail {

namespace {
inline double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// Rotation of r by the rotation vector theta (Rodrigues).
Vec3 rotate(const Vec3& r, const Vec3& theta) {
  const double a = norm(theta);
  if (a == 0) return r;
  const Vec3 k = theta / a;
  const double c = std::cos(a), s = std::sin(a);
  return r * c + cross(k, r) * s + k * (dot(k, r) * (1 - c));
}
}  // namespace

namespace {

// The motion of group gi in this step (stage `motion` of group_stages): its members' force and
// torque summed in member order, each degree of freedom advanced by its mode, the centre moved.
// What its members' moves need, and its terms of the ledgers, go to s.ctx.group_steps[gi].
void advance_group_motion(const GroupStageView& s, std::size_t gi) {
  Group& grp = s.groups[gi];
  GroupStep& out = s.ctx.group_steps[gi];
  out = GroupStep{};
  if (grp.members.empty()) return;
  const ParticleStore& p = s.p;
  const double dt = s.dt;
  const Vec3 g = s.gravity;
  const double alpha = grp.motion.damping >= 0 ? grp.motion.damping : s.local_damping;
  // Idle members of a lazy group carry no force (split_idle): summing and moving the busy ones
  // (the group's slots of moved_particle, in member order) is the whole group.
  Vec3 F = grp.applied, T{0, 0, 0};
  for (std::size_t slot = s.ctx.moved_start[gi]; slot < s.ctx.moved_start[gi + 1]; ++slot) {
    const std::int32_t i = s.ctx.moved_particle[slot];
    const Vec3 f{p.fx[i], p.fy[i], p.fz[i]};
    const Vec3 r = Vec3{p.x[i], p.y[i], p.z[i]} - grp.centre;
    F += f;
    T += Vec3{p.tx[i], p.ty[i], p.tz[i]} + cross(r, f);
  }
  grp.force = F;
  grp.torque = T;
  grp.impulse += F * dt;
  const double M = grp.mass;

  // Translation, per axis.
  double V[3] = {grp.velocity.x, grp.velocity.y, grp.velocity.z};
  const double Fk[3] = {F.x, F.y, F.z}, gk[3] = {g.x, g.y, g.z};
  const double Vp[3] = {grp.motion.velocity.x, grp.motion.velocity.y, grp.motion.velocity.z};
  double Vn[3] = {0, 0, 0};
  double agent_work = 0, damping_work = 0;
  for (int k = 0; k < 3; ++k) {
    switch (grp.motion.translation[k]) {
      case Dof::free: {
        const double fd = -alpha * std::fabs(Fk[k] + M * gk[k]) * sign(V[k]);  // unbalanced
        Vn[k] = V[k] + (Fk[k] + fd) / M * dt + gk[k] * dt;
        damping_work -= fd * 0.5 * (V[k] + Vn[k]) * dt;
        break;
      }
      case Dof::fixed:
      case Dof::velocity:
      case Dof::servo: {
        if (grp.motion.translation[k] == Dof::servo) {
          // model.md 7: v = clamp(G (F - F_target), -vmax, vmax), target moving with CNS;
          // with integral_time Ti > 0, v = G (e + I / Ti), I = int e dt, integrated only while
          // the velocity is not clamped (no wind-up while the platen runs at vmax).
          const Servo& sv = grp.motion.servo[k];
          const double shift = grp.centre[k] - grp.servo_origin[k];
          const double target = sv.target_force + sv.stiffness * shift;
          const double error = Fk[k] - target;
          // Automatic gain: a body out of contact counts as meeting one contact (as in the
          // time-step estimate [3-30]): it approaches at most `relaxation` x (its force error /
          // kn) per step, so the first contact cannot be overshot by more than the target load
          // needs. (kn > 0 and relaxation > 0 are enforced, so the gain is always positive.)
          const double gain =
              sv.gain > 0 ? sv.gain : sv.relaxation / (std::max(grp.contact_stiffness, s.contact.kn) * dt);
          double& integral = grp.servo_integral[k];
          if (sv.integral_time > 0) {
            const double trial = integral + error * dt;
            if (std::fabs(gain * (error + trial / sv.integral_time)) <= sv.max_velocity) integral = trial;
          }
          const double v = gain * (error + (sv.integral_time > 0 ? integral / sv.integral_time : 0.0));
          Vn[k] = std::clamp(v, -sv.max_velocity, sv.max_velocity);
        } else {
          Vn[k] = grp.motion.translation[k] == Dof::fixed ? 0.0 : Vp[k];
        }
        const double agent = M * (Vn[k] - V[k]) / dt - (Fk[k] + M * gk[k]);
        agent_work += agent * 0.5 * (V[k] + Vn[k]) * dt;
        break;
      }
    }
  }
  const Vec3 Vnew{Vn[0], Vn[1], Vn[2]};
  const Vec3 Vmid = (grp.velocity + Vnew) * 0.5;

  // Rotation, all axes together.
  Vec3 W = grp.angular_velocity, Wnew{0, 0, 0};
  if (grp.motion.rotation == Dof::fixed) {
    Wnew = {0, 0, 0};
  } else {
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (std::int32_t i : grp.members) {
      const Eigen::Vector3d r(p.x[i] - grp.centre.x, p.y[i] - grp.centre.y, p.z[i] - grp.centre.z);
      I += p.mass[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose()) +
           p.inertia[i] * Eigen::Matrix3d::Identity();
    }
    if (grp.motion.rotation == Dof::velocity) {
      Wnew = grp.motion.angular_velocity;
      const Eigen::Vector3d dW(Wnew.x - W.x, Wnew.y - W.y, Wnew.z - W.z);
      const Eigen::Vector3d agent = I * dW / dt - Eigen::Vector3d(T.x, T.y, T.z);
      agent_work += Vec3{agent.x(), agent.y(), agent.z()} == Vec3{} ? 0.0
                    : dot(Vec3{agent.x(), agent.y(), agent.z()}, (W + Wnew) * 0.5) * dt;
    } else {
      const Vec3 Td{-alpha * std::fabs(T.x) * sign(W.x), -alpha * std::fabs(T.y) * sign(W.y),
                    -alpha * std::fabs(T.z) * sign(W.z)};
      const Eigen::Vector3d dW = I.ldlt().solve(Eigen::Vector3d(T.x + Td.x, T.y + Td.y, T.z + Td.z)) * dt;
      Wnew = W + Vec3{dW.x(), dW.y(), dW.z()};
      damping_work -= dot(Td, (W + Wnew) * 0.5) * dt;
    }
  }

  // Its terms of the ledgers, added in group order after the region (moves' finish).
  out.moves = true;
  out.boundary = agent_work + dot(grp.applied, Vmid) * dt;
  out.damping = damping_work;
  out.gravity = M * dot(g, Vmid) * dt;
  out.kinetic = 0.5 * (grp.inert_mass + grp.idle_mass) * dot(Vmid, Vmid);

  // What the rigid moves of its members need (stage `moves`).
  out.old_centre = grp.centre;
  grp.centre += Vnew * dt;
  out.centre = grp.centre;
  grp.velocity = Vnew;
  grp.angular_velocity = Wnew;
  out.velocity = Vnew;
  out.angular_velocity = Wnew;
  out.mean_angular_velocity = (Wnew + W) * 0.5;
  out.theta = Wnew * dt;
  out.spins = !(Wnew == Vec3{});
  // Inert members: only the shift is recorded; they are moved when someone reads them.
  grp.inert_shift += Vnew * dt;
  grp.idle_shift += Vnew * dt;
}

// Moves the moved members of particle block blk (stage `moves`) rigidly with their groups and
// keeps each one's kinetic energy for the finish, which sums them in member order, and its
// displacement since the build and whether its position is finite for bookkeep. By particle
// block, so that the thread which gathered a block's particles (and holds their lines) moves them.
void move_members(const GroupStageView& s, std::size_t blk) {
  ParticleStore& p = s.p;
  // A block's slots ascend, and the slots run over the groups in order: the group of a slot is
  // found by walking the groups' slot ranges.
  std::size_t g = 0;
  for (std::int32_t e = s.ctx.block_moved.start[blk]; e < s.ctx.block_moved.start[blk + 1]; ++e) {
    const std::size_t slot = std::size_t(s.ctx.block_moved.entry[e]);
    while (slot >= s.ctx.moved_start[g + 1]) ++g;
    const std::int32_t i = s.ctx.moved_particle[slot];
    const GroupStep& st = s.ctx.group_steps[g];
    Vec3 r = Vec3{p.x[i], p.y[i], p.z[i]} - st.old_centre;
    if (st.spins) r = rotate(r, st.theta);
    const Vec3 x = st.centre + r;
    const Vec3 v = st.velocity + cross(st.angular_velocity, r);
    const Vec3 vmid = (v + Vec3{p.vx[i], p.vy[i], p.vz[i]}) * 0.5;
    const Vec3 wmid = st.mean_angular_velocity;
    double kinetic = 0.5 * p.mass[i] * dot(vmid, vmid);
    // The rotational term is an exact +0 where the group does not turn (adding it changes no bit
    // of the non-negative translational one): its inertia is not read then.
    if (!(wmid == Vec3{})) kinetic += 0.5 * p.inertia[i] * dot(wmid, wmid);
    s.ctx.member_kinetic[slot] = kinetic;
    p.x[i] = x.x; p.y[i] = x.y; p.z[i] = x.z;
    p.vx[i] = v.x; p.vy[i] = v.y; p.vz[i] = v.z;
    p.wx[i] = st.angular_velocity.x; p.wy[i] = st.angular_velocity.y; p.wz[i] = st.angular_velocity.z;
    // For the rebuild criterion and the health check (bookkeep), while the member is at hand.
    const double dx = x.x - p.x0[i], dy = x.y - p.y0[i], dz = x.z - p.z0[i];
    s.ctx.member_disp2[slot] = dx * dx + dy * dy + dz * dz;
    s.ctx.member_finite[slot] = std::isfinite(x.x + x.y + x.z);
  }
}

bool any_servo(const GroupStageView& s) {
  for (const Group& g : s.groups)
    for (Dof d : g.motion.translation)
      if (d == Dof::servo) return true;
  return false;
}

// The servo gain G = relaxation / (K dt) needs the stiffness K the group meets now: computed every
// step from this step's overlaps (a stale K, e.g. from before the platen touched, makes the servo a
// bang-bang controller that rings about the target and creates energy).
// Only the pairs joining two bodies can contribute; their indices are collected once per rebuild.
void update_servo_stiffness(const GroupStageView& s) {
  if (s.groups.empty()) return;
  bool servo = false;
  for (const Group& g : s.groups)
    for (Dof d : g.motion.translation) servo = servo || d == Dof::servo;
  if (!servo) return;
  const ParticleStore& p = s.p;
  if (s.servo.pairs_at != s.rebuilds || s.servo.bond_ends.size() != s.groups.size()) {
    s.servo.pairs.clear();
    for (std::size_t k = 0; k < s.pairs.n; ++k)
      if (p.group[s.pairs.a[k]] != p.group[s.pairs.b[k]]) s.servo.pairs.push_back(std::uint32_t(k));
    s.servo.pairs_at = s.rebuilds;
    s.servo.bonds_of = ~std::uint64_t(0);  // the groups may have changed with the build
  }
  if (s.servo.bonds_of != s.bond_version) {
    s.servo.bond_ends.assign(s.groups.size(), 0);
    for (std::size_t k = 0; k < s.bonds.n; ++k)
      if (!s.bonds.dead(k)) s.servo.count_bond_ends(p.group, s.bonds.a[k], s.bonds.b[k], 1);
    s.servo.bonds_of = s.bond_version;
  }
  std::vector<double> K(s.groups.size(), 0.0);
  auto add = [&](std::int64_t a, std::int64_t b, double k) {
    const int ga = p.group[a], gb = p.group[b];
    if (ga == gb) return;
    if (ga >= 0) K[ga] += k;
    if (gb >= 0) K[gb] += k;
  };
  const double kn = s.contact.kn;
  for (std::uint32_t k : s.servo.pairs)
    if (s.pairs.overlap_at(k) > 0) add(s.pairs.a[k], s.pairs.b[k], kn);
  // The same sums as over every pair and bond: the others (one body) add nothing. Every bond adds
  // the same kn + beam_kn to each group it ties, so a group's sum takes that term once per end it
  // holds, in any order: the same additions, without reading the bonds and groups each step.
  const double kb = kn + s.bonds.material.beam_kn;
  for (std::size_t g = 0; g < s.groups.size(); ++g)
    for (std::uint32_t e = 0; e < s.servo.bond_ends[g]; ++e) K[g] += kb;
  const WallContacts& wc = s.walls.contacts;
  for (std::size_t k = 0; k < wc.n; ++k) {
    const int g = p.group[wc.particle[k]];
    if (g >= 0 && wc.overlap[k] > 0) K[g] += s.walls.walls[wc.wall[k]].material.kn;
  }
  for (std::size_t g = 0; g < s.groups.size(); ++g) s.groups[g].contact_stiffness = K[g];
}

}  // namespace

GroupStages group_stages(const GroupStageView& s) {
  GroupStages st;
  if (s.groups.empty()) return st;
  s.ctx.group_steps.assign(s.groups.size(), GroupStep{});
  s.ctx.member_kinetic.resize(s.ctx.moved_particle.size());
  s.ctx.member_disp2.resize(s.ctx.moved_particle.size());
  s.ctx.member_finite.resize(s.ctx.moved_particle.size());
  if (any_servo(s)) {
    st.servo.blocks = 1;  // reads the force stages' overlaps only: no barrier of its own
    st.servo.run = [s](std::size_t) { update_servo_stiffness(s); };
  }
  st.motion.blocks = s.groups.size();
  st.motion.after_barrier = true;  // every member's force gathered, the servo's stiffness known
  st.motion.run = [s](std::size_t g) { advance_group_motion(s, g); };
  st.moves.blocks = s.ctx.block_moved.start.empty() ? 0 : s.ctx.block_moved.start.size() - 1;
  st.moves.after_barrier = true;  // every group's motion
  st.moves.run = [s](std::size_t blk) { move_members(s, blk); };
  st.moves.finish = [s] {
    // In the order of the serial loop over groups and members these stages replace: per group its
    // ledger terms, its inert and idle members' kinetic energy, then its moved members' (the
    // slots run over the groups in order, each group's members in their order).
    double kinetic = 0;
    std::size_t slot = 0;
    for (std::size_t g = 0; g < s.groups.size(); ++g) {
      const GroupStep& gs = s.ctx.group_steps[g];
      if (!gs.moves) continue;
      if (s.ledger) {
        s.ledger->boundary += gs.boundary;
        s.ledger->damping += gs.damping;
        s.ledger->gravity += gs.gravity;
      }
      kinetic += gs.kinetic;
      const std::size_t end = s.ctx.moved_start[g + 1];
      for (; slot < end; ++slot) kinetic += s.ctx.member_kinetic[slot];
    }
    s.kinetic_at_step = kinetic;  // the free particles' share is added in bookkeeping
  };
  return st;
}


}  // namespace asperity::detail
