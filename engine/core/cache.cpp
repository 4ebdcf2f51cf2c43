#include "core/cache.hpp"

#include <cctype>
#include <fstream>
#include <string>

namespace asperity::detail {

std::size_t parse_cache_size(std::string_view text) {
  std::size_t i = 0, value = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  const std::size_t digits = i;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i)
    value = value * 10 + std::size_t(text[i] - '0');
  if (i == digits) return 0;
  if (i < text.size()) {
    switch (text[i]) {
      case 'K': case 'k': return value << 10;
      case 'M': case 'm': return value << 20;
      case 'G': case 'g': return value << 30;
      default: break;
    }
  }
  return value;
}

std::size_t last_level_cache_bytes() {
  static const std::size_t bytes = [] {
    std::size_t found = 0;
    int best_level = 0;
    for (int index = 0; index < 8; ++index) {
      const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index);
      std::ifstream level_file(dir + "/level"), size_file(dir + "/size");
      int level = 0;
      std::string size;
      if (!(level_file >> level) || !(size_file >> size)) continue;
      const std::size_t b = parse_cache_size(size);
      if (b > 0 && level >= best_level) {
        best_level = level;
        found = b;
      }
    }
    return found > 0 ? found : std::size_t(32) << 20;
  }();
  return bytes;
}

}  // namespace asperity::detail
