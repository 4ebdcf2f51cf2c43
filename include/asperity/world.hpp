// The public face of the engine: a World holds particles, walls and rigid groups and advances
// them in time (model.md sections 1-4, 6, 8). Tests, benchmarks and the Lua layer use only this
// header (plus vec3.hpp / error.hpp); the stores and kernels behind it live in engine/.
//
// Identity: every particle gets a stable id (0, 1, 2, ... in order of creation). Internally the
// particles are reordered by cell for cache locality (a Morton curve; the raster order of the
// cells in large scenes), so array positions change; every function here speaks in stable ids.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <optional>
#include <vector>

#include "asperity/error.hpp"
#include "asperity/fields.hpp"
#include "asperity/materials.hpp"
#include "asperity/vec3.hpp"

namespace asperity {

namespace detail {
struct State;
}

// Bounds of the values a World accepts (an Error names the value outside them). Wide enough for
// any scene of this engine (mm particles in a cm specimen, or metre-sized test bodies), narrow
// enough that what the step derives from them stays finite: mass rho 4/3 pi R^3 and inertia
// 2/5 m R^2 (model.md 2) neither overflow nor underflow, and the cell grids' extents
// (differences of coordinates) cannot overflow.
inline constexpr double kMinDensity = 1e-6, kMaxDensity = 1e9;     // kg/m^3
inline constexpr double kMinRadius = 1e-6, kMaxRadius = 1e3;       // m
inline constexpr double kMaxCoordinate = 1e9;                      // m, |x|, |y|, |z|
inline constexpr double kMinDt = 1e-15;                            // s, a fixed time step
inline constexpr double kMinDtSafety = 1e-3;                       // dt / critical estimate
inline constexpr int kMaxThreads = 1024;                           // OpenMP threads asked for

// What a World is made with. Each field is described (Lua name, checkpoint name, accepted values,
// meaning) once, in for_each_setting below.
struct WorldSettings {
  ContactMaterial contact;
  double density = 2500.0;
  double local_damping = 0.7;
  Vec3 gravity{0, 0, 0};
  bool rotation = true;
  double skin = 0.0;
  double dt = 0.0;
  double dt_safety = 0.8;
  bool allow_dt_above_estimate = false;
  int dt_interval = 100;
  int threads = 0;
  std::string simd = "auto";
  bool track_energy = true;
  int reorder_interval = 10;
  bool lock_bonded_rotation = true;
  int rotation_lock_bonds = 1;
  bool rotation_lock_beams = false;
  double overlap_limit = 1.0;
};

// visit(field, member) for each field of WorldSettings, in checkpoint order. The World checks
// every value against its field, the Lua binding reads and pushes them by name, a checkpoint
// saves the stored ones (threads and simd are the loader's choice: results do not depend on
// them) and help() lists them with their defaults.
template <class Settings, class Visit>
void for_each_setting(Settings& s, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(Field{"material", "contact", 1, {}, "ball-ball contacts {kn = N/m, ks = N/m, friction} (model.md 4)"},
        s.contact);
  visit(Field{"density", "density", 1, {kMinDensity, kMaxDensity, false, false, nullptr, "kg/m^3"},
              "default density of add_particle, kg/m^3"},
        s.density);
  visit(Field{"damping", "local_damping", 1, {0, 1, false, true}, "local (Cundall) damping alpha [3-28]"},
        s.local_damping);
  visit(Field{"gravity", "gravity", 1, {}, "acceleration of gravity, m/s^2"}, s.gravity);
  visit(Field{"rotation", "rotation", 1, {}, "false: no particle rotates (and none pays for rotation)"},
        s.rotation);
  visit(Field{"skin", "skin", 1, {0, kMaxCoordinate, true, false, "automatic", "m"},
              "Verlet skin; automatic: 0.4 x the mean radius at the first build"},
        s.skin);
  visit(Field{"dt", "dt", 1, {kMinDt, inf, false, true, "automatic", "s"},
              "time step; automatic: dt_safety x the critical estimate [3-30..3-32]"},
        s.dt);
  visit(Field{"dt_safety", "dt_safety", 1, {kMinDtSafety, 2}, "automatic dt / critical estimate"},
        s.dt_safety);
  visit(Field{"allow_dt_above_estimate", "allow_dt_above_estimate", 1, {},
              "a fixed dt above the critical estimate is an error unless set"},
        s.allow_dt_above_estimate);
  visit(Field{"dt_interval", "dt_interval", 1, {1, 1e9},
              "steps between critical-step estimates (also at each neighbour build)"},
        s.dt_interval);
  visit(Field{"threads", nullptr, 1, {1, kMaxThreads, false, false, "automatic"},
              "OpenMP threads; automatic: from the pairs and bonds, up to the cores that other "
              "processes leave free"},
        s.threads);
  visit(Field{"simd", nullptr, 1, {},
              "\"auto\", \"scalar\", \"sse4_2\", \"avx2\", \"avx512f\" (those this CPU runs)"},
        s.simd);
  visit(Field{"track_energy", "track_energy", 1, {},
              "friction, damping and boundary work ledgers (model.md 8)"},
        s.track_energy);
  visit(Field{"reorder_interval", "reorder_interval", 1, {0, 1e9},
              "neighbour builds between reorders by cell; 0: never"},
        s.reorder_interval);
  visit(Field{"lock_bonded_rotation", "lock_bonded_rotation", 1, {},
              "a particle holding an intact bond does not rotate (model.md 2)"},
        s.lock_bonded_rotation);
  visit(Field{"rotation_lock_bonds", "rotation_lock_bonds", 6, {1, 1e9},
              "a bonded particle none of whose bonds broke is locked; a damaged one while it still "
              "holds at least this many intact bonds"},
        s.rotation_lock_bonds);
  visit(Field{"rotation_lock_beams", "rotation_lock_beams", 12, {},
              "true: only bonds whose parallel bond holds lock rotation (model.md 5's alternative); "
              "false: a bond either part of which holds"},
        s.rotation_lock_beams);
  visit(Field{"overlap_limit", "overlap_limit", 8, {0, 2, true, true},
              "health: the deepest contact or bond overlap allowed, in radii of its smaller body "
              "(a rigid block's contacts may pass deeper than 1)"},
        s.overlap_limit);
}

// How a rigid group's degree of freedom moves (model.md 1, 7).
enum class Dof : std::uint8_t { free, fixed, velocity, servo };

// Force control of one translational degree of freedom (model.md 7): each step the axis moves at
// v = clamp(G (F - F_target), -max_velocity, max_velocity), where F is the force the particles
// exert on the group along the axis. With stiffness > 0 (constant normal stiffness, CNS) the
// target follows the displacement since the servo was engaged: F_target = target_force +
// stiffness * displacement (setting the motion again with the same target, stiffness and integral
// time keeps that origin and the integral, so the other axes can change on the fly). Sign convention: a top platen pressing down feels F > 0, so its
// target is positive; a bottom platen's is negative.
struct Servo {
  double target_force = 0;    // N
  double stiffness = 0;       // N/m; 0: constant normal load (CNL)
  double gain = 0;            // m/s per N; 0: automatic, relaxation / (K dt) with K the summed
                              // stiffness of the group's contacts this step (at least one kn)
  // Fraction of the force error corrected per step (automatic gain): the joint's closure and shear
  // hold their target within 1 % at 0.4 (docs/model.md 7); at 1 a step would cancel the error
  // that the contacts' own response also corrects, and the platen rings.
  double relaxation = 0.4;
  double max_velocity = 1e-3; // m/s
  double integral_time = 0;   // s; > 0 adds integral action, v = G (e + (1/Ti) int e dt): a P servo
                              // lags by v/G whenever the specimen dilates at a steady rate
};

// visit(field, member) for each field of a servo (checked when a motion is set, read and pushed by
// the Lua binding, saved by a checkpoint).
template <class S, class Visit>
  requires std::is_same_v<std::remove_const_t<S>, Servo>
void for_each_field(S& s, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(Field{"target_force", "target_force", 1, {-inf, inf, true, true, nullptr, "N"},
              "the particles' force on the group along the axis (a top platen pressing down: > 0)"},
        s.target_force);
  visit(Field{"stiffness", "stiffness", 1, {0, inf, false, true, nullptr, "N/m"},
              "constant normal stiffness: the target grows by stiffness x displacement; 0: constant load"},
        s.stiffness);
  visit(Field{"gain", "gain", 1, {0, inf, false, true}, "G, m/s per N; 0: automatic, relaxation / (K dt)"},
        s.gain);
  visit(Field{"relaxation", "relaxation", 1, {0, 1, true, false},
              "fraction of the force error corrected per step (automatic gain)"},
        s.relaxation);
  visit(Field{"max_velocity", "max_velocity", 1, {0, inf, true, true, nullptr, "m/s"}, "bound on the axis's speed"},
        s.max_velocity);
  visit(Field{"integral_time", "integral_time", 2, {0, inf, false, true, nullptr, "s"},
              "> 0 adds integral action (no lag while the specimen dilates); 0: proportional only"},
        s.integral_time);
}

struct GroupMotion {
  std::array<Dof, 3> translation{Dof::free, Dof::free, Dof::free};
  Vec3 velocity{0, 0, 0};          // used on the axes whose mode is Dof::velocity
  std::array<Servo, 3> servo{};    // used on the axes whose mode is Dof::servo
  Dof rotation = Dof::fixed;       // all three rotational axes together (the thesis locks them)
  Vec3 angular_velocity{0, 0, 0};  // used when rotation == Dof::velocity
  // Local damping of the free axes; < 0: the world's. A dead-load platen wants 0: damping by
  // |unbalanced force| pushes back harder while it rises than while it sinks, so the load it
  // transmits is biased by alpha times the mean magnitude of the force noise.
  double damping = -1;
};

// visit(field, member) for each field of a group motion: checked when a motion is set, pushed to
// Lua, saved by a checkpoint, listed by help(). The modes (translation per axis, rotation) are
// kept together in a checkpoint's `modes` column, hence not `stored` here; the rules between
// fields (a servo only on servo axes, no servo rotation; in Lua, a velocity alone sets the
// velocity mode) are written where they apply.
template <class M, class Visit>
  requires std::is_same_v<std::remove_const_t<M>, GroupMotion>
void for_each_field(M& m, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(Field{"translation", nullptr, 1, {}, "per axis: free, fixed, velocity (prescribed) or servo (force control)"},
        m.translation);
  visit(Field{"velocity", "motion_velocity", 1, {}, "m/s, on the velocity axes"}, m.velocity);
  visit(Field{"servo", "servo", 1, {}, "per axis, used on the servo axes (fields below)"}, m.servo);
  visit(Field{"rotation", nullptr, 1, {}, "the three rotational axes together: fixed, free or velocity"},
        m.rotation);
  visit(Field{"angular_velocity", "motion_angular_velocity", 1, {}, "rad/s, when rotation is velocity"},
        m.angular_velocity);
  visit(Field{"damping", "damping", 2, {-inf, 1, true, true},
              "local damping of the free axes; negative: the world's (0 for a dead-load platen)"},
        m.damping);
}

struct ContactInfo {  // one ball-ball contact (touching pair), for inspection and output
  std::int64_t id_a, id_b;
  Vec3 normal;         // unit, from a to b
  Vec3 point;          // contact point [3-11]
  double overlap;      // U > 0
  double normal_force; // Fn >= 0, acting on b along normal
  Vec3 shear_force;    // Fs on b
};

// Contacts between particles of two tags (e.g. the two halves of a joint), summed.
struct ContactSummary {
  std::size_t count = 0;      // touching ball-ball contacts between the tags
  double area = 0;            // sum of pi a^2, a^2 = Rm U - U^2/4 [4-1], m^2
  Vec3 force{0, 0, 0};        // total force on the tag_b particles from the tag_a particles
  std::size_t flagged_count = 0;  // of those, contacts with a particle carrying flag_mask
  Vec3 flagged_force{0, 0, 0};
};

struct BondInfo {  // one bond of which some part holds, for inspection and output
  std::int64_t id_a, id_b;    // id_a < id_b; forces act on b, their negatives on a
  Vec3 normal;                // unit, from a to b
  Vec3 point;                 // contact point
  double gap;                 // -U: > 0 when stretched
  double beam_radius;         // Rb
  double normal_force;        // contact bond + parallel bond, > 0 in compression
  Vec3 shear_force;           // contact bond + parallel bond
  double twisting_moment;     // Mbn (along the normal)
  Vec3 bending_moment;        // Mbs
  double sigma, tau;          // periphery stresses [3-27], tension positive, Pa
  bool beam = true;           // the parallel bond holds (else its forces and moments are 0)
  bool contact_bond = true;   // the contact bond holds (else the contact springs are an
                              // ordinary contact: no tension, Coulomb slip)
};

struct BreakEvent {  // model.md 5: every break
  std::uint64_t step;
  double time;
  Vec3 position;              // contact point
  std::int64_t id_a, id_b;
  // Which stress was nearest its own failure value (beam: st in tension, 10 st in compression,
  // 5 st in shear; contact bond: tension where its tensile force reached c st A, else shear).
  enum class Mode : std::uint8_t { tension, compression, shear } mode;
  // What broke: the parallel bond (the thesis's "broken bonds"; with contact_strength 0 the
  // contact bond goes with it) or the contact bond on its own.
  enum class Kind : std::uint8_t { beam, contact_bond } kind = Kind::beam;
  double sigma, tau;          // at the break (contact bond: -Fn / A and |Fs| / A)
  double released_energy;     // strain energy of the part that was not kept by a contact, J
};

// The fields of a contact's, a bond's and a break's row, by the names users read them under
// (world:contacts(), world:bonds(), world:break_events() in Lua), in one table each: the Lua
// binding writes its rows from these, so a new field is declared in its struct, listed here and
// filled where the row is made. std::int64_t fields are particle ids (Lua counts them from 1).
template <class Row, class Visit>
  requires std::is_same_v<std::remove_const_t<Row>, ContactInfo>
void for_each_info(Row& c, Visit&& visit) {
  visit("a", c.id_a);
  visit("b", c.id_b);
  visit("normal", c.normal);
  visit("point", c.point);
  visit("overlap", c.overlap);
  visit("normal_force", c.normal_force);
  visit("shear_force", c.shear_force);
}
template <class Row, class Visit>
  requires std::is_same_v<std::remove_const_t<Row>, BondInfo>
void for_each_info(Row& b, Visit&& visit) {
  visit("a", b.id_a);
  visit("b", b.id_b);
  visit("normal", b.normal);
  visit("point", b.point);
  visit("gap", b.gap);
  visit("beam_radius", b.beam_radius);
  visit("normal_force", b.normal_force);
  visit("shear_force", b.shear_force);
  visit("twisting_moment", b.twisting_moment);
  visit("bending_moment", b.bending_moment);
  visit("sigma", b.sigma);
  visit("tau", b.tau);
  visit("beam", b.beam);
  visit("contact_bond", b.contact_bond);
}
template <class Row, class Visit>
  requires std::is_same_v<std::remove_const_t<Row>, BreakEvent>
void for_each_info(Row& e, Visit&& visit) {
  visit("step", e.step);
  visit("time", e.time);
  visit("position", e.position);
  visit("a", e.id_a);
  visit("b", e.id_b);
  visit("mode", e.mode);
  visit("kind", e.kind);
  visit("sigma", e.sigma);
  visit("tau", e.tau);
  visit("released_energy", e.released_energy);
}
inline const char* name_of(BreakEvent::Mode m) {
  switch (m) {
    case BreakEvent::Mode::tension: return "tension";
    case BreakEvent::Mode::compression: return "compression";
    case BreakEvent::Mode::shear: return "shear";
  }
  return "?";
}
inline const char* name_of(BreakEvent::Kind k) { return k == BreakEvent::Kind::beam ? "beam" : "contact_bond"; }

struct Energies {            // model.md 8; all in J
  double kinetic = 0;        // translational + rotational
  double strain = 0;         // stored in the contact springs and bonds
  double friction = 0;       // dissipated by Coulomb slip (cumulative)
  double damping = 0;        // dissipated by local damping (cumulative)
  double boundary_work = 0;  // done on the particles by walls, velocity-prescribed groups and
                             // applied external forces (cumulative)
  double gravity_work = 0;   // done by gravity (cumulative)
  double released = 0;       // strain energy released by bond breaks (cumulative)
  // Input work minus what is stored and dissipated (zero for a perfect balance).
  double balance_error(const Energies& initial) const;
};

struct StepStats {
  std::uint64_t rebuilds = 0;  // neighbour-list rebuilds so far
  std::uint64_t reorders = 0;  // reorders by cell so far
  std::size_t pairs = 0;       // pairs in the neighbour list (touching or not)
  std::size_t contacts = 0;    // touching ball-ball pairs
  std::size_t wall_contacts = 0;
  // Bonds inside a rigid group that does not turn: they cannot deform and their forces cancel
  // within the body, so the step leaves them out (they still count in bond_count and bonds()).
  std::size_t frozen_bonds = 0;
  int threads = 1;                 // threads the next step runs on
  double busy_elsewhere = -1;      // cores other processes kept busy lately (automatic threads
                                   // only; -1: not measured), which the automatic count leaves
};

// A run of many steps with stop conditions (World::run).
struct RunPlan {
  std::uint64_t steps = 0;         // at most this many; 0: no limit (a stop condition is needed)
  bool until_equilibrium = false;  // stop once unbalanced_force_ratio() <= ratio
  double ratio = 1e-4;
  std::uint64_t every = 100;       // steps between checks: the callback, then the stop condition
  std::function<void()> callback;
  std::function<bool()> stop_when;  // true ends the run
  // An outside request to stop, polled after every chunk of steps (e.g. a Ctrl-C that landed
  // between two chunks); request_stop() ends a chunk early, which also ends the run.
  std::function<bool()> interrupted;
  // After every chunk (chunks are sized to take about 50 ms, cut at the checks): the steps done
  // and the last equilibrium ratio (NaN before the first check). For progress reports.
  std::function<void(std::uint64_t steps, double ratio)> on_chunk;
  // Every `sample_every` steps of the run (0: never): a hook that only reads the world, such as a
  // series of energies (World::energies, which moves nothing). Its own cadence, so a fine
  // series does not make the callback and the stop condition run as often.
  std::uint64_t sample_every = 0;
  std::function<void()> sample;
  // Steps of this run done before (a run resumed from a checkpoint): the step limit, the checks'
  // and the samples' cadences count on from there, so the resumed run calls its hooks at the
  // steps the uninterrupted one would have. RunResult::steps includes them.
  std::uint64_t steps_done = 0;
};

struct RunResult {
  enum class End { steps, equilibrium, stop_when, interrupted };
  std::uint64_t steps = 0;
  End end = End::steps;
  double ratio = std::numeric_limits<double>::quiet_NaN();  // the last equilibrium check's
};

class World {
 public:
  explicit World(WorldSettings settings = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const WorldSettings& settings() const;

  // --- particles -------------------------------------------------------------------------
  // Returns the new particle's stable id. density <= 0 means the world's default.
  std::int64_t add_particle(Vec3 position, double radius, double density = 0.0);
  // Bulk: positions as x0,y0,z0,x1,... and one radius each; returns the first id (ids are
  // consecutive).
  std::int64_t add_particles(std::span<const double> xyz, std::span<const double> radii,
                             double density = 0.0);
  std::size_t particle_count() const;

  Vec3 position(std::int64_t id) const;
  Vec3 velocity(std::int64_t id) const;          // at the last half step (leapfrog)
  Vec3 angular_velocity(std::int64_t id) const;
  Vec3 force(std::int64_t id) const;             // contact + applied force of the last step
  // Torque of the last step. On a particle that does not turn, its bonds' share is computed when
  // asked (the step leaves it out: kernels::BondRecord), from the bonds as the step left them: a
  // bond that broke in that step no longer counts.
  Vec3 torque(std::int64_t id) const;
  double radius(std::int64_t id) const;
  double mass(std::int64_t id) const;
  double density(std::int64_t id) const;
  int group_of(std::int64_t id) const;           // -1: not in a group

  void set_position(std::int64_t id, Vec3 x);
  void set_velocity(std::int64_t id, Vec3 v);
  void set_angular_velocity(std::int64_t id, Vec3 w);
  void set_radius(std::int64_t id, double r);    // keeps density: mass and inertia follow
  // Mass and inertia follow (its rigid group's too). A quasi-static process may weigh its
  // lightest particles more, which raises the critical time step [3-30] (genesis mass floor).
  void set_density(std::int64_t id, double rho);
  void set_applied_force(std::int64_t id, Vec3 f);  // constant external force, until reset
  void set_rotation_locked(std::int64_t id, bool locked);
  // Multiply every radius by `factor` (radius expansion packing); masses follow.
  void scale_radii(double factor);

  // Bulk reads in id order: 3 values per particle for vectors.
  std::vector<double> positions() const;
  std::vector<double> velocities() const;
  std::vector<double> forces() const;
  std::vector<double> radii() const;

  // --- walls -----------------------------------------------------------------------------
  // An infinite plane through `point`; `normal` points to the side where particles live.
  int add_plane(Vec3 point, Vec3 normal, ContactMaterial material = {});
  // A triangle mesh (two-sided). Triangles are binned so that the cost of a step stays
  // proportional to the particles near the mesh, not to the number of triangles.
  int add_mesh(std::span<const Vec3> vertices, std::span<const std::array<int, 3>> triangles,
               ContactMaterial material = {});
  void set_wall_velocity(int wall, Vec3 v);   // prescribed translation
  Vec3 wall_velocity(int wall) const;
  Vec3 wall_displacement(int wall) const;     // since creation
  Vec3 wall_force(int wall) const;            // force of the particles on the wall, last step
  void remove_wall(int wall);                 // its contacts vanish; the index stays unused
  std::size_t wall_count() const;             // including removed ones

  // --- rigid groups ----------------------------------------------------------------------
  // The particles move as one rigid body; contacts between members are never computed. A
  // particle belongs to at most one group.
  int add_group(std::span<const std::int64_t> ids, GroupMotion motion = {});
  void set_group_motion(int group, const GroupMotion& motion);
  const GroupMotion& group_motion(int group) const;
  void set_group_applied_force(int group, Vec3 f);
  Vec3 group_force(int group) const;       // sum of contact + applied forces on members, last step
  // Sum of group_force x dt over the steps since the world was made (checkpointed since version 10;
  // 0 when an older checkpoint is loaded): the mean force over an interval is the change of the impulse over the change of time(), what
  // a load cell with a low-pass filter reads, without sampling every step.
  Vec3 group_impulse(int group) const;
  Vec3 group_torque(int group) const;      // about the centre of mass
  Vec3 group_position(int group) const;    // centre of mass
  Vec3 group_velocity(int group) const;
  double group_mass(int group) const;
  std::vector<std::int64_t> group_members(int group) const;
  std::size_t group_count() const;
  // Members of a translating group (rotation fixed) that can never touch anything (the interior
  // of a rigid half): left out of the neighbour search and not moved every step; their positions
  // follow the group when read. The cost of a rigid body then scales with its surface.
  void set_inert(std::span<const std::int64_t> ids, bool inert = true);
  std::size_t inert_count() const;

  // --- labels --------------------------------------------------------------------------------
  // A tag (integer label, default 0) and flag bits (default 0) per particle, for measurements.
  void set_tag(std::span<const std::int64_t> ids, int tag);
  int tag(std::int64_t id) const;
  void set_flags(std::span<const std::int64_t> ids, std::uint8_t flags);
  std::uint8_t flags(std::int64_t id) const;
  ContactSummary contact_summary(int tag_a, int tag_b, std::uint8_t flag_mask = 0) const;
  // Mean stress of the particles of one tag from their touching ball-ball contacts (Love-Weber):
  // sum Fn d / (3 volume), d the distance of the two centres; compression positive, Pa. And its
  // affine stiffness against a common radius factor f: dp/df = sum kn (Ra + Rb) d / (3 volume).
  struct ContactStress {
    double stress = 0, stiffness = 0;
    std::size_t contacts = 0;
  };
  ContactStress contact_stress(int tag, double volume) const;

  // --- bonds (model.md 5) ----------------------------------------------------------------
  // Bond every pair whose gap d - Ra - Rb <= tolerance (tolerance < 0: 1e-3 x mean radius), at
  // the current configuration; existing contact forces are kept. With `ids`, only pairs of two
  // listed particles. Pairs already bonded and members of one rigid group are skipped.
  // Returns the number of bonds installed.
  // stress_free: instead, each new contact bond is unloaded at its current overlap (its rest
  // overlap: Fn = kn (U - rest), shear force 0), and a contact it leaves behind when it breaks
  // keeps that rest overlap until the pair separates. Not model.md 5's rule: it removes the
  // stresses a jammed packing would lock into the bonds (scripts/README.md, "The REV").
  std::size_t install_bonds(const BondMaterial& material, double tolerance = -1,
                            std::span<const std::int64_t> ids = {}, bool stress_free = false);
  std::size_t bond_count() const;                   // parallel bonds that hold
  // Change the strength of every bond (e.g. unbreakable while a specimen is prepared, then the
  // calibrated strength for the fracture model), and, where given, the contact bond's strength
  // factors c and cs and its friction mu_b (BondMaterial). Stiffness and
  // stored forces are unchanged.
  void set_bond_strength(double tensile_strength, bool breakable,
                         std::optional<double> contact_strength = std::nullopt,
                         std::optional<double> contact_shear_strength = std::nullopt,
                         std::optional<double> contact_bond_friction = std::nullopt);
  void remove_bonds();                              // all of them (no events, no energy booked)
  std::vector<BondInfo> bonds() const;
  const std::vector<BreakEvent>& break_events() const;
  // Sigma and tau [3-27] of every intact bond, and the elliptic criterion's value (>= 1: fails).
  static double bond_criterion(double sigma, double tau, double tensile_strength);

  // --- running ---------------------------------------------------------------------------
  // Advance n steps. Returns the number of steps done: fewer than n only if request_stop() was
  // called (e.g. from a SIGINT handler). Throws HealthError when the run goes wrong.
  std::uint64_t cycle(std::uint64_t n);
  // Steps until the plan's limit or stop condition, or an interruption. The hooks may throw: the
  // run then ends where it was, the world intact. A stop request ends only the run it reaches.
  RunResult run(const RunPlan& plan);
  void request_stop();                    // async-signal-safe
  double dt() const;                      // the step in use
  void set_dt(double dt);                 // fix it (0: back to automatic)
  void set_dt_safety(double f);           // automatic dt = f x estimate (0 < f <= 2)
  void set_skin(double skin);             // Verlet skin, m (0: automatic); the list is rebuilt
  void set_overlap_limit(double r);       // health check's deepest overlap / smaller radius, (0, 2)
  // The rotation lock's count rule (WorldSettings::rotation_lock_bonds; 1: the thesis's rule, a
  // particle holding a bond does not rotate), applied at once.
  void set_rotation_lock_bonds(double k);
  // Which bonds the lock counts (WorldSettings::rotation_lock_beams), applied at once.
  void set_rotation_lock_beams(bool beams_only);
  void set_friction(double mu);           // ball-ball Coulomb coefficient from now on (>= 0)
  void set_damping(double alpha);         // local damping [3-28] from the next step on, [0, 1)
  double critical_dt();                   // estimate now [3-30..3-32], without safety factor
  std::uint64_t step_count() const;
  double time() const;
  void set_threads(int threads);
  std::string simd_architecture() const;  // what the kernels use: "avx512f", ..., "scalar"
  StepStats stats() const;
  void rebuild_neighbors();               // force a rebuild now (history carried)

  // --- measurements ----------------------------------------------------------------------
  Energies energies() const;              // kinetic and strain computed now; ledgers cumulative
  // PFC's equilibrium ratio: mean |unbalanced force| over the particles outside rigid groups (inert
  // ones are in groups) / mean normal force of touching contacts, wall contacts and intact bonds
  // (|contact bond + parallel bond|); 0 when no force acts at all, infinite when forces act but
  // nothing carries any.
  double unbalanced_force_ratio() const;
  std::vector<ContactInfo> contacts() const;  // touching ball-ball pairs
  std::size_t contact_count() const;
  // The deepest overlap of a touching pair, wall contact or bond over the radius of the smaller
  // body (a wall's contact: the particle's); 0 when nothing overlaps. A step stops with a
  // HealthError past 1; well before that the soft contacts of model.md 9 are soft for the load.
  // turning_only: only the contacts with a particle that turns freely (not rotation-locked, not
  // inert, not in a group of fixed rotation): where the contact point and lever arm [3-11] enter
  // the motion. Elsewhere a deep overlap leaves the linear law's forces as they are.
  double max_overlap_ratio(bool turning_only = false) const;

  // --- checkpoints ---------------------------------------------------------------------------
  // The whole state in one HDF5 file (written to a temporary name, then renamed); a world loaded
  // from it continues bit for bit as the saved one would have.
  void save(const std::string& path) const;
  static World load(const std::string& path, int threads = 0, const std::string& simd = "auto");

  // Internal state, for the engine's own tests and the Lua layer's bulk access.
  detail::State& state() { return *state_; }
  const detail::State& state() const { return *state_; }

 private:
  std::unique_ptr<detail::State> state_;
};

// Architectures the running CPU supports, best first, always ending with "scalar".
std::vector<std::string> available_simd_architectures();

}  // namespace asperity
