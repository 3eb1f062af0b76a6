#pragma once
// Angles, constants and small numeric helpers shared by every part of fiberlab.
#include <cmath>
#include <numbers>

namespace fiberlab {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }

// Wrap an angle to [-pi, pi) (SPEC section 1: relative azimuth).
inline double wrap_angle(double a) {
  a = std::fmod(a + kPi, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  double w = a - kPi;
  return w >= kPi ? -kPi : w;  // guard the rounding edge
}

}  // namespace fiberlab
