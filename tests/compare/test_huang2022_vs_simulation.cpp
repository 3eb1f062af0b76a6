// huang2022 against the simulator (end to end: Monte Carlo, prediction from
// the result's config, the comparison's chi-square). Roughness 0 is the
// model's smooth limit, so a smooth elliptical fiber lit off its symmetry
// axes is an oracle for the model's geometry in fiberlab's frame (ellipse
// axes, entry points, chords, relative azimuth, projected width): R, TT and
// TRT are accepted bin by bin. With tilt, the paper's flux onto the tilted
// mesonormal (flux=mesonormal, the default) is off in energy, while the
// projected width's flux (flux=macro, the simulator's) is accepted.
// Mutations caught: the relative azimuth with the wrong sign (phi_i - phi_r:
// every lobe rejected); the ellipse's axes swapped in the entry point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic/huang2022.h"
#include "compare_test_support.h"

namespace fiberlab::compare {
namespace {

sim::Settings ellipse(double theta_i_deg, double tilt_deg) {
  sim::Settings s = testing::circle(theta_i_deg, 400000, fiberlab::roughness::Smooth{});
  s.fiber.eccentricity = 0.7;
  s.fiber.scale_tilt = deg_to_rad(tilt_deg);
  s.fiber.sigma_a = {0.3};
  s.source.phi_i = {deg_to_rad(30.0)};
  s.tally.n_theta = 91;
  s.tally.n_phi = 90;
  return s;
}

void expect_accepted(const std::vector<LobeComparison>& cs) {
  for (const auto& c : cs) {
    std::printf("lobe %d: E_sim %.6f +- %.6f, E_model %.6f, chi2/dof %.3f (%d)\n", c.lobe, c.sim_energy,
                c.sim_error, c.model_energy, c.bins.per_dof(), c.bins.dof);
    if (c.lobe == 3) continue;  // Cycles' residual: M_p and uniform phi, not the fiber's p >= 3
    ASSERT_TRUE(c.judged);
    EXPECT_LT(std::fabs(c.energy_z), 5.0) << c.lobe;
    EXPECT_LT(c.bins.per_dof(), testing::max_chi2_per_dof(c.bins.dof)) << c.lobe;
  }
}

TEST(Huang2022VsSimulation, SmoothEllipseIsTheZeroRoughnessLimit) {
  const sim::ResultFile r = testing::run(ellipse(40.0, 0.0));
  const analytic::ModelParameters p = testing::params(r, "huang2022", {"quadrature_points=262144"});
  EXPECT_EQ(p.as<analytic::Huang2022Params>().roughness, 0.0);  // smooth config -> the model's exact limit
  expect_accepted(testing::compare_with(r, "huang2022", {"quadrature_points=262144"}));
}

TEST(Huang2022VsSimulation, TiltedEllipseNeedsTheProjectedWidthsFlux) {
  // theta_i = -20 deg: the tilted normal faces the light all over the lit arc.
  const sim::ResultFile r = testing::run(ellipse(-20.0, 2.0));
  expect_accepted(testing::compare_with(r, "huang2022", {"quadrature_points=262144", "flux=macro"}));
  // The paper's flux gives wi.ns / wi.n0 of the light: TT off in energy.
  for (const auto& c : testing::compare_with(r, "huang2022", {"quadrature_points=262144"}))
    if (c.lobe == 1) {
      EXPECT_GT(c.energy_z, 5.0);
    }
}

}  // namespace
}  // namespace fiberlab::compare
