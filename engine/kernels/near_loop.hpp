// The neighbour search's distance test over runs of cell-ordered entries (neighbor/build.cpp),
// shared by the scalar reference and the SIMD kernels: the same operations in the same order on
// every set, so every set finds the same entries.
#pragma once
#include <bit>

#include "kernels/kernels.hpp"

namespace asperity::kernels {

template <class Lanes>
std::size_t near_loop(const NearArgs& k, const std::int32_t* runs, std::size_t count, std::int32_t* hits) {
  using T = typename Lanes::Real;
  const T cx(k.cx), cy(k.cy), cz(k.cz), reach(k.reach);
  const typename Lanes::Index after(k.after);
  std::size_t found = 0;
  for (std::size_t m = 0; m < count; ++m) {
    const std::int32_t last = runs[2 * m + 1];
    for (std::int32_t t = runs[2 * m]; t < last; t += std::int32_t(Lanes::size)) {
      const T dx = Lanes::load_u(k.x + t) - cx, dy = Lanes::load_u(k.y + t) - cy,
              dz = Lanes::load_u(k.z + t) - cz;
      const T cut = reach + Lanes::load_u(k.r + t);
      std::uint64_t hit = Lanes::bits(dx * dx + dy * dy + dz * dz < cut * cut) &
                          Lanes::bits(Lanes::index32(k.index + t) > after);
      if (last - t < std::int32_t(Lanes::size)) hit &= (std::uint64_t(1) << (last - t)) - 1;
      for (; hit != 0; hit &= hit - 1) hits[found++] = t + std::int32_t(std::countr_zero(hit));
    }
  }
  return found;
}

}  // namespace asperity::kernels
