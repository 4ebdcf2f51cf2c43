// The a-side particles of a batch of pairs or bonds. Both lists are sorted by a, and a particle
// has a few pairs in a row, so the lanes' a usually lie within one lane-width window
// [a0, a0 + lanes): then one contiguous load and a lane permutation replace each a-side gather
// (ten of the twenty per batch with rotation; a gather costs a load per lane, and the gathers are
// most of what the pair kernel waits for). The values loaded are the same, so the results are
// bitwise those of the gathers.
#pragma once
#include <cstddef>
#include <cstdint>

namespace asperity::kernels {

template <class Lanes>
class ASide {
 public:
  using T = typename Lanes::Real;
  using I = typename Lanes::Index;
  // a: the batch's a column; ia: the same, loaded; columns: length of the particle columns (the
  // window must not read past them).
  ASide(const std::int64_t* a, const I& ia, std::size_t columns)
      : index_(ia), first_(a[0]), offset_(Lanes::offsets(ia, a[0])),
        window_(std::size_t(a[0]) + Lanes::size <= columns && Lanes::fits(offset_)) {}
  T gather(const double* col) const {
    return window_ ? Lanes::window(col + first_, offset_) : Lanes::gather(col, index_);
  }

 private:
  const I& index_;
  std::int64_t first_;
  I offset_;
  bool window_;
};

// The particle values a batch of pairs or bonds reads, both sides: positions, radii, velocities
// and (with Rotation) angular velocities, which stay 0 otherwise. Args: PairKernelArgs or
// BondKernelArgs (kernels.hpp), which name their columns alike.
template <class T>
struct BatchSides {
  T xa, ya, za, ra, vax, vay, vaz, wax, way, waz;
  T xb, yb, zb, rb, vbx, vby, vbz, wbx, wby, wbz;
};

// The positions and radii of both sides (into xa..rb), then their velocities (vax..wbz): apart
// for a loop that needs the velocities of some batches only (pair_loop.hpp), together in
// load_sides.
template <class Lanes, class Args>
inline void load_positions(const Args& k, std::size_t i, BatchSides<typename Lanes::Real>& s) {
  const auto ia = Lanes::index(k.a + i);
  const auto ib = Lanes::index(k.b + i);
  const ASide<Lanes> A(k.a + i, ia, k.columns);
  s.xa = A.gather(k.x); s.ya = A.gather(k.y); s.za = A.gather(k.z); s.ra = A.gather(k.radius);
  s.xb = Lanes::gather(k.x, ib); s.yb = Lanes::gather(k.y, ib); s.zb = Lanes::gather(k.z, ib);
  s.rb = Lanes::gather(k.radius, ib);
}

template <class Lanes, bool Rotation, class Args>
inline void load_velocities(const Args& k, std::size_t i, BatchSides<typename Lanes::Real>& s) {
  using T = typename Lanes::Real;
  const auto ia = Lanes::index(k.a + i);
  const auto ib = Lanes::index(k.b + i);
  const ASide<Lanes> A(k.a + i, ia, k.columns);
  s.vax = A.gather(k.vx); s.vay = A.gather(k.vy); s.vaz = A.gather(k.vz);
  s.vbx = Lanes::gather(k.vx, ib); s.vby = Lanes::gather(k.vy, ib); s.vbz = Lanes::gather(k.vz, ib);
  s.wax = s.way = s.waz = s.wbx = s.wby = s.wbz = T(0.0);
  if constexpr (Rotation) {
    s.wax = A.gather(k.wx); s.way = A.gather(k.wy); s.waz = A.gather(k.wz);
    s.wbx = Lanes::gather(k.wx, ib); s.wby = Lanes::gather(k.wy, ib); s.wbz = Lanes::gather(k.wz, ib);
  }
}

template <class Lanes, bool Rotation, class Args>
inline BatchSides<typename Lanes::Real> load_sides(const Args& k, std::size_t i) {
  BatchSides<typename Lanes::Real> s;
  load_positions<Lanes>(k, i, s);
  load_velocities<Lanes, Rotation>(k, i, s);
  return s;
}

}  // namespace asperity::kernels
