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

inline std::size_t round_up(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

namespace detail_memory {
// Arrays of at least this many bytes are mapped on their own, on transparent huge pages where
// the system offers them, each starting at a different cache line (core/aligned.cpp says why).
// Smaller ones come from the heap.
inline constexpr std::size_t kLargeArray = std::size_t(256) << 10;
void* allocate_large(std::size_t bytes);
void release_large(void* p);
bool large_arrays_mapped();  // false under AddressSanitizer and off Linux: heap, no stagger
}  // namespace detail_memory

template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = bytes_for(n);
    if (bytes >= detail_memory::kLargeArray) return static_cast<T*>(detail_memory::allocate_large(bytes));
    void* p = std::aligned_alloc(kAlignment, bytes == 0 ? kAlignment : bytes);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  // The same size decides how an array was allocated and how it is released.
  void deallocate(T* p, std::size_t n) {
    if (bytes_for(n) >= detail_memory::kLargeArray) detail_memory::release_large(p);
    else std::free(p);
  }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const { return true; }

 private:
  static std::size_t bytes_for(std::size_t n) { return round_up(n * sizeof(T), kAlignment); }
};

template <class T>
using AVec = std::vector<T, AlignedAllocator<T>>;

}  // namespace asperity
