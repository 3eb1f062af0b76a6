// Tests of the shared quadrature helpers (analytic/quadrature.h). Oracle for
// the Gaussian interval masses: erf written out, and the sum of all masses.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analytic/quadrature.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace {

TEST(Quadrature, GaussianIntervalMassesEqualTheOneIntervalForm) {
  // Centres inside, at an edge, outside and far outside the edges; narrow and
  // wide Gaussians. Each mass must be the one-interval function's value
  // exactly (the same erfc arguments, one per edge instead of two per
  // interval), erf's difference within 1e-15, and the masses add up to the
  // Gaussian's mass over the whole range.
  const int n = 36;
  std::vector<double> edges(n + 1);
  for (int k = 0; k <= n; ++k) edges[k] = -kPi + k * kTwoPi / n;
  for (double beta : {0.01, 0.3, 2.0})
    for (double mu : {0.1, edges[7], -3.0, 5.0, 12.0}) {
      std::vector<double> out(2 * n, 0.0);
      add_gaussian_interval_masses(edges.data(), n, mu, beta, out.data(), 2);
      double sum = 0.0;
      for (int j = 0; j < n; ++j) {
        EXPECT_EQ(out[2 * j], gaussian_interval_mass(edges[j], edges[j + 1], mu, beta)) << beta << " " << mu << " " << j;
        EXPECT_EQ(out[2 * j + 1], 0.0);
        const double s = 1.0 / (std::sqrt(2.0) * beta);
        EXPECT_NEAR(out[2 * j], 0.5 * (std::erf((edges[j + 1] - mu) * s) - std::erf((edges[j] - mu) * s)), 1e-15);
        sum += out[2 * j];
      }
      const double s = 1.0 / (std::sqrt(2.0) * beta);
      EXPECT_NEAR(sum, 0.5 * (std::erf((kPi - mu) * s) - std::erf((-kPi - mu) * s)), 1e-14);
    }
}

}  // namespace
}  // namespace fiberlab::analytic
