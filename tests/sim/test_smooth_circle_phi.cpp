// A smooth absorbing circle's phi histogram, lobe by lobe,
// against the exact smooth-cylinder bin probabilities of SPEC section 7
// (chord-length absorption), which analytic/smooth_cylinder computes by
// integrating A(p, h) over h, with no simulator code.
#include <gtest/gtest.h>

#include <cstdio>

#include "analytic/smooth_cylinder.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

struct Chi2 {
  double value = 0.0;
  int dof = 0;
};

// Sum over bins with effective sample size S1^2/S2 >= 30 (SPEC section 10) of
// ((P_hat - P) / se)^2: chi-square with dof = number of bins if P is right.
// Bins whose exact probability is below 1e-9 are left out: with 2e6 photons
// such a bin is carried by a handful of strongly absorbed photons, and the
// sample variance of so skewed a sum understates its error (with one random
// stream a p >= 3 bin of P = 1.6e-10 read 5e-12 at an effective sample
// size of 31, a 160-sigma "deviation").
constexpr double kMinBinProbability = 1e-9;
Chi2 phi_chi2(const ResultFile& r, int lobe, int c,
              const analytic::SmoothCylinderPrediction& exact) {
  std::vector<double> s2;
  const std::vector<double> s1 = testing::phi_marginal(r, 0, lobe, c, &s2);
  Chi2 out;
  for (int j = 0; j < r.grid.n_phi(); ++j) {
    const double p = exact.phi_bins[(static_cast<std::size_t>(lobe) * exact.n_phi + j) * exact.channels + c];
    if (s2[j] <= 0.0 || s1[j] * s1[j] / s2[j] < 30.0 || p < kMinBinProbability) continue;
    const Estimate e = bin_estimate(s1[j], s2[j], r.photons[0]);
    out.value += (e.mean - p) * (e.mean - p) / (e.std_error * e.std_error);
    ++out.dof;
  }
  return out;
}

class SmoothAbsorbingCircle : public ::testing::TestWithParam<double> {};

TEST_P(SmoothAbsorbingCircle, PhiHistogramPerLobeMatchesExactCylinder) {
  const double theta_i_deg = GetParam();
  Settings s = testing::smooth_circle(theta_i_deg, 2000000);
  s.fiber.sigma_a = {0.3, 1.0};
  const ResultFile r = testing::run(s);
  const auto exact = analytic::smooth_cylinder_prediction(
      1.55, deg_to_rad(theta_i_deg), s.fiber.sigma_a, analytic::Absorption::Chord, 4, 180);
  for (int lobe = 0; lobe < 4; ++lobe)
    for (int c = 0; c < 2; ++c) {
      const Chi2 chi = phi_chi2(r, lobe, c, exact);
      std::printf("theta_i %.1f lobe %d channel %d: chi2 %.1f over %d bins (threshold %.1f)\n",
                  theta_i_deg, lobe, c, chi.value, chi.dof, testing::chi2_threshold(chi.dof));
      ASSERT_GT(chi.dof, 10);
      EXPECT_LT(chi.value, testing::chi2_threshold(chi.dof)) << "lobe " << lobe << " channel " << c;
    }
}

INSTANTIATE_TEST_SUITE_P(NormalAndOblique, SmoothAbsorbingCircle, ::testing::Values(0.7, 40.3));

// The same statistic tells the published Marschner/d'Eon attenuation (SPEC
// section 7's note) from the chord length the simulator follows.
TEST(SmoothAbsorbingCircleTeeth, PublishedAttenuationIsRejected) {
  Settings s = testing::smooth_circle(40.3, 2000000);
  s.fiber.sigma_a = {0.3, 1.0};
  const ResultFile r = testing::run(s);
  const auto published = analytic::smooth_cylinder_prediction(
      1.55, deg_to_rad(40.3), s.fiber.sigma_a, analytic::Absorption::Published, 4, 180);
  const Chi2 chi = phi_chi2(r, 1, 1, published);
  std::printf("published attenuation, TT channel 1: chi2 %.1f over %d bins\n", chi.value, chi.dof);
  EXPECT_GT(chi.value, 3.0 * testing::chi2_threshold(chi.dof));
}

}  // namespace
}  // namespace fiberlab::sim
