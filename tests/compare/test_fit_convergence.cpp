// The fit's stopping rules and outcomes (compare/fit.h) on data made from
// the model itself: a histogram whose every bin holds N times the model's
// probability at known parameters (weights 1, so the bin's variance is its
// count), without noise. The truth is then the exact minimum (chi2 = 0), so
// a fit from elsewhere must end there: within a small part of one standard
// error of the truth (the errors are those of N photons). That is the
// oracle. Also: a fit cut by the iteration cap says so, and a fit whose
// optimum lies outside the range ends at a bound and says so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "compare/fit.h"
#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

// A result with `r`'s settings and grid whose bins are N times the model's
// probabilities at `truth` (weights 1: weight_sum = weight_sq_sum = count).
sim::ResultFile synthetic(sim::ResultFile r, const std::string& model, const analytic::ModelParameters& truth,
                          std::uint64_t photons) {
  const auto m = make_model(model, truth);
  const std::vector<std::vector<double>> p = predict_result(*m, r);
  for (std::size_t k = 0; k < r.configs(); ++k) {
    r.photons[k] = photons;
    const std::size_t per_k = r.bin_cells();
    for (std::size_t b = 0; b < per_k; ++b) {
      const double n = static_cast<double>(photons) * p[k][b];
      r.weight_sum[k * per_k + b] = n;
      r.weight_sq_sum[k * per_k + b] = n;
    }
  }
  const std::size_t cells = static_cast<std::size_t>(r.lobes) * r.grid.n_theta() * r.grid.n_phi();
  for (std::size_t k = 0; k < r.configs(); ++k)
    for (std::size_t b = 0; b < cells; ++b)
      r.count[k * cells + b] = static_cast<std::uint64_t>(std::llround(r.weight_sum[(k * cells + b) * r.channels]));
  return r;
}

sim::ResultFile template_result(double theta_i_deg, double tilt_deg) {
  sim::Settings s = testing::circle(theta_i_deg, 2000, fiberlab::roughness::Gaussian{});
  s.fiber.scale_tilt = deg_to_rad(tilt_deg);
  s.tally.n_theta = 24;
  s.tally.n_phi = 36;
  return testing::run(s);
}

void print(const char* what, const FitResult& f) {
  std::printf("%s: %s (%s), %d iterations, chi2/dof %.3g -> %.3g:", what, outcome_name(f.outcome),
              f.stop_reason.c_str(), f.iterations, f.chi2_start / f.dof, f.per_dof());
  for (std::size_t j = 0; j < f.keys.size(); ++j)
    std::printf(" %s %.5g -> %.5g +- %.3g", f.keys[j].c_str(), f.start[j], f.value[j], f.error[j]);
  std::printf("\n");
}

// d'Eon 2011's three free parameters (beta_long, beta_azim, scale_tilt) from
// a start 30-60% off. Mutation caught: a convergence flag never set
// (outcome). Not caught: the stopping tolerances 100x looser (a fit of
// noise-free data converges quadratically: the last steps are far inside
// any of them).
TEST(FitConvergence, RecoversDeonFromItsOwnBins) {
  const sim::ResultFile t = template_result(40.0, 3.0);
  analytic::ModelParameters truth = testing::params(t, "deon2011");
  set_parameter("deon2011", truth, "beta_long", 6.0);
  set_parameter("deon2011", truth, "beta_azim", 20.0);
  set_parameter("deon2011", truth, "scale_tilt", 2.5);
  const sim::ResultFile r = synthetic(t, "deon2011", truth, 300000);
  analytic::ModelParameters start = truth;
  set_parameter("deon2011", start, "beta_long", 9.0);
  set_parameter("deon2011", start, "beta_azim", 12.0);
  set_parameter("deon2011", start, "scale_tilt", 1.0);
  const FitResult f = fit_model(r, "deon2011", start, {"beta_long", "beta_azim", "scale_tilt"}, Options{}, 40);
  print("deon2011", f);
  EXPECT_EQ(f.outcome, FitOutcome::Converged);
  EXPECT_TRUE(f.converged);
  EXPECT_FALSE(f.stop_reason.empty());
  EXPECT_LT(f.iterations, 40);
  const double want[3] = {6.0, 20.0, 2.5};
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(f.value[j], want[j], 0.05 * f.error[j]) << f.keys[j];
  EXPECT_LT(f.per_dof(), 1e-3);
}

// huang2022 (its bins a fixed point set pushed through the model: piecewise
// constant in the parameters on a fine scale, 2^14 points here) recovers
// its roughness and tilt from its own bins at the same point count, within
// one standard error of 300k photons (the truth is the exact minimum, chi2
// = 0; the fit ends where the steps no longer resolve the model, measured
// 0.5 error off in roughness, 0.2 in tilt).
TEST(FitConvergence, RecoversHuangFromItsOwnBins) {
  const sim::ResultFile t = template_result(30.0, 3.0);
  analytic::ModelParameters truth = testing::params(t, "huang2022", {"quadrature_points=16384"});
  set_parameter("huang2022", truth, "roughness", 0.2);
  set_parameter("huang2022", truth, "tilt", 3.0);
  const sim::ResultFile r = synthetic(t, "huang2022", truth, 300000);
  analytic::ModelParameters start = truth;
  set_parameter("huang2022", start, "roughness", 0.3);
  set_parameter("huang2022", start, "tilt", 0.5);
  const FitResult f = fit_model(r, "huang2022", start, {"roughness", "tilt"}, Options{}, 20);
  print("huang2022", f);
  EXPECT_NE(f.outcome, FitOutcome::NotConverged);
  EXPECT_NEAR(f.value[0], 0.2, f.error[0]);
  EXPECT_NEAR(f.value[1], 3.0, f.error[1]);
}

// The cap: one iteration from far away cannot meet the stopping rules; the
// fit says it stopped at the cap. An optimum outside the range (the data's
// beta_long 0.6 deg, below d'Eon's fit range [1, 90]) ends on the bound,
// flagged. Mutations caught: converged set whenever a step was accepted;
// the outcome ignoring at_bound.
TEST(FitConvergence, SaysWhyItStopped) {
  const sim::ResultFile t = template_result(40.0, 0.0);
  analytic::ModelParameters truth = testing::params(t, "deon2011");
  set_parameter("deon2011", truth, "beta_long", 6.0);
  const sim::ResultFile r = synthetic(t, "deon2011", truth, 300000);
  analytic::ModelParameters start = truth;
  set_parameter("deon2011", start, "beta_long", 15.0);
  const FitResult capped = fit_model(r, "deon2011", start, {"beta_long"}, Options{}, 1);
  print("capped", capped);
  EXPECT_EQ(capped.outcome, FitOutcome::NotConverged);
  EXPECT_FALSE(capped.converged);
  EXPECT_NE(capped.stop_reason.find("iteration cap (1)"), std::string::npos) << capped.stop_reason;

  analytic::ModelParameters narrow = truth;
  set_parameter("deon2011", narrow, "beta_long", 0.6);
  const sim::ResultFile rn = synthetic(t, "deon2011", narrow, 300000);
  const FitResult bound = fit_model(rn, "deon2011", start, {"beta_long"}, Options{}, 40);
  print("bound", bound);
  EXPECT_EQ(bound.outcome, FitOutcome::AtBound);
  EXPECT_TRUE(bound.at_bound[0]);
  EXPECT_DOUBLE_EQ(bound.value[0], 1.0);
}

}  // namespace
}  // namespace fiberlab::compare
