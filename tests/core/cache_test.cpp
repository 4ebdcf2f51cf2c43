// The last-level cache size read from /sys (core/cache.hpp), which decides whether the pair
// records are streamed past the caches (stages/pairs.cpp).
#include <gtest/gtest.h>

#include "core/cache.hpp"

namespace asperity::detail {
namespace {

TEST(CacheSize, ParsesTheSysfsSuffixes) {
  EXPECT_EQ(parse_cache_size("32768K"), std::size_t(32) << 20);
  EXPECT_EQ(parse_cache_size("1024K\n"), std::size_t(1) << 20);
  EXPECT_EQ(parse_cache_size("16M"), std::size_t(16) << 20);
  EXPECT_EQ(parse_cache_size("2G"), std::size_t(2) << 30);
  EXPECT_EQ(parse_cache_size("512"), std::size_t(512));
}

TEST(CacheSize, RejectsTextWithoutANumber) {
  EXPECT_EQ(parse_cache_size(""), 0u);
  EXPECT_EQ(parse_cache_size("K"), 0u);
  EXPECT_EQ(parse_cache_size("unknown"), 0u);
}

TEST(CacheSize, TheMachineReportsAPlausibleLastLevel) {
  // Read from /sys or the 32 MB fallback: at least an L1's worth, at most a terabyte.
  const std::size_t bytes = last_level_cache_bytes();
  EXPECT_GE(bytes, std::size_t(32) << 10);
  EXPECT_LE(bytes, std::size_t(1) << 40);
  EXPECT_EQ(bytes, last_level_cache_bytes());  // read once
}

}  // namespace
}  // namespace asperity::detail
