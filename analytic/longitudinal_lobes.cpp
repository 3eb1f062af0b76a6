#include "analytic/longitudinal_lobes.h"

#include <cmath>

#include "common/units.h"

namespace fiberlab::analytic::longitudinal {

double log_I0(double x) {
  x = std::abs(x);
  if (x < 30.0) {
    // I0(x) = sum_k (x^2/4)^k / (k!)^2: positive terms, no cancellation.
    const double y = 0.25 * x * x;
    double term = 1.0, sum = 1.0;
    for (int k = 1; k < 500; ++k) {
      term *= y / (static_cast<double>(k) * k);
      sum += term;
      if (term < 1e-17 * sum) break;
    }
    return std::log(sum);
  }
  // Asymptotic expansion (Abramowitz & Stegun 9.7.1), a_k = ((2k-1)!!)^2 / (k! 8^k).
  double term = 1.0, sum = 1.0;
  for (int k = 1; k < 60; ++k) {
    term *= (2.0 * k - 1.0) * (2.0 * k - 1.0) / (8.0 * k * x);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return x - 0.5 * std::log(kTwoPi * x) + std::log(sum);
}

double log_csch(double x) { return std::log(2.0) - x - std::log1p(-std::exp(-2.0 * x)); }

double vmf_log_M_p(double v, double theta_i, double theta_r) {
  // M_p = csch(1/v) / (2v) * exp(-sin theta_i sin theta_r / v) * I0(cos theta_i cos theta_r / v).
  // For small v each factor over/underflows while the product is O(1/sqrt v):
  // add the logarithms (their sum loses ~|1/v| * 1e-16 absolutely, i.e.
  // 1e-12 relative at v = 1e-4).
  const double a = std::cos(theta_i) * std::cos(theta_r) / v;
  const double b = std::sin(theta_i) * std::sin(theta_r) / v;
  return log_csch(1.0 / v) - std::log(2.0 * v) - b + log_I0(a);
}

double vmf_M_p(double v, double theta_i, double theta_r) { return std::exp(vmf_log_M_p(v, theta_i, theta_r)); }

double gaussian(double beta, double x) {
  return std::exp(-0.5 * (x / beta) * (x / beta)) / (std::sqrt(kTwoPi) * beta);
}

double gaussian_M_p(double beta, double alpha_theta_r, double theta_i, double theta_r, bool two_theta_h) {
  const double theta_h = 0.5 * (theta_i + theta_r);
  if (two_theta_h) return gaussian(beta, 2.0 * theta_h - alpha_theta_r);
  return gaussian(beta, theta_h - 0.5 * alpha_theta_r);
}

}  // namespace fiberlab::analytic::longitudinal
