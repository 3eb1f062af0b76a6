#include "analytic/azimuthal_lobes.h"

#include <algorithm>
#include <vector>

#include "analytic/quadrature.h"
#include "common/units.h"

namespace fiberlab::analytic::azimuthal {

double wrapped_gaussian(double beta, double phi) {
  phi = wrap_angle(phi);
  const int K = static_cast<int>(std::ceil(8.5 * beta / kTwoPi)) + 1;
  const double norm = 1.0 / (std::sqrt(kTwoPi) * beta);
  double s = 0.0;
  for (int k = -K; k <= K; ++k) {
    const double x = (phi - kTwoPi * k) / beta;
    s += std::exp(-0.5 * x * x);
  }
  return s * norm;
}

double half_angle_r_shape_series(double phi, double beta) {
  const int K = static_cast<int>(std::ceil(8.9 / beta));
  const double c1 = std::cos(phi);
  double c_prev = 1.0, c = c1, s = 2.0 / kPi;
  for (int k = 1; k <= K; ++k) {
    const double g = std::exp(-0.5 * k * k * beta * beta);
    s += ((k % 2) ? 4.0 : -4.0) * g / (kPi * (4.0 * k * k - 1.0)) * c;
    const double c_next = 2.0 * c1 * c - c_prev;
    c_prev = c;
    c = c_next;
  }
  return 0.25 * s;
}

double half_angle_r_shape_quadrature(double phi, double beta, double refine) {
  const double a = phi - 8.5 * beta, b = phi + 8.5 * beta;
  std::vector<double> cuts{a};
  // |cos(psi/2)| has kinks at psi = pi + 2 pi k: split there.
  for (long k = static_cast<long>(std::ceil((a - kPi) / kTwoPi)); kPi + kTwoPi * k < b; ++k)
    cuts.push_back(kPi + kTwoPi * k);
  cuts.push_back(b);
  const GaussLegendre& gl = gauss_legendre(8);
  const double max_len = std::min(0.5 * beta, 0.2) / refine;
  const double norm = 1.0 / (std::sqrt(kTwoPi) * beta);
  double s = 0.0;
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    const int m = std::max(1, static_cast<int>(std::ceil((cuts[c + 1] - cuts[c]) / max_len)));
    const double len = (cuts[c + 1] - cuts[c]) / m;
    for (int k = 0; k < m; ++k) {
      const double mid = cuts[c] + (k + 0.5) * len;
      for (int q = 0; q < 8; ++q) {
        const double psi = mid + 0.5 * len * gl.x[q];
        const double x = (phi - psi) / beta;
        s += 0.5 * len * gl.w[q] * norm * std::exp(-0.5 * x * x) * std::abs(std::cos(0.5 * psi)) * 0.25;
      }
    }
  }
  return s;
}

namespace {
// 1 / (1 + exp(-t)) without overflow for either sign of t.
double sigmoid(double t) {
  if (t >= 0.0) return 1.0 / (1.0 + std::exp(-t));
  const double e = std::exp(t);
  return e / (1.0 + e);
}
// Mass of the logistic on [-pi, pi]: sigmoid(pi/s) - sigmoid(-pi/s).
double trimmed_mass(double s) { return std::tanh(0.5 * kPi / s); }
}  // namespace

double trimmed_logistic(double x, double s) {
  // Logistic density exp(-|x|/s) / (s (1 + exp(-|x|/s))^2), symmetric in x.
  const double e = std::exp(-std::abs(x) / s);
  return e / (s * (1.0 + e) * (1.0 + e)) / trimmed_mass(s);
}

double trimmed_logistic_cumulative(double x, double s) {
  const double k = std::floor((x + kPi) / kTwoPi);
  const double r = x - kTwoPi * k;  // [-pi, pi)
  return k + (sigmoid(r / s) - sigmoid(-kPi / s)) / trimmed_mass(s);
}

}  // namespace fiberlab::analytic::azimuthal
