// huang2022's default quadrature (quadrature_points=auto) against the noise
// of the default atlas's simulations (configs/atlas.yaml: 24 x 36 bins, 300k
// photons): on its white ggx 0.3 fiber (e 0.85, tilt 3 deg) and on a dark
// one (sigma_a 1 and 2 per radius), at theta_i 45 deg, against 2^25
// points (at least 3x what auto takes here), the mean over bins with p N >=
// 10 of (bin error)^2 / ((p2 - p^2) / N), the simulated bin's variance (its
// photons carry their attenuation as weight, SPEC s4; p2, the second moment
// of their weights, is the bin at twice the absorption; p on the white
// fiber), is below 0.01 for R, TT
// and TRT (an RMS error below 0.1 standard errors, auto's target; the
// reference's own error included) and below 1e-3 for p >= 3 (its M_p
// integrated per theta bin). auto sizes the quadrature from its pilot's
// estimate of its own error: an estimate 4x too small (points / 4) fails
// both fibers' bounds, and sizing for p / N, the standard error of
// unweighted photons, fails the dark fiber's (p / N overstates its standard
// errors several times).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "analytic/huang2022.h"
#include "common/bin_grid.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

namespace {

void expect_a_tenth_of_the_atlas_noise(const std::vector<double>& sigma_a) {
  Huang2022Params p;
  ASSERT_EQ(p.quadrature_points, kAutoQuadraturePoints);
  ASSERT_EQ(p.quadrature_photons, 300000.0);
  p.sigma_a = sigma_a;
  p.roughness = 0.3;
  p.eccentricity = 0.85;
  p.tilt = deg_to_rad(3.0);
  Huang2022Params reference = p;
  reference.quadrature_points = 1L << 25;
  const BinGrid grid = BinGrid::make(24, 36, ThetaBinning::Uniform);
  const double theta_i = deg_to_rad(45.0), photons = 300000.0;
  const std::vector<double> q = Huang2022(p).bin_probabilities(grid, theta_i, 0.0);
  const std::vector<double> r = Huang2022(reference).bin_probabilities(grid, theta_i, 0.0);
  Huang2022Params doubled = reference;
  for (double& s : doubled.sigma_a) s *= 2.0;
  doubled.quadrature_points = 1L << 22;
  const std::vector<double> r2 = Huang2022(doubled).bin_probabilities(grid, theta_i, 0.0);
  const std::size_t bins = 24 * 36, C = sigma_a.size();
  ASSERT_EQ(q.size(), 4 * bins * C);
  for (std::size_t c = 0; c < C; ++c)
    for (int lobe = 0; lobe < 4; ++lobe) {
      double sum = 0.0;
      int n = 0;
      for (std::size_t b = lobe * bins; b < (lobe + 1) * bins; ++b) {
        const double x = q[b * C + c], y = r[b * C + c], y2 = r2[b * C + c];
        if (y * photons < 10.0) continue;
        sum += (x - y) * (x - y) / ((y2 - y * y) / photons);
        ++n;
      }
      if (n == 0) {  // a dark channel's TRT and p >= 3 may hold no bin of 10 photons' weight
        EXPECT_TRUE(lobe >= 2 && sigma_a[c] > 0.0) << "channel " << c << " lobe " << lobe;
        continue;
      }
      std::printf("channel %zu lobe %d: mean squared quadrature error / simulated variance %.4f (%d bins)\n", c, lobe,
                  sum / n, n);
      EXPECT_LT(sum / n, lobe == 3 ? 1e-3 : 0.01) << "channel " << c << " lobe " << lobe;
    }
}

}  // namespace

TEST(Huang2022, AutoQuadratureIsATenthOfTheAtlasNoiseOnAWhiteFiber) { expect_a_tenth_of_the_atlas_noise({0.0}); }

TEST(Huang2022, AutoQuadratureIsATenthOfTheAtlasNoiseOnADarkFiber) {
  expect_a_tenth_of_the_atlas_noise({1.0, 2.0});
}
