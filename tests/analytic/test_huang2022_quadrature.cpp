// huang2022's default quadrature (Huang2022Params::quadrature_points) against
// the noise of the default atlas's simulations (configs/atlas.yaml: 24 x 36
// bins, 300k photons): on its white ggx 0.3 fiber (e 0.85, tilt 3 deg) at
// theta_i 45 deg, against 4x the points, the mean over bins with >= 10
// expected photons of (bin error)^2 / (p / N), the simulated bin's variance,
// is below 0.01 for R, TT and TRT (an RMS error below 0.1 standard errors;
// measured R 1e-4, TT 0.0043, TRT 0.0051, the reference's own error
// included) and below 1e-3 for p >= 3 (its M_p integrated per theta bin).
// The bound catches a default of 2^22 points (TRT 0.0114; TT 0.0095).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "analytic/huang2022.h"
#include "common/bin_grid.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

TEST(Huang2022, DefaultQuadratureIsATenthOfTheAtlasNoise) {
  Huang2022Params p;
  p.sigma_a = {0.0};
  p.roughness = 0.3;
  p.eccentricity = 0.85;
  p.tilt = deg_to_rad(3.0);
  Huang2022Params reference = p;
  reference.quadrature_points = 4 * p.quadrature_points;
  const BinGrid grid = BinGrid::make(24, 36, ThetaBinning::Uniform);
  const double theta_i = deg_to_rad(45.0), photons = 300000.0;
  const std::vector<double> q = Huang2022(p).bin_probabilities(grid, theta_i, 0.0);
  const std::vector<double> r = Huang2022(reference).bin_probabilities(grid, theta_i, 0.0);
  const std::size_t bins = 24 * 36;
  ASSERT_EQ(q.size(), 4 * bins);
  for (int lobe = 0; lobe < 4; ++lobe) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t b = lobe * bins; b < (lobe + 1) * bins; ++b) {
      if (r[b] * photons < 10.0) continue;
      sum += (q[b] - r[b]) * (q[b] - r[b]) / (r[b] / photons);
      ++n;
    }
    ASSERT_GT(n, 0) << "lobe " << lobe;
    std::printf("lobe %d: mean squared quadrature error / simulated variance %.4f (%d bins)\n", lobe, sum / n, n);
    EXPECT_LT(sum / n, lobe == 3 ? 1e-3 : 0.01) << "lobe " << lobe;
  }
}
