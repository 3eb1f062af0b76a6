#pragma once
// How a Monte Carlo estimate is printed: the value with fixed decimals, its
// standard error with two significant digits ("0.002967 +- 2.0e-05",
// "0.088950 +- 0.00028"): two digits of an error are enough to judge a
// difference by it, and fixed decimals would print a small error as 0.
#include <fmt/core.h>

#include <string>

namespace fiberlab {

inline std::string error_text(double std_error) { return fmt::format("{:#.2g}", std_error); }

inline std::string estimate_text(double value, double std_error, int decimals = 6) {
  return fmt::format("{:.{}f} +- {}", value, decimals, error_text(std_error));
}

}  // namespace fiberlab
