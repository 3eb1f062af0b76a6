// chiang2016 against the simulator (end to end: Monte Carlo, prediction
// from the result's config, the comparison's chi-square): a smooth white
// circle is Chiang's zero-roughness limit for R, TT and TRT, so those lobes
// are accepted bin by bin; its residual p >= 3 lobe is uniform in phi by
// construction (p_max = 3), so only its energy agrees.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic/chiang2016.h"
#include "compare_test_support.h"

namespace fiberlab::compare {
namespace {

TEST(Chiang2016VsSimulation, SmoothCircleIsTheZeroRoughnessLimit) {
  sim::Settings s = testing::circle(35.0, 1000000, fiberlab::roughness::Smooth{});
  s.tally.n_theta = 91;
  const sim::ResultFile r = testing::run(s);
  const analytic::ModelParameters p = testing::params(r, "chiang2016");
  EXPECT_EQ(p.as<analytic::Chiang2016Params>().beta_m, 0.0);  // smooth config -> the model's exact limit
  EXPECT_EQ(p.as<analytic::Chiang2016Params>().beta_n, 0.0);
  for (const auto& c : testing::compare_with(r, "chiang2016")) {
    std::printf("lobe %d: E_sim %.6f +- %.6f, E_model %.6f, chi2/dof %.3f (%d)\n", c.lobe, c.sim_energy,
                c.sim_error, c.model_energy, c.bins.per_dof(), c.bins.dof);
    EXPECT_LT(std::fabs(c.energy_z), 5.0) << c.lobe;
    if (c.lobe < 3) {
      ASSERT_TRUE(c.judged);
      EXPECT_LT(c.bins.per_dof(), testing::max_chi2_per_dof(c.bins.dof)) << c.lobe;
    } else {
      EXPECT_GT(c.bins.per_dof(), testing::max_chi2_per_dof(c.bins.dof)) << "residual is uniform in phi";
    }
  }
}

}  // namespace
}  // namespace fiberlab::compare
