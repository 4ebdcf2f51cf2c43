// A field of a settings struct described once: the name users give it (Lua option, help entry),
// the name a checkpoint keeps it under, the values it accepts and what it means. A struct lists
// its fields in one table (for_each_setting in world.hpp, for_each_field of the materials), and
// the checks, the Lua binding, the checkpoint and help() all walk that table, so a new field is
// written once and no consumer can forget it.
#pragma once

#include <limits>
#include <sstream>
#include <string>

namespace asperity {

// The numbers a field accepts: [lo, hi] with either end open, and optionally 0 besides (for a
// field whose 0 means "automatic"). A NaN is never accepted.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  const char* zero = nullptr;  // what 0 means when it is accepted outside [lo, hi]
  const char* unit = "";

  bool contains(double v) const {
    if (zero != nullptr && v == 0) return true;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
};

struct Field {
  const char* name;              // the Lua option, the help entry, the messages
  const char* stored = nullptr;  // the checkpoint's name for it; nullptr: not saved
  int since = 1;                 // the checkpoint version that added it (older files: the default)
  Range range{};                 // numbers only
  const char* doc = "";
};

// A number as the messages print it: "1e-06", "0.7", "inf", "nan" (never "-nan": the sign of a
// NaN means nothing to a user).
inline std::string short_number_text(double v) {
  if (v != v) return "nan";
  std::ostringstream s;
  s << v;
  return s.str();
}

// "[0.001, 2]", "(0, 2)", "[1e-15, inf)": the interval of a range, with its unit.
inline std::string range_text(const Range& r) {
  std::string t = (r.lo_open ? "(" : "[") + short_number_text(r.lo) + ", " + short_number_text(r.hi) +
                  (r.hi_open ? ")" : "]");
  return *r.unit ? t + " " + r.unit : t;
}

// Empty when `v` is in the range; else what is wrong, naming the field: "dt_safety 3 outside
// [0.001, 2]", "dt 1e-20 must be 0 (automatic) or in [1e-15, inf) s".
inline std::string range_problem(const char* name, double v, const Range& r) {
  if (r.contains(v)) return {};
  const std::string head = std::string(name) + " " + short_number_text(v);
  if (r.zero != nullptr) return head + " must be 0 (" + r.zero + ") or in " + range_text(r);
  return head + " outside " + range_text(r);
}

}  // namespace asperity
