#include "analytic/pbrt_v4_mp.h"

#include <cmath>

#include "common/units.h"

namespace fiberlab::analytic::pbrt_v4 {

double I0(double x) {
  // Terms (x^2/4)^i / (i!)^2, i = 0..9: each term is the previous times
  // (x^2/4) / i^2.
  const double q = 0.25 * x * x;
  double term = 1.0, sum = 1.0;
  for (int i = 1; i < 10; ++i) {
    term *= q / (static_cast<double>(i) * i);
    sum += term;
  }
  return sum;
}

double log_I0(double x) {
  if (x > 12.0) return x + 0.5 * (-std::log(kTwoPi) + std::log(1.0 / x) + 1.0 / (8.0 * x));
  return std::log(I0(x));
}

double log_M_p(double v, double theta_i, double theta_r) {
  const double a = std::cos(theta_i) * std::cos(theta_r) / v;
  const double b = std::sin(theta_i) * std::sin(theta_r) / v;
  if (v <= 0.1) return log_I0(a) - b - 1.0 / v + 0.6931 + std::log(1.0 / (2.0 * v));
  return -b + std::log(I0(a)) - std::log(std::sinh(1.0 / v) * 2.0 * v);
}

}  // namespace fiberlab::analytic::pbrt_v4
