// A fiber with microfacet roughness (`roughness: {model: beckmann |
// ggx, alpha: A, masking: none | smith_g1}`) traced whole:
// - alpha -> 0 is the smooth fiber: phi histograms per lobe against the exact
//   smooth cylinder (SPEC s7, analytic/smooth_cylinder), and on a tilted
//   fiber against the simulator's smooth model (two-sample chi-square);
// - white furnaces: without masking nothing is lost (exited + truncated = N,
//   lost exactly 0); with masking the lost weight grows with alpha;
// - the ledger exited + absorbed + truncated + lost = N with absorption, and
//   lost is absorbed along the path (less lost in a darker channel).
//
// Mutations run, each alone (statistic vs threshold):
// - the VNDF about the untilted normal (mean_normal returns
//   n.untilted_facing, or draw_normal handed {n0, n0}):
//   SmallAlphaOnATiltedFiberIsTheTiltedSmoothFiber, R lobe theta chi2 28313
//   over the 1 bin both runs fill (threshold 8.1, and >= 2 bins required;
//   TT and TRT share none), phi chi2 867 vs 272 (R), 1255 vs 152 (TT);
// - GGX stretch of w inverted (alpha 1e-4 acts as 1e4 at oblique w):
//   SmallAlphaIsTheSmoothCylinder, TRT+ chi2 500 vs 131 (and the tilted
//   test, TT theta 462 vs 20.8); GGX unstretch inverted: every test here;
// - no repeated events (truncated after the first inconsistent event):
//   WhiteFurnaceWithoutMaskingLosesNothing, truncated 0.025 (ggx 0.1) to
//   0.34 (ggx 0.6) vs 5e-3; inconsistent events killed as Lost instead:
//   absorbed 0.025 vs 0 (1e-12), and the same in the masking furnace;
// - masking applied without `masking: smith_g1` (masks() always true):
//   WhiteFurnaceWithoutMaskingLosesNothing, lost 0.039 to 0.53 vs exactly 0;
// - lost not booked (photon_life's losses.add removed) or not scored
//   (ExitScorer without score_lost): WhiteFurnaceWithMaskingLosesMoreWithAlpha,
//   absorbed 0.039 (ggx 0.1) vs 0 and lost 0 not growing;
// - lost not absorbed along the path (weight booked without exp(-sigma l)):
//   LedgerBalancesWithAbsorptionAndLost, lost equal in the three channels;
// - every refraction judged on the incident side (killed):
//   SmallAlphaIsTheSmoothCylinder (beckmann + smith_g1 loses the TT, TRT
//   lobes), LedgerBalances;
// - the masking factor not multiplied into the weight (only its removal
//   booked): caught here only by chance (absorbed 2.7e-4 at beckmann 0.1:
//   Tally::score_lost caps each photon's lost at 1 - kept, which hides the
//   double count); test_microfacet_masking's per-photon ledger catches it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic/smooth_cylinder.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

void make_microfacet(Settings& s, MicrofacetModel model, double alpha, Masking masking) {
  s.fiber.roughness = testing::microfacet(model, alpha, alpha, masking);
}

double sum_exited(const ResultFile& r, std::size_t k, int c) {
  double e = 0.0;
  for (int l = 0; l < r.lobes; ++l) e += r.exited[(k * r.lobes + l) * r.channels + c];
  return e;
}

struct Chi2 {
  double value = 0.0;
  int dof = 0;
};

// As test_smooth_circle_phi: bins with effective sample size >= 30 and exact
// probability >= 1e-9.
Chi2 phi_chi2(const ResultFile& r, int lobe, int c, const analytic::SmoothCylinderPrediction& exact) {
  std::vector<double> s2;
  const std::vector<double> s1 = testing::phi_marginal(r, 0, lobe, c, &s2);
  Chi2 out;
  for (int j = 0; j < r.grid.n_phi(); ++j) {
    const double p = exact.phi_bins[(static_cast<std::size_t>(lobe) * exact.n_phi + j) * exact.channels + c];
    if (s2[j] <= 0.0 || s1[j] * s1[j] / s2[j] < 30.0 || p < 1e-9) continue;
    const Estimate e = bin_estimate(s1[j], s2[j], r.photons[0]);
    out.value += (e.mean - p) * (e.mean - p) / (e.std_error * e.std_error);
    ++out.dof;
  }
  return out;
}

// Two-sample chi-square of two runs' marginals (S1, S2 per bin, N photons each).
Chi2 two_sample(const std::vector<double>& a1, const std::vector<double>& a2, std::uint64_t na,
                const std::vector<double>& b1, const std::vector<double>& b2, std::uint64_t nb) {
  Chi2 out;
  for (std::size_t j = 0; j < a1.size(); ++j) {
    if (a2[j] <= 0.0 || b2[j] <= 0.0 || a1[j] * a1[j] / a2[j] < 30.0 || b1[j] * b1[j] / b2[j] < 30.0)
      continue;
    const Estimate ea = bin_estimate(a1[j], a2[j], na), eb = bin_estimate(b1[j], b2[j], nb);
    const double var = ea.std_error * ea.std_error + eb.std_error * eb.std_error;
    out.value += (ea.mean - eb.mean) * (ea.mean - eb.mean) / var;
    ++out.dof;
  }
  return out;
}

// alpha = 1e-4: facet slopes of order 1e-4 rad, far below the 2-degree phi
// bins: the exact smooth cylinder's phi distribution per lobe and channel.
TEST(MicrofacetFiber, SmallAlphaIsTheSmoothCylinder) {
  const double theta_i_deg = 40.3;
  const auto exact = analytic::smooth_cylinder_prediction(1.55, deg_to_rad(theta_i_deg), {0.3, 1.0},
                                                          analytic::Absorption::Chord, 4, 180);
  for (MicrofacetModel model : {MicrofacetModel::GGX, MicrofacetModel::Beckmann}) {
    Settings s = testing::smooth_circle(theta_i_deg, 1000000);
    s.fiber.sigma_a = {0.3, 1.0};
    const Masking masking = model == MicrofacetModel::GGX ? Masking::None : Masking::SmithG1;
    make_microfacet(s, model, 1e-4, masking);
    const ResultFile r = testing::run(s);
    const char* name = model == MicrofacetModel::GGX ? "ggx" : "beckmann + smith_g1";
    for (int lobe = 0; lobe < 4; ++lobe)
      for (int c = 0; c < 2; ++c) {
        const Chi2 chi = phi_chi2(r, lobe, c, exact);
        std::printf("%s alpha 1e-4, lobe %d channel %d: chi2 %.1f over %d bins (threshold %.1f)\n",
                    name, lobe, c, chi.value, chi.dof, testing::chi2_threshold(chi.dof));
        ASSERT_GT(chi.dof, 10);
        EXPECT_LT(chi.value, testing::chi2_threshold(chi.dof)) << name << " lobe " << lobe << " channel " << c;
      }
    // Nearly every photon on the specular cone's theta bin (SPEC s10: 40.3 is
    // no bin edge). GGX's slope tail falls only as alpha^2 / tan^2 theta_m:
    // about 1e-4 of its R light leaves the 2-degree bin even at alpha 1e-4.
    const int specular = r.grid.theta_bin(-deg_to_rad(theta_i_deg));
    const std::vector<double> theta = testing::theta_marginal(r, 0, 0, 0);
    double all = 0.0;
    for (double w : theta) all += w;
    EXPECT_GT(theta[specular] / all, 1.0 - 1e-3) << name;
    // Masking at alpha 1e-4 removes of order (alpha tan theta)^2: nothing visible.
    EXPECT_LT(r.lost[0] / static_cast<double>(r.photons[0]), 1e-5) << name;
  }
}

// With a 3-degree tilt the R lobe sits near theta_r = -theta_i - 2 alpha' and
// TT, TRT move the other way: a microfacet fiber of alpha 1e-4 must put every
// lobe where the smooth tilted fiber does (theta and phi marginals).
TEST(MicrofacetFiber, SmallAlphaOnATiltedFiberIsTheTiltedSmoothFiber) {
  Settings smooth = testing::smooth_circle(30.3, 400000);
  smooth.fiber.scale_tilt = deg_to_rad(3.0);
  smooth.tally.n_theta = 180;
  Settings rough = smooth;
  rough.seed = 777;
  make_microfacet(rough, MicrofacetModel::GGX, 1e-4, Masking::None);
  const ResultFile a = testing::run(smooth), b = testing::run(rough);
  for (int lobe = 0; lobe < 3; ++lobe) {
    std::vector<double> a2, b2;
    const auto a1 = testing::theta_marginal(a, 0, lobe, 0, &a2);
    const auto b1 = testing::theta_marginal(b, 0, lobe, 0, &b2);
    const Chi2 t = two_sample(a1, a2, a.photons[0], b1, b2, b.photons[0]);
    const auto pa1 = testing::phi_marginal(a, 0, lobe, 0, &a2);
    const auto pb1 = testing::phi_marginal(b, 0, lobe, 0, &b2);
    const Chi2 p = two_sample(pa1, a2, a.photons[0], pb1, b2, b.photons[0]);
    std::printf("tilted, lobe %d: theta chi2 %.1f over %d bins, phi chi2 %.1f over %d bins\n", lobe,
                t.value, t.dof, p.value, p.dof);
    // A lobe moved whole leaves few bins both runs fill: that fails too.
    EXPECT_GE(t.dof, 2) << "theta, lobe " << lobe;
    EXPECT_LT(t.value, testing::chi2_threshold(t.dof)) << "theta, lobe " << lobe;
    EXPECT_GT(p.dof, 10) << "phi, lobe " << lobe;
    EXPECT_LT(p.value, testing::chi2_threshold(p.dof)) << "phi, lobe " << lobe;
  }
}

Settings rough_tilted_ellipse(MicrofacetModel model, double alpha, Masking masking) {
  Settings s = testing::smooth_circle(30.0, 100000);
  s.fiber.eccentricity = 0.85;
  s.fiber.scale_tilt = deg_to_rad(3.0);
  s.source.phi_i = {deg_to_rad(17.0)};
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  make_microfacet(s, model, alpha, masking);
  return s;
}

// White furnace, no masking: the consistency rule keeps every photon's
// weight, so exited + truncated = N and nothing is lost or absorbed.
TEST(MicrofacetFiber, WhiteFurnaceWithoutMaskingLosesNothing) {
  for (MicrofacetModel model : {MicrofacetModel::GGX, MicrofacetModel::Beckmann})
    for (double alpha : {0.1, 0.6}) {
      const ResultFile r = testing::run(rough_tilted_ellipse(model, alpha, Masking::None));
      const double N = static_cast<double>(r.photons[0]);
      const double exited = sum_exited(r, 0, 0);
      std::printf("%s alpha %.1f, no masking: exited %.6f truncated %.2e lost %.1e\n",
                  to_string(model).c_str(), alpha, exited / N, r.truncated[0] / N, r.lost[0] / N);
      EXPECT_EQ(r.lost[0], 0.0);
      EXPECT_NEAR(r.absorbed[0] / N, 0.0, 1e-12);
      EXPECT_NEAR((exited + r.truncated[0]) / N, 1.0, 1e-12);
      // Light guiding leaves a little weight inside (SPEC s5); it is small.
      EXPECT_LT(r.truncated[0] / N, 5e-3);
    }
}

// White furnace with masking: (1 - G1) of every event and the paths killed on
// the wrong side are lost; rougher facets mask more. The lost fractions of
// neighbouring alphas differ by far more than their Monte Carlo spread: each
// is a mean of per-photon losses x in [0, 1] over N photons, whose variance is
// at most E[x^2] <= E[x], so its standard error is at most sqrt(lost / N).
TEST(MicrofacetFiber, WhiteFurnaceWithMaskingLosesMoreWithAlpha) {
  for (MicrofacetModel model : {MicrofacetModel::GGX, MicrofacetModel::Beckmann}) {
    double previous = 0.0;
    for (double alpha : {0.1, 0.3, 0.6}) {
      const ResultFile r = testing::run(rough_tilted_ellipse(model, alpha, Masking::SmithG1));
      const double N = static_cast<double>(r.photons[0]);
      const double exited = sum_exited(r, 0, 0), lost = r.lost[0] / N;
      std::printf("%s alpha %.1f, smith_g1: exited %.6f truncated %.2e lost %.6f\n",
                  to_string(model).c_str(), alpha, exited / N, r.truncated[0] / N, lost);
      EXPECT_NEAR(r.absorbed[0] / N, 0.0, 1e-12);
      EXPECT_NEAR((exited + r.truncated[0] + r.lost[0]) / N, 1.0, 1e-12);
      EXPECT_GT(lost, previous + 5.0 * std::sqrt(lost / N)) << to_string(model) << " alpha " << alpha;
      previous = lost;
    }
  }
}

// The ledger with absorption: every channel balances, and weight removed by
// masking after a stretch inside is absorbed along that stretch first, so a
// darker channel loses less (sigma_a 0 loses the most).
TEST(MicrofacetFiber, LedgerBalancesWithAbsorptionAndLost) {
  Settings s = rough_tilted_ellipse(MicrofacetModel::GGX, 0.3, Masking::SmithG1);
  s.fiber.sigma_a = {0.0, 0.5, 2.0};
  const ResultFile r = testing::run(s);
  const double N = static_cast<double>(r.photons[0]);
  for (int c = 0; c < 3; ++c) {
    const double total = sum_exited(r, 0, c) + r.absorbed[c] + r.truncated[c] + r.lost[c];
    EXPECT_NEAR(total / N, 1.0, 1e-12) << "channel " << c;
    EXPECT_GT(r.lost[c], 0.0);
  }
  EXPECT_NEAR(r.absorbed[0] / N, 0.0, 1e-12);
  EXPECT_GT(r.absorbed[1], 0.0);
  EXPECT_GT(r.lost[0], r.lost[1]);
  EXPECT_GT(r.lost[1], r.lost[2]);
  // The histogram holds exactly what the ledger says exited.
  for (int c = 0; c < 3; ++c) {
    double binned = 0.0;
    for (std::size_t i = c; i < r.weight_sum.size(); i += 3) binned += r.weight_sum[i];
    EXPECT_NEAR(binned / N, sum_exited(r, 0, c) / N, 1e-12);
  }
}

}  // namespace
}  // namespace fiberlab::sim
