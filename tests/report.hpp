// Prints a measured figure beside its closed form, so the test binary (or `ctest -V -R <test>`)
// shows the numbers a physics test checks, not only that it passed.
#pragma once
#include <cstdio>

namespace asperity::test {
inline void report(const char* what, double measured, double expected) {
  std::printf("[figure] %s: measured %.10g, closed form %.10g, relative difference %.3g\n", what,
              measured, expected, expected != 0 ? (measured - expected) / expected : measured);
}
}  // namespace asperity::test
