// Fitting chiang2016's own parameters (beta_m, beta_n in [0, 1] and its
// scalar tilt alpha), with the table's ranges.
//
// Oracle: a synthetic result drawn from the model itself. For a white fiber
// every photon leaves with weight 1, so the histogram of N photons is a
// multinomial draw over the cells with the model's bin probabilities as
// cell probabilities (S1 = S2 = count). The truth is then known exactly and
// is a point of the model, so a correct fit with correct errors lands
// within 3 reported standard errors of it (probability 0.997 per parameter;
// fixed seed, so deterministic) and its chi2 follows chi2(dof): the
// threshold is SPEC s10's n + 5 sqrt(2n) (testing::max_chi2_per_dof).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "analytic/chiang2016.h"
#include "common/error.h"
#include "compare/fit.h"
#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

// A result with the layout of `s` whose tallies are a multinomial draw of
// `photons` photons per incident direction from `model` (white fiber).
sim::ResultFile synthetic_result(const analytic::ModelParameters& truth, std::uint64_t photons, std::uint64_t seed) {
  sim::Settings s = testing::circle(25.0, 4096, fiberlab::roughness::Smooth{});  // the layout only
  s.source.theta_i = {deg_to_rad(25.0), deg_to_rad(55.0)};
  s.tally.n_theta = 45;
  s.tally.n_phi = 72;
  sim::ResultFile r = testing::run(s);
  const auto bins = predict_result(*make_model("chiang2016", truth), r);
  std::mt19937_64 rng(seed);
  std::fill(r.exited.begin(), r.exited.end(), 0.0);
  std::fill(r.absorbed.begin(), r.absorbed.end(), 0.0);
  std::fill(r.truncated.begin(), r.truncated.end(), 0.0);
  const std::size_t cells = r.bin_cells(), per_lobe = cells / r.lobes;
  for (std::size_t k = 0; k < r.configs(); ++k) {
    r.photons[k] = photons;
    // Multinomial by successive binomials: cell b gets Binomial(remaining,
    // p_b / (probability not yet assigned)).
    std::uint64_t left = photons;
    double mass_left = 1.0;
    for (std::size_t b = 0; b < cells; ++b) {
      const double p = std::clamp(bins[k][b] / std::max(mass_left, 1e-300), 0.0, 1.0);
      const std::uint64_t n = left == 0 || p <= 0.0 ? 0 : std::binomial_distribution<std::uint64_t>(left, p)(rng);
      left -= n;
      mass_left -= bins[k][b];
      r.weight_sum[k * cells + b] = static_cast<double>(n);
      r.weight_sq_sum[k * cells + b] = static_cast<double>(n);
      r.count[k * cells + b] = n;  // one channel: cells are (lobe, theta, phi)
      r.exited[k * r.lobes + b / per_lobe] += static_cast<double>(n);
    }
    r.truncated[k] = static_cast<double>(left);  // the model's mass outside the sphere (rounding)
  }
  return r;
}

// chiang2016's table defaults for a white fiber (one channel).
analytic::ModelParameters white_chiang() {
  analytic::ModelParameters p = params_for(sim::testing::smooth_circle(25.0, 1), parse_model_spec("chiang2016"), {});
  p.as<analytic::Chiang2016Params>().sigma_a = {0.0};
  return p;
}

TEST(FitChiang2016, RecoversBetaMBetaNAndAlphaFromItsOwnDraw) {
  analytic::ModelParameters truth = white_chiang();
  truth.as<analytic::Chiang2016Params>().beta_m = 0.35;
  truth.as<analytic::Chiang2016Params>().beta_n = 0.45;
  truth.as<analytic::Chiang2016Params>().alpha = deg_to_rad(2.0);
  const sim::ResultFile r = synthetic_result(truth, 2000000, 2016);

  analytic::ModelParameters start = truth;
  start.as<analytic::Chiang2016Params>().beta_m = 0.2;
  start.as<analytic::Chiang2016Params>().beta_n = 0.3;
  start.as<analytic::Chiang2016Params>().alpha = 0.0;
  const FitResult f = fit_model(r, "chiang2016", start, {"beta_m", "beta_n", "alpha"});
  const double want[3] = {0.35, 0.45, 2.0};
  for (int j = 0; j < 3; ++j) {
    std::printf("%s: %.4g -> %.5f +- %.5f (truth %.4g)\n", f.keys[j].c_str(), f.start[j], f.value[j], f.error[j],
                want[j]);
    EXPECT_NEAR(f.value[j], want[j], 3.0 * f.error[j]) << f.keys[j];
    EXPECT_FALSE(f.at_bound[j]) << f.keys[j];
    EXPECT_GT(f.error[j], 0.0) << f.keys[j];
  }
  std::printf("chi2/dof %.3f -> %.4f (%d dof), %d iterations\n", f.chi2_start / f.dof, f.per_dof(), f.dof,
              f.iterations);
  EXPECT_TRUE(f.converged);
  EXPECT_LT(f.per_dof(), testing::max_chi2_per_dof(f.dof));
  EXPECT_GT(f.chi2_start / f.dof, 10.0);  // the start was visibly wrong
  // The data pin the roughness down (relative error below 1%).
  EXPECT_LT(f.error[0], 0.0035);
  EXPECT_LT(f.error[1], 0.0045);
}

// The fit keeps to the table's ranges: a start outside is pulled in, a
// truth at the edge is reached from inside and flagged.
TEST(FitChiang2016, StaysInsideTheTablesRange) {
  analytic::ModelParameters truth = white_chiang();
  truth.as<analytic::Chiang2016Params>().beta_m = 0.3;
  truth.as<analytic::Chiang2016Params>().beta_n = 1.0;  // the upper end of [0, 1]
  const sim::ResultFile r = synthetic_result(truth, 200000, 7);
  analytic::ModelParameters start = truth;
  start.as<analytic::Chiang2016Params>().beta_n = 0.7;
  const FitResult f = fit_model(r, "chiang2016", start, {"beta_n"});
  std::printf("beta_n: 0.7 -> %.5f +- %.5f, at bound %d\n", f.value[0], f.error[0], int(f.at_bound[0]));
  EXPECT_LE(f.value[0], 1.0);
  EXPECT_NEAR(f.value[0], 1.0, std::max(3.0 * f.error[0], 1e-6));
}

TEST(FitChiang2016, FreeKeysAndRangesComeFromTheTables) {
  EXPECT_EQ(free_fit_keys("chiang2016"), (std::vector<std::string>{"beta_m", "beta_n", "alpha"}));
  EXPECT_EQ(free_fit_keys("deon2011"), (std::vector<std::string>{"beta_long", "beta_azim", "scale_tilt"}));
  EXPECT_TRUE(free_fit_keys("exact").empty());
  EXPECT_EQ(fit_range("chiang2016", "beta_m"), (std::pair<double, double>{0.0, 1.0}));
  EXPECT_EQ(fit_range("chiang2016", "beta_n"), (std::pair<double, double>{0.0, 1.0}));
  EXPECT_GT(fit_range("exact", "eta").first, 1.0);
  EXPECT_NO_THROW(check_fit_key("chiang2016", "alpha"));  // its scalar tilt
  EXPECT_THROW(check_fit_key("chiang2016", "scale_tilt"), Error);
  EXPECT_THROW(check_fit_key("chiang2016", "beta_m[1]"), Error);
  analytic::ModelParameters p = white_chiang();
  set_parameter("chiang2016", p, "alpha", 3.0);
  EXPECT_NEAR(p.as<analytic::Chiang2016Params>().alpha, deg_to_rad(3.0), 1e-15);
  EXPECT_NEAR(get_parameter("chiang2016", p, "alpha"), 3.0, 1e-12);
}

}  // namespace
}  // namespace fiberlab::compare
