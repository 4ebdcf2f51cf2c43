// The neighbour search's distance test over a run of cell-ordered entries (neighbor/build.cpp),
// shared by the scalar reference and the SIMD kernels: the same operations in the same order on
// every set, so every set finds the same entries.
#pragma once
#include <bit>

#include "kernels/kernels.hpp"

namespace asperity::kernels {

template <class Lanes>
std::size_t near_loop(const NearArgs& k, std::int32_t first, std::int32_t last, std::int32_t* hits) {
  using T = typename Lanes::Real;
  const T cx(k.cx), cy(k.cy), cz(k.cz), reach(k.reach);
  const typename Lanes::Index after(k.after);
  std::size_t found = 0;
  for (std::int32_t t = first; t < last; t += std::int32_t(Lanes::size)) {
    const T dx = Lanes::load_u(k.x + t) - cx, dy = Lanes::load_u(k.y + t) - cy,
            dz = Lanes::load_u(k.z + t) - cz;
    const T cut = reach + Lanes::load_u(k.r + t);
    std::uint64_t m = Lanes::bits(dx * dx + dy * dy + dz * dz < cut * cut) &
                      Lanes::bits(Lanes::index32(k.index + t) > after);
    if (last - t < std::int32_t(Lanes::size)) m &= (std::uint64_t(1) << (last - t)) - 1;
    for (; m != 0; m &= m - 1) hits[found++] = t + std::int32_t(std::countr_zero(m));
  }
  return found;
}

}  // namespace asperity::kernels
