// Large arrays on transparent huge pages (aligned.hpp, AlignedAllocator).
//
// Why: the columns of a scene past the caches (some forty of them) are walked by many streams at
// once, each on its own 4 kB pages, and the TLB cannot hold them all; with 2 MB pages the page
// walks go.
//
// Why the stagger: arrays that all start on a 2 MB boundary put element i of every column in the
// same L1 and L2 sets, and the pair kernel reads some twenty columns at one index, more than a
// set holds, so they would evict one another (slower than on 4 kB pages). Starting each array at
// a different 64-byte line within its first 4 kB spreads them over the sets again.
#include "core/aligned.hpp"

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace asperity::detail_memory {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
std::atomic<std::size_t> arrays{0};

#if defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
constexpr bool kUseMmap = true;
#else
constexpr bool kUseMmap = false;  // elsewhere, and under AddressSanitizer (which checks the heap)
#endif
}  // namespace

bool large_arrays_mapped() { return kUseMmap; }

void* allocate_large(std::size_t bytes) {
#if defined(__linux__)
  if constexpr (kUseMmap) {
    // The header (mapping start and length) sits in the stagger, just before the array.
    const std::size_t stagger = kAlignment * (1 + arrays.fetch_add(1, std::memory_order_relaxed) % 63);
    const std::size_t need = round_up(bytes + stagger, kHugePage);
    const std::size_t length = need + kHugePage;  // room to align the start
    void* raw = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    char* const first = static_cast<char*>(raw);
    char* const base = reinterpret_cast<char*>(round_up(reinterpret_cast<std::uintptr_t>(first), kHugePage));
    if (base > first) munmap(first, std::size_t(base - first));
    if (first + length > base + need) munmap(base + need, std::size_t(first + length - (base + need)));
    madvise(base, need, MADV_HUGEPAGE);  // a hint: without THP the array is on 4 kB pages
    char* const p = base + stagger;
    reinterpret_cast<char**>(p)[-1] = base;
    reinterpret_cast<std::size_t*>(p)[-2] = need;
    return p;
  }
#endif
  void* p = std::aligned_alloc(kAlignment, round_up(bytes, kAlignment));
  if (!p) throw std::bad_alloc();
  return p;
}

void release_large(void* p) {
#if defined(__linux__)
  if constexpr (kUseMmap) {
    char* const q = static_cast<char*>(p);
    munmap(reinterpret_cast<char**>(q)[-1], reinterpret_cast<std::size_t*>(q)[-2]);
    return;
  }
#endif
  std::free(p);
}

}  // namespace asperity::detail_memory
