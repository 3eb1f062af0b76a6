// `compare` on designs where the model is exact (accepted) or deliberately
// wrong (rejected).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

namespace fs = std::filesystem;

void print(const LobeComparison& c) {
  std::printf("theta_i %.0f lobe %d: E_sim %.6f +- %.6f, E_model %.6f, chi2/dof %.3f (%d), "
              "theta %.3f (%d), phi %.3f (%d), L1 %.4f\n",
              rad_to_deg(c.theta_i), c.lobe, c.sim_energy, c.sim_error, c.model_energy,
              c.bins.per_dof(), c.bins.dof, c.theta_marginal.per_dof(), c.theta_marginal.dof,
              c.phi_marginal.per_dof(), c.phi_marginal.dof, c.l1);
}

// exit_blur on a circle without tilt against d'Eon with matching beta_long,
// beta_azim and chord absorption (SPEC s3): the simulated theta-marginal of
// lobe p is exactly M_p and the phi-marginal exactly N_p at theta_d =
// -theta_i. d'Eon evaluates N_p (and its attenuation) at theta_d =
// (theta_r - theta_i)/2 in each bin, so the model differs from the
// simulation at first order in theta_r + theta_i away from theta_i = 0
// (measured: theta_i = 21 deg, sigma_a = 1, beta_TT = 10 deg, 300k photons
// gives TT theta-marginal chi2/dof 16.7). Near theta_i = 0 the difference is
// of second order; at theta_i = 3 deg, betas 5-10 deg, sigma_a 0.2 / 0.6 and
// 300k photons it is below the noise, so the 2D chi-square and both
// marginals are judged (measured chi2/dof 0.8-1.2).
// r_fresnel=per_h: the simulator's R lobe has f per h (Eq. 14), not
// Eq. 12's half-angle Fresnel.
TEST(CompareModels, ExitBlurAcceptedByDeon) {
  sim::Settings s = testing::circle(3.0, 300000, fiberlab::roughness::ExitBlur{});
  s.fiber.sigma_a = {0.2, 0.6};
  sim::testing::roughness_of<fiberlab::roughness::ExitBlur>(s).beta_long = {deg_to_rad(5.0), deg_to_rad(7.0), deg_to_rad(10.0)};
  sim::testing::roughness_of<fiberlab::roughness::ExitBlur>(s).beta_azim = {deg_to_rad(12.0), deg_to_rad(20.0)};
  s.tally.n_theta = 45;
  s.tally.n_phi = 60;
  const sim::ResultFile r = testing::run(s);
  const auto rows = testing::compare_with(r, "deon2011", {"absorption=chord", "r_fresnel=per_h"});
  int judged = 0;
  for (const auto& c : rows) {
    print(c);
    if (!c.judged) continue;
    ++judged;
    EXPECT_LT(c.theta_marginal.per_dof(), testing::max_chi2_per_dof(c.theta_marginal.dof)) << c.lobe;
    EXPECT_LT(c.phi_marginal.per_dof(), testing::max_chi2_per_dof(c.phi_marginal.dof)) << c.lobe;
    EXPECT_LT(c.bins.per_dof(), testing::max_chi2_per_dof(c.bins.dof)) << c.lobe;
    EXPECT_LT(std::fabs(c.energy_z), 5.0) << c.lobe;
  }
  EXPECT_GE(judged, 7);  // 4 lobes x 2 channels, the last lobe may be faint
}

// A smooth circle against the exact model (SPEC s7-8), at two incidences.
TEST(CompareModels, SmoothCircleAcceptedByExact) {
  sim::Settings s = testing::circle(35.0, 1000000, fiberlab::roughness::Smooth{});
  s.source.theta_i = {deg_to_rad(35.0), deg_to_rad(71.0)};
  s.tally.n_theta = 91;
  const sim::ResultFile r = testing::run(s);
  for (const auto& c : testing::compare_with(r, "exact")) {
    print(c);
    ASSERT_TRUE(c.judged);
    EXPECT_LT(c.bins.per_dof(), testing::max_chi2_per_dof(c.bins.dof)) << c.lobe;
    EXPECT_LT(c.l1, 0.1);
  }
}

// The same data against a wrong index (1.45 instead of 1.55) is rejected
// with a chi-square far beyond any statistical fluctuation.
TEST(CompareModels, WrongEtaRejected) {
  sim::Settings s = testing::circle(35.0, 1000000, fiberlab::roughness::Smooth{});
  s.tally.n_theta = 91;
  const sim::ResultFile r = testing::run(s);
  for (const auto& c : testing::compare_with(r, "exact", {"eta=1.45"})) {
    print(c);
    EXPECT_GT(c.bins.per_dof(), 10.0 * testing::max_chi2_per_dof(c.bins.dof)) << c.lobe;
  }
}

int run_binary(const std::string& args) {
  const std::string cmd = std::string(FIBERLAB_BINARY) + " " + args + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The real program's exit status: 0 accepted, 1 rejected, 2 bad input.
TEST(CompareModels, ExitStatus) {
  sim::Settings s = testing::circle(35.0, 400000, fiberlab::roughness::Smooth{});
  s.tally.n_theta = 91;
  const fs::path dir = fs::temp_directory_path() / ("fiberlab_compare_exit_status_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "smooth.h5").string();
  sim::write_result(testing::run(s), path);
  EXPECT_EQ(run_binary("compare " + path + " --model exact"), 0);
  EXPECT_EQ(run_binary("compare " + path + " --model exact --set eta=1.45"), 1);
  EXPECT_EQ(run_binary("compare " + path + " --model nosuchmodel"), 2);
  EXPECT_EQ(run_binary("compare " + (dir / "missing.h5").string() + " --model exact"), 2);
  EXPECT_EQ(run_binary("compare " + path + " --model exact --set eta=0.5"), 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fiberlab::compare
