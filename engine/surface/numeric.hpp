// engine/surface/numeric.hpp - small numerical helpers shared by the surface code.
//
// Design notes
// - Sums over 10^5 heights in plain double lose up to ~1e-12 relative; the generator promises the
//   variance to 1e-12, so moments are accumulated with Neumaier's compensated summation, which
//   keeps the error at a few ulps independently of the count.
#pragma once

#include <cmath>
#include <numbers>

namespace asperity::surface::detail {

class CompensatedSum {
 public:
  void add(double x) {
    const double t = sum_ + x;
    // Neumaier: recover the low-order bits lost in whichever operand was smaller.
    if (std::abs(sum_) >= std::abs(x))
      compensation_ += (sum_ - t) + x;
    else
      compensation_ += (x - t) + sum_;
    sum_ = t;
  }
  double value() const { return sum_ + compensation_; }

 private:
  double sum_ = 0.0;
  double compensation_ = 0.0;
};

inline constexpr double pi = std::numbers::pi;

// Angle test with a tolerance: directions are given as doubles (pi/4 is not exact).
inline bool near_integer(double x, double tol = 1e-9) { return std::abs(x - std::round(x)) < tol; }

}  // namespace asperity::surface::detail
