// The stores' arrays (core/aligned.hpp): 64-byte aligned at every size; large ones are mapped on
// their own (core/aligned.cpp), each starting at a different cache line, and keep their contents
// through growth and release.
#include <cstdint>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "core/aligned.hpp"

namespace asperity {
namespace {

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

TEST(AlignedArrays, SmallAndLargeAreAlignedAndHoldTheirValues) {
  for (std::size_t n : {std::size_t(1), std::size_t(1000), detail_memory::kLargeArray / 8 - 1,
                        detail_memory::kLargeArray / 8, std::size_t(3) << 20}) {
    AVec<double> v(n);
    EXPECT_EQ(address(v.data()) % kAlignment, 0u) << n;
    for (std::size_t i = 0; i < n; ++i) v[i] = double(i);
    v.resize(2 * n + 5, -1.0);  // moves into a new array and releases the old one
    EXPECT_EQ(address(v.data()) % kAlignment, 0u) << n;
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(v[i], double(i)) << n;
    EXPECT_EQ(v.back(), -1.0);
  }
}

TEST(AlignedArrays, LargeArraysStartOnDifferentCacheLines) {
  // Columns that all started at the same offset within a page would share the L1 and L2 sets at
  // every index (core/aligned.cpp). Twenty columns, as many as the pair kernel reads at once.
  if (!detail_memory::large_arrays_mapped()) GTEST_SKIP() << "large arrays come from the heap here";
  std::vector<AVec<double>> columns;
  std::set<std::uintptr_t> lines;
  for (int c = 0; c < 20; ++c) {
    columns.emplace_back(detail_memory::kLargeArray / 8 * 2, double(c));
    lines.insert(address(columns.back().data()) % 4096 / kAlignment);
  }
  EXPECT_GE(lines.size(), 16u);
  for (int c = 0; c < 20; ++c) EXPECT_EQ(columns[std::size_t(c)].back(), double(c));
}

}  // namespace
}  // namespace asperity
