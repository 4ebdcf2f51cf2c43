// 64-byte aligned arrays: every structure-of-arrays column of the stores is one of these, so the
// SIMD kernels can use aligned loads at any block start that is a multiple of the widest width.
#pragma once
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

namespace asperity {

inline constexpr std::size_t kAlignment = 64;
// Widest SIMD width in doubles (AVX-512); store capacities are padded to a multiple of it so no
// kernel needs a tail loop.
inline constexpr std::size_t kMaxLanes = 8;

template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    std::size_t bytes = (n * sizeof(T) + kAlignment - 1) / kAlignment * kAlignment;
    void* p = std::aligned_alloc(kAlignment, bytes == 0 ? kAlignment : bytes);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const { return true; }
};

template <class T>
using AVec = std::vector<T, AlignedAllocator<T>>;

inline std::size_t round_up(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

}  // namespace asperity
