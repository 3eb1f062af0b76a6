// Elliptical cross-section (SPEC section 2): symmetries that any correct
// tracer must show, tested with two-sample chi-squares on the histograms.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

// Two-sample chi-square between histograms a and b (same photon counts), bin
// by bin, over bins whose effective sample size S1^2/S2 is >= 30 in both
// (SPEC section 10). Returns {chi2, dof}.
std::pair<double, int> two_sample_chi2(const ResultFile& a, std::size_t ka, const ResultFile& b,
                                       std::size_t kb, bool mirror_b_phi) {
  double chi2 = 0.0;
  int dof = 0;
  const int T = a.grid.n_theta(), P = a.grid.n_phi();
  for (int l = 0; l < a.lobes; ++l)
    for (int i = 0; i < T; ++i)
      for (int j = 0; j < P; ++j) {
        const int jb = mirror_b_phi ? P - 1 - j : j;
        const double s1a = a.weight_sum[a.cell(ka, l, i, j, 0)], s2a = a.weight_sq_sum[a.cell(ka, l, i, j, 0)];
        const double s1b = b.weight_sum[b.cell(kb, l, i, jb, 0)], s2b = b.weight_sq_sum[b.cell(kb, l, i, jb, 0)];
        if (s2a <= 0 || s2b <= 0 || s1a * s1a / s2a < 30 || s1b * s1b / s2b < 30) continue;
        const Estimate ea = bin_estimate(s1a, s2a, a.photons[ka]);
        const Estimate eb = bin_estimate(s1b, s2b, b.photons[kb]);
        const double d = ea.mean - eb.mean;
        chi2 += d * d / (ea.std_error * ea.std_error + eb.std_error * eb.std_error);
        ++dof;
      }
  return {chi2, dof};
}

Settings rough_ellipse(double phi_i_deg, std::uint64_t seed) {
  Settings s = testing::smooth_circle(27.0, 400000);
  s.seed = seed;
  s.fiber.eccentricity = 0.85;
  s.fiber.sigma_a = {0.3};
  testing::make_rough(s, 8.0);
  s.source.phi_i = {deg_to_rad(phi_i_deg)};
  s.tally.n_theta = 30;
  s.tally.n_phi = 36;
  return s;
}

void expect_same_distribution(const ResultFile& a, const ResultFile& b, bool mirror,
                              const char* what) {
  const auto [chi2, dof] = two_sample_chi2(a, 0, b, 0, mirror);
  std::printf("%s: chi2 %.1f over %d bins (threshold %.1f)\n", what, chi2, dof,
              testing::chi2_threshold(dof));
  ASSERT_GT(dof, 50);
  EXPECT_LT(chi2, testing::chi2_threshold(dof)) << what;
}

// phi_i = 0 lights the ellipse along its major axis: the scattering is
// mirror-symmetric, phi -> -phi.
TEST(Ellipse, MirrorSymmetryAtPhiZero) {
  const ResultFile a = testing::run(rough_ellipse(0.0, 1));
  const ResultFile b = testing::run(rough_ellipse(0.0, 2));
  expect_same_distribution(a, b, /*mirror=*/true, "phi -> -phi at phi_i = 0");
}

// The ellipse is symmetric under a 180-degree turn: phi_i and phi_i + 180 deg
// give the same distribution of the relative azimuth.
TEST(Ellipse, HalfTurnSymmetryInPhiI) {
  const ResultFile a = testing::run(rough_ellipse(30.0, 3));
  const ResultFile b = testing::run(rough_ellipse(210.0, 4));
  expect_same_distribution(a, b, false, "phi_i 30 vs 210 deg");
}

// A circle does not care about phi_i: e = 1 at 0 and at 37 degrees agree.
TEST(Ellipse, CircleIgnoresPhiI) {
  Settings s0 = rough_ellipse(0.0, 5), s1 = rough_ellipse(37.0, 6);
  s0.fiber.eccentricity = s1.fiber.eccentricity = 1.0;
  expect_same_distribution(testing::run(s0), testing::run(s1), false, "circle phi_i 0 vs 37 deg");
}

// And the ellipse does care: the same test tells e = 0.85 at 0 and 90 deg apart.
TEST(Ellipse, EllipseDependsOnPhiI) {
  const ResultFile a = testing::run(rough_ellipse(0.0, 7));
  const ResultFile b = testing::run(rough_ellipse(90.0, 8));
  const auto [chi2, dof] = two_sample_chi2(a, 0, b, 0, false);
  std::printf("ellipse phi_i 0 vs 90 deg: chi2 %.1f over %d bins\n", chi2, dof);
  EXPECT_GT(chi2, 3.0 * testing::chi2_threshold(dof));
}

}  // namespace
}  // namespace fiberlab::sim
