// engine/surface/random.hpp - the portable random numbers behind the phase field.
//
// Design notes
// - std::uniform_real_distribution and friends are implementation-defined: the same seed gives
//   different numbers with libstdc++ and libc++, or across versions. A surface must be the same
//   surface everywhere (S1..S8 are reference geometries), so the generator is written out here:
//   splitmix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", 2014)
//   expands the 64-bit seed into the 256-bit state of xoshiro256** (Blackman, Vigna, "Scrambled
//   linear pseudorandom number generators", 2018). Both are a few integer operations, fully
//   specified by those papers, and pass BigCrush.
// - uniform() takes the top 53 bits, so it returns k * 2^-53 in [0, 1), exact in double.
#pragma once

#include <array>
#include <cstdint>

namespace asperity::surface::detail {

// One splitmix64 step: advances `state` by the golden-ratio increment and mixes it.
inline std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Xoshiro256StarStar {
 public:
  explicit Xoshiro256StarStar(std::uint64_t seed) {
    std::uint64_t sm = seed;
    for (auto& word : s_) word = splitmix64(sm);  // never all zero (splitmix64 is a bijection)
  }

  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::array<std::uint64_t, 4> s_{};
};

}  // namespace asperity::surface::detail
