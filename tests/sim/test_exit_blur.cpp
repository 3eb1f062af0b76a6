// exit_blur on a circle without tilt (SPEC section 3): the theta-marginal of
// lobe p is exactly d'Eon's M_p(v_p, theta_i, theta_r) cos(theta_r).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

// d'Eon et al. 2011 Eq. 7, written out here from SPEC section 7 (not taken
// from analytic/): M_p = csch(1/v)/(2v) exp(-sin ti sin tr / v) I0(cos ti cos tr / v).
// Direct evaluation is safe for the v used here (1/v <= 150: no overflow).
double deon_mp(double v, double ti, double tr) {
  return 1.0 / (std::sinh(1.0 / v) * 2.0 * v) * std::exp(-std::sin(ti) * std::sin(tr) / v) *
         std::cyl_bessel_i(0.0, std::cos(ti) * std::cos(tr) / v);
}

// Probability of theta_r in [lo, hi]: integral of M_p cos(theta_r), Simpson's rule.
double mp_bin_probability(double v, double ti, double lo, double hi) {
  const int n = 400;
  const double h = (hi - lo) / n;
  double s = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double t = lo + k * h;
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    s += w * deon_mp(v, ti, t) * std::cos(t);
  }
  return s * h / 3.0;
}

// Multinomial chi-square of one lobe's theta-marginal against M_p(beta^2),
// over the bins expecting >= 30 photons: chi-square with bins - 1 degrees of
// freedom when M_p is right. White fiber: weights are 1, so S1 = counts.
struct MarginalChi2 {
  double chi2 = 0.0, expected_fraction = 0.0;
  int dof = -1;
};
MarginalChi2 theta_marginal_vs_mp(const ResultFile& r, int lobe, double theta_i, double beta) {
  const std::vector<double> m = testing::theta_marginal(r, 0, lobe, 0);
  double n_lobe = 0.0, expected_total = 0.0;
  for (double x : m) n_lobe += x;
  MarginalChi2 out;
  for (int i = 0; i < r.grid.n_theta(); ++i) {
    const double e = n_lobe * mp_bin_probability(beta * beta, theta_i, r.grid.theta_edges[i],
                                                  r.grid.theta_edges[i + 1]);
    if (e < 30.0) continue;
    out.chi2 += (m[i] - e) * (m[i] - e) / e;
    expected_total += e;
    ++out.dof;
  }
  out.expected_fraction = expected_total / n_lobe;
  return out;
}

Settings exit_blur_circle(std::vector<double> beta_long_deg) {
  Settings s = testing::smooth_circle(35.0, 1000000);
  roughness::ExitBlur blur;
  blur.beta_long.clear();
  for (double b : beta_long_deg) blur.beta_long.push_back(deg_to_rad(b));
  blur.beta_azim = {deg_to_rad(10.0)};
  s.fiber.roughness = blur;
  s.tally.n_theta = 180;
  s.tally.n_phi = 8;
  return s;
}

TEST(ExitBlur, ThetaMarginalIsDeonMp) {
  const Settings s = exit_blur_circle({6.0, 12.0, 20.0});
  const ResultFile r = testing::run(s);
  for (int lobe = 0; lobe < 3; ++lobe) {
    const double beta = std::get<roughness::ExitBlur>(s.fiber.roughness).beta_long[lobe];
    const MarginalChi2 c = theta_marginal_vs_mp(r, lobe, deg_to_rad(35.0), beta);
    std::printf("lobe %d, beta %.0f deg: chi2 %.1f over %d dof (threshold %.1f)\n", lobe,
                rad_to_deg(beta), c.chi2, c.dof, testing::chi2_threshold(c.dof));
    ASSERT_GT(c.dof, 10);
    EXPECT_GT(c.expected_fraction, 0.99);  // the tails left out are small
    EXPECT_LT(c.chi2, testing::chi2_threshold(c.dof)) << "lobe " << lobe;
  }
}

// The same test must reject a wrong width: M_p at 1.1 beta fails.
TEST(ExitBlur, ChiSquareRejectsWrongWidth) {
  const ResultFile r = testing::run(exit_blur_circle({10.0}));
  const MarginalChi2 c = theta_marginal_vs_mp(r, 1, deg_to_rad(35.0), 1.1 * deg_to_rad(10.0));
  EXPECT_GT(c.chi2, 3.0 * testing::chi2_threshold(c.dof));
}

}  // namespace
}  // namespace fiberlab::sim
