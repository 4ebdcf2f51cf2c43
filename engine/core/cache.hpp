// The size of the last-level cache this process's first CPU sees, for choices that depend on
// whether a working set fits (stages/pairs.cpp: non-temporal record stores). Read once from
// /sys/devices/system/cpu/cpu0/cache (the highest level listed); 32 MB where it cannot be read.
// Not sysconf(_SC_LEVEL3_CACHE_SIZE): in a virtual machine it can report the host's total over
// all its L3s instead of the one the guest sees.
#pragma once
#include <cstddef>
#include <string_view>

namespace asperity::detail {

std::size_t last_level_cache_bytes();

// A cache size as /sys writes it ("32768K", "1M", "512"); 0 if it cannot be read.
std::size_t parse_cache_size(std::string_view text);

}  // namespace asperity::detail
