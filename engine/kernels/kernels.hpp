// Kernel entry points and their run-time dispatch. A pair kernel processes pairs [begin, end) of
// the pair list (begin and end multiples of kMaxLanes) and returns the slip energy it dissipated.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace asperity::kernels {

// Pairs per stage of the pair loop (pair_loop.hpp): its scratch stays in L1. Blocks start at
// multiples of it, so stage s holds pairs [s kPairStage, (s + 1) kPairStage).
inline constexpr std::size_t kPairStage = 128;

struct PairKernelArgs {
  const double* x; const double* y; const double* z;
  const double* vx; const double* vy; const double* vz;
  const double* wx; const double* wy; const double* wz;
  const double* radius;
  const std::int64_t* a; const std::int64_t* b;
  double* nx; double* ny; double* nz;
  double* fsx; double* fsy; double* fsz;
  // Output for the gather and the readers of normal forces and overlaps (store/pairs.hpp): per
  // pair the record fx fy fz U cx cy cz fn, eight doubles from out + 8 k (64-byte aligned).
  double* out;
  double kn, ks, friction, dt;
  // Length of the particle columns. A batch whose a-side particles lie within one lane-width
  // window [a0, a0 + lanes) that fits in the columns loads them with one contiguous load and a
  // lane permutation instead of a gather (lists sorted by a make this the common case); 0 never.
  std::size_t columns = 0;
  // Rest overlaps (store/pairs.hpp), read and, where the pair no longer touches, reset to 0;
  // null: every rest overlap is 0 and the column is not touched.
  double* rest = nullptr;
  bool stream = false;  // non-temporal record stores (pairs.cpp: record arrays past the caches)
  // Per stage of kPairStage pairs (null: not kept), written by the kernel: with `live` given, how
  // many of the stage's records are live (below), else 1 where one of its pairs touches, else 0.
  // A stage with 0 in the last step is computed geometry first and its kinematics only if it
  // touches now (pair_loop.hpp), the values the same.
  std::uint8_t* touched = nullptr;
  // Per pair (null: not written): 1 where its record is live, i.e. not all zeros but for the
  // overlap U <= 0: the pair touches, carries a normal force or has a NaN overlap; else 0 (the
  // gather skips those: GatherArgs::live).
  std::uint8_t* live = nullptr;
  // With `live`: the flags it holds on entry are the last step's, and a batch dead then and now
  // keeps its records, which are dead records already (zero forces, an overlap U <= 0 from the
  // step it was last written; store/pairs.hpp): nothing reads them in the step (the gather
  // skips them) and every reader outside it asks only whether U > 0.
  bool keep_dead_records = false;
};

using PairKernel = double (*)(const PairKernelArgs&, std::size_t begin, std::size_t end);

// What of a bond still holds (BondStore::holds, a bit set; model.md 5): the parallel bond (beam)
// and the contact bond break separately; an entry with neither leaves the bond list.
inline constexpr double kBeamHolds = 1, kContactBondHolds = 2, kBothHold = 3;

// Bond kernel: bonds [begin, end) of the bond list; where a part breaks (only when strength > 0)
// sets broken[k] to the parts that broke (kBeamHolds: the beam by the elliptic criterion,
// kContactBondHolds: the contact bond; store/bonds.hpp) and leaves the other flags as they are
// (all 0 between steps: BondStore::broken). Returns the number of bonds with a break and the
// slip energy of the contact springs whose contact bond broke.
struct BondKernelArgs {
  const double* x; const double* y; const double* z;
  const double* vx; const double* vy; const double* vz;
  const double* wx; const double* wy; const double* wz;
  const double* radius;
  const std::int64_t* a; const std::int64_t* b;
  const double* beam_radius;
  double* nx; double* ny; double* nz;
  double* fsx; double* fsy; double* fsz; double* fn; double* overlap;
  double* fbn; double* fbsx; double* fbsy; double* fbsz;
  double* mbn; double* mbsx; double* mbsy; double* mbsz;
  double* broken;
  // Output for the gather (store/bonds.hpp): per bond the record fx fy fz U cx cy cz 0 mx my mz 0,
  // twelve doubles from out + 12 k (32-byte aligned); the kernel without moments writes the first
  // eight only, from out + 8 k, and the one for bonds no end of which turns the first four, from
  // out + 4 k (BondRecord).
  double* out;
  double kn, ks, beam_kn, beam_ks, dt, strength;
  std::size_t columns = 0;  // as PairKernelArgs::columns
  const double* rest = nullptr;  // rest overlaps of the contact bonds; null: all 0
  // What of each bond holds (BondStore::holds); null: every bond holds both parts.
  const double* holds = nullptr;
  double friction = 0;  // of the contact springs whose contact bond broke
  // c of the contact bond's strength c st A (BondMaterial::contact_strength): 0 breaks it with
  // the beam, inf never.
  double contact_strength = 0;
  double contact_shear_strength = 0;  // cs of its shear strength cs st A (0: cs = c)
  double contact_bond_friction = 0;   // mu_b: + mu_b Fn under compression
};

// What a bond record holds (store/bonds.hpp), as many doubles as its value: the layout the bond
// kernel that wrote it gives, and the gather reads.
enum class BondRecord : std::uint8_t {
  // fx fy fz U cx cy cz 0 mx my mz 0: the force on b, the overlap, n x Fs and the beam's moment.
  moments = 12,
  // fx fy fz U cx cy cz 0: every beam moment zero (no spin ever grew one), left out.
  levers = 8,
  // fx fy fz U: besides, no end of a bond turns (model.md 2 locks a bonded particle; a rigid
  // group's member turns with its group), so the torque of the bonds' shear forces moves nothing
  // and is not gathered: a bonded specimen's record is half a cache line (World::torque adds
  // those terms when asked).
  forces = 4,
};

struct BondSums {
  double breaks = 0;  // bonds of which a part broke
  double slip = 0;    // J, Coulomb slip of contact springs without their contact bond
};

using BondKernel = BondSums (*)(const BondKernelArgs&, std::size_t begin, std::size_t end);

// Plane wall kernel (wall_loop.hpp): ball-plane contacts [begin, end) of the wall contact list,
// all of them with planes; the plane is body a of the contact law (model.md 4), translating with
// its velocity, not spinning. Reads the contacts' history and writes their new state, and per
// contact the slip energy; the per-wall sums stay with the caller (stages/walls.cpp), which adds
// them in contact order. The wall columns (px .. friction) are indexed by wall number; px..pz is
// the plane's current point (its point at creation plus its displacement).
struct PlaneWallArgs {
  const double* x; const double* y; const double* z;
  const double* vx; const double* vy; const double* vz;
  const double* wx; const double* wy; const double* wz;
  const double* radius;
  const std::int32_t* particle; const std::int32_t* wall;
  double* nx; double* ny; double* nz;
  double* fsx; double* fsy; double* fsz; double* fn; double* overlap;
  double* slip;
  const double* px; const double* py; const double* pz;
  const double* pnx; const double* pny; const double* pnz;
  const double* pvx; const double* pvy; const double* pvz;
  const double* kn; const double* ks; const double* friction;
  double dt;
  // Walls in the per-wall columns px..friction, each then readable to at least kMaxLanes entries
  // (zero padding): with no more walls than lanes, a lane permutation of the column replaces
  // the gather (Lanes::lookup). 0: not padded, always gathered.
  std::size_t walls = 0;
};

using PlaneWallKernel = void (*)(const PlaneWallArgs&, std::size_t begin, std::size_t end);

// The gather kernel (gather_loop.hpp), for each particle i in [begin, end) not marked in `inert`
// or `idle` (either may be null; the pairs' arguments say), in the order of its incidences:
// - the sum of the force and torque the pair records give it (store/pairs.hpp: record
//   fx fy fz U cx cy cz fn; on b: +F, on a: -F; on either: -(R - U/2) n x Fs);
// - then, where a bond list is given, the same from the bond records (store/bonds.hpp) plus the
//   beam moment (+M on b, -M on a), added to those sums (the terms its BondRecord holds);
// written to fx..tz[i] (the pairs' arguments name the columns). The walls and applied forces are
// added by the caller (stages/integrate.cpp).
struct GatherArgs {
  const std::int32_t* start;  // incidence CSR (store/pairs.hpp, Incidence)
  const std::int64_t* entry;  // (pair or bond << 1) | (particle is b)
  const double* records;      // 8 doubles per pair, 4, 8 or 12 per bond (BondRecord)
  const double* radius;
  const std::uint8_t* inert; const std::uint8_t* idle;
  double* fx; double* fy; double* fz;
  double* tx; double* ty; double* tz;
  // Prefetch the records of the particle kGatherAhead ahead (vector gathers only, gather_loop.hpp):
  // for record arrays past the caches, whose lines the incidences reach out of order
  // (stages/integrate.cpp, records_past_caches in state.hpp).
  bool prefetch = false;
  // Pair lists: per pair, 0 where its record is zero but for the overlap (PairKernelArgs::live,
  // from this step's pair kernel); the gather skips those records.
  // Exact: the terms left out are +-0, and a sum that starts at +0 is never changed by adding
  // +-0 (it never becomes -0 in round-to-nearest), with the lever R - U/2 finite for U <= 0.
  // Null: every record is read.
  const std::uint8_t* live = nullptr;
  // Bond lists: the layout the bond kernel wrote (BondRecord); the gather leaves out the terms
  // the record does not hold.
  BondRecord bond_record = BondRecord::moments;
};

using GatherKernel = void (*)(const GatherArgs& pairs, const GatherArgs* bonds, std::size_t begin,
                              std::size_t end);

// Integrate kernel (integrate_loop.hpp): particles [begin, end), begin a multiple of kMaxLanes and
// end padded up to one (the padding particles have free = 0). `free` and `spin` are 0/1 masks
// indexed from begin; ax..az are null when no particle carries an applied force.
struct IntegrateArgs {
  double* x; double* y; double* z;
  double* vx; double* vy; double* vz;
  double* wx; double* wy; double* wz;
  const double* fx; const double* fy; const double* fz;
  const double* tx; const double* ty; const double* tz;
  const double* x0; const double* y0; const double* z0;
  const double* mass; const double* inv_mass; const double* inertia; const double* inv_inertia;
  const double* radius;
  const double* ax; const double* ay; const double* az;
  const double* free; const double* spin;
  double dt, alpha, gx, gy, gz;
};

// What a block of the integrate stage reports: energy terms of the step (summed per lane, then
// over lanes: equal to the scalar sums to rounding), the largest squared displacement since the
// last build, and the largest step displacement / R (or turn / 0.1 rad) with its particle index.
struct IntegrateSums {
  double damping = 0, gravity = 0, applied = 0, kinetic = 0;
  double max_disp2 = 0, worst_step = 0;
  std::int64_t worst = -1;
};

using IntegrateKernel = void (*)(const IntegrateArgs&, std::size_t begin, std::size_t end,
                                 IntegrateSums& out);

// Neighbour search (neighbor/build.cpp, model.md 6): of the entries of cell-ordered columns
// (centre x, y, z, radius r and particle index; readable kMaxLanes entries past any run) in the
// runs [runs[2 m], runs[2 m + 1]), m < count, the ones of an index above `after` within reach of
// a centre: (x - cx)^2 + (y - cy)^2 + (z - cz)^2 < (reach + r)^2, each difference and sum taken
// in that order. Writes their positions to hits (room for the runs' entries), run after run,
// ascending in each, and returns how many.
struct NearArgs {
  const double* x; const double* y; const double* z; const double* r;
  const std::int32_t* index;
  double cx, cy, cz, reach;
  std::int32_t after;
};

using NearKernel = std::size_t (*)(const NearArgs&, const std::int32_t* runs, std::size_t count,
                                   std::int32_t* hits);

struct KernelSet {
  const char* name;        // "scalar", "sse4_2", "avx2", "avx512f"
  std::size_t lanes;       // doubles per batch
  PairKernel pair;         // with rotation
  PairKernel pair_norot;   // every particle's rotation locked: w is not read
  BondKernel bond;
  BondKernel bond_norot;
  BondKernel bond_no_moment;  // no spin and no beam moment (bond_loop.hpp): the moments untouched,
                              // records of 8 doubles (no moment)
  BondKernel bond_forces;     // the same, for bonds no end of which turns: records of 4 (BondRecord)
  IntegrateKernel integrate;        // with rotation
  IntegrateKernel integrate_norot;  // no particle can rotate: w and torques are not read
  PlaneWallKernel plane_walls;       // with rotation
  PlaneWallKernel plane_walls_norot;
  GatherKernel gather;
  NearKernel near;
};

const KernelSet& scalar_kernels();
// The kernel set for `name` ("auto": the best the CPU supports).
// Throws asperity::Error for an unknown or unsupported name, listing the valid ones.
const KernelSet& select_kernels(const std::string& name);

}  // namespace asperity::kernels
