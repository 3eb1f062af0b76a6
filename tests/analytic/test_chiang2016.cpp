// Chiang et al. 2016 (analytic/chiang2016.h) against oracles: the paper's
// roughness mappings, the unit mass of the trimmed logistic and of M_p, the
// white furnace (exact in this model: pbrt's hair tests allow +-5% by Monte
// Carlo), the exact smooth cylinder at zero and small roughness (SPEC s8's
// lobe energies, chord absorption) and SPEC s7's tilt shifts.
// Each test names the mutation of the model it was checked to catch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "analytic/chiang2016.h"
#include "analytic/quadrature.h"
#include "analytic/smooth_cylinder.h"
#include "common/bin_grid.h"
#include "common/error.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

namespace {

Chiang2016Params white(double beta_m, double beta_n) {
  Chiang2016Params p;
  p.sigma_a = {0.0};
  p.beta_m = beta_m;
  p.beta_n = beta_n;
  return p;
}

// Sum of bin probabilities of one lobe and channel.
double lobe_sum(const std::vector<double>& b, const BinGrid& g, int lobe, int C, int c) {
  const std::size_t per = static_cast<std::size_t>(g.n_theta()) * g.n_phi();
  double s = 0.0;
  for (std::size_t k = 0; k < per; ++k) s += b[(lobe * per + k) * C + c];
  return s;
}

// Composite Gauss-Legendre of f over [a, b] with n panels of 8 points.
template <class F>
double integrate(F f, double a, double b, int n) {
  const GaussLegendre& gl = gauss_legendre(8);
  const double h = (b - a) / n;
  double s = 0.0;
  for (int k = 0; k < n; ++k)
    for (int q = 0; q < 8; ++q) s += 0.5 * h * gl.w[q] * f(a + (k + 0.5 + 0.5 * gl.x[q]) * h);
  return s;
}

}  // namespace

// Oracle: the paper's formulas evaluated by hand at beta = 0.3 and 1:
// v = (0.726 b + 0.812 b^2 + 3.7 b^20)^2, s = sqrt(pi/8)(0.265 b + 1.194 b^2 + 5.372 b^22).
// (Values at 0.3 and 1 pin every coefficient and exponent.)
TEST(Chiang2016, RoughnessMappingsAreThePapers) {
  EXPECT_NEAR(chiang2016::longitudinal_variance(0.3), 0.08461117, 1e-8);
  EXPECT_NEAR(chiang2016::longitudinal_variance(1.0), 27.436644, 1e-9);
  EXPECT_NEAR(chiang2016::logistic_scale(0.3), 0.11715981, 1e-8);
  EXPECT_NEAR(chiang2016::logistic_scale(1.0), 4.28069444, 1e-8);
  EXPECT_EQ(chiang2016::longitudinal_variance(0.0), 0.0);
  EXPECT_EQ(chiang2016::logistic_scale(0.0), 0.0);
}

// The trimmed logistic integrates to 1 over [-pi, pi] for every scale the
// mapping produces, and its closed-form cumulative agrees with quadrature
// and is periodic with unit step.
// Mutation tried and caught: dropping the trimming normalisation.
TEST(Chiang2016, TrimmedLogisticIsNormalised) {
  for (double beta_n : {0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0}) {
    const double s = chiang2016::logistic_scale(beta_n);
    const int n = std::max(64, static_cast<int>(std::ceil(2.0 * kPi / (0.2 * s))));
    const double total = integrate([&](double x) { return chiang2016::trimmed_logistic(x, s); }, -kPi, kPi, n);
    EXPECT_NEAR(total, 1.0, 1e-12) << "beta_n " << beta_n;
    for (double x : {-2.0, -0.3, 0.0, 0.1, 1.7}) {
      const double part = integrate([&](double y) { return chiang2016::trimmed_logistic(y, s); }, -kPi, x, n);
      EXPECT_NEAR(chiang2016::trimmed_logistic_cumulative(x, s), part, 1e-12) << beta_n << " " << x;
      EXPECT_NEAR(chiang2016::trimmed_logistic_cumulative(x + kTwoPi, s),
                  chiang2016::trimmed_logistic_cumulative(x, s) + 1.0, 1e-12);
      EXPECT_NEAR(chiang2016::trimmed_logistic_cumulative(x - 2 * kTwoPi, s),
                  chiang2016::trimmed_logistic_cumulative(x, s) - 2.0, 1e-12);
    }
  }
}

// White furnace (sigma_a = 0) through the bin probabilities: every lobe's M_p
// and N_p carry unit mass, sum_p A_p = 1, so the sum over the sphere is 1 to
// quadrature accuracy for beta_m, beta_n in {0.1 .. 0.9}, with and without tilt,
// including incidences where the tilt rotation passes the pole.
// Mutation tried and caught: the residual summing p > 3 instead of p >= 3
// (A_beyond(3) for A_beyond(2)). (Not a mutation: dropping |cos| past the
// pole; M_p depends on cos theta_i only through the even I0.)
TEST(Chiang2016, WhiteFurnaceOfBinProbabilities) {
  const BinGrid grid = BinGrid::make(36, 72, ThetaBinning::Uniform);
  const double kBetas[] = {0.1, 0.3, 0.5, 0.7, 0.9};
  for (double alpha_deg : {0.0, 10.0})
    for (double bm : kBetas)
      for (double bn : kBetas)
        for (double ti : {0.0, 30.0, 60.0, 85.0}) {
          Chiang2016Params p = white(bm, bn);
          p.alpha = deg_to_rad(alpha_deg);
          const Chiang2016 model(p);
          const std::vector<double> b = model.bin_probabilities(grid, deg_to_rad(ti), 0.0);
          const double total = std::accumulate(b.begin(), b.end(), 0.0);
          EXPECT_NEAR(total, 1.0, 1e-6) << "beta_m " << bm << " beta_n " << bn << " theta_i " << ti
                                        << " alpha " << alpha_deg;
        }
}

// White furnace through density() alone (the bin machinery is not used):
// per lobe, the integral over the sphere of the density. In the frame of
// the issue (pbrt's wo is our wi) each lobe's density is M_p(theta_r) cos
// theta_r times N_p(phi): the test checks that separability at other points
// and then integrates the two 1D factors by Gauss-Legendre.
// Oracle: 1 within 1e-6 (the issue asks 1e-3; measured <= 7e-8, from the
// kink of the wrapped logistic at beta_n = 0.9).
// Mutation tried and caught: density() building A_p and eta' from theta_r
// instead of theta_i (pbrt's frame the other way round).
TEST(Chiang2016, WhiteFurnaceOfDensity) {
  const double kBetas[] = {0.1, 0.5, 0.9};
  std::vector<double> d;
  for (double bm : kBetas)
    for (double bn : kBetas)
      for (double ti_deg : {0.0, 80.0}) {
        Chiang2016Params p = white(bm, bn);
        p.alpha = deg_to_rad(3.0);
        const Chiang2016 model(p);
        const double ti = deg_to_rad(ti_deg);
        double total = 0.0;
        for (int lobe = 0; lobe < 4; ++lobe) {
          const double t_star = std::clamp(-ti, -1.4, 1.4);
          const double f_star = lobe == 1 ? 3.0 : 0.1;
          auto dens = [&](double tr, double ph) {
            model.density(lobe, ti, 0.0, tr, ph, d);
            return d[0];
          };
          const double D = dens(t_star, f_star);
          ASSERT_GT(D, 0.0);
          for (double tr : {-1.0, -0.2, 0.3, 1.2})
            for (double ph : {-2.5, -0.5, 1.0, 2.9})
              EXPECT_NEAR(dens(tr, ph) * D, dens(tr, f_star) * dens(t_star, ph),
                          1e-9 * std::max(dens(tr, ph) * D, 1e-300))
                  << "lobe " << lobe << " at " << tr << ", " << ph;
          const double it = integrate([&](double tr) { return dens(tr, f_star); }, -kPi / 2, kPi / 2, 50);
          const double ip = integrate([&](double ph) { return dens(t_star, ph); }, -kPi, kPi, 40);
          total += it * ip / D;
        }
        EXPECT_NEAR(total, 1.0, 1e-6) << "beta_m " << bm << " beta_n " << bn << " theta_i " << ti_deg;
      }
}

// M_p normalisation: each lobe's mass over the theta bins equals its energy
// (1/2) int A_p dh for every roughness, every tilt rotation (up to 50 deg,
// past the pole at theta_i = 80 deg) and absorbing fibers.
// Mutation tried and caught: a window of 3 sqrt(v) instead of 12 about the peak.
TEST(Chiang2016, LongitudinalMassIsOne) {
  const BinGrid grid = BinGrid::make(45, 8, ThetaBinning::EqualArea);
  for (double bm : {0.02, 0.1, 0.4, 1.0})
    for (double alpha : {-6.0, 0.0, 12.5})
      for (double ti : {-80.0, 10.0, 80.0}) {
        Chiang2016Params p;
        p.sigma_a = {0.0, 0.5, 3.0};
        p.beta_m = bm;
        p.beta_n = 0.4;
        p.alpha = deg_to_rad(alpha);
        const Chiang2016 model(p);
        const std::vector<double> b = model.bin_probabilities(grid, deg_to_rad(ti), 0.0);
        const std::vector<double> e = model.lobe_energies(deg_to_rad(ti));
        for (int l = 0; l < 4; ++l)
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(lobe_sum(b, grid, l, 3, c), e[l * 3 + c], 1e-10 * std::max(1.0, e[l * 3 + c]))
                << "beta_m " << bm << " alpha " << alpha << " theta_i " << ti << " lobe " << l;
      }
}

// SPEC s8, smooth circular fiber, eta = 1.55, sigma_a = 0, scalar Fresnel:
// lobe energies R, TT, TRT, p >= 3 at theta_i = 0 and 60 deg. Chiang's A_p
// are the smooth cylinder's, so these hold at every roughness.
// Mutation tried and caught: the residual off by one order (as above).
TEST(Chiang2016, LobeEnergiesAreSpecSection8) {
  struct Row { double theta_deg, R, TT, TRT, rest; };
  const Row rows[] = {{0.0, 0.07496, 0.86179, 0.05567, 0.00758},
                      {60.0, 0.17347, 0.69735, 0.10201, 0.02717}};
  const BinGrid grid = BinGrid::make(18, 36, ThetaBinning::Uniform);
  for (const Row& r : rows)
    for (double beta : {0.0, 0.3}) {
      const Chiang2016 model(white(beta, beta));
      const std::vector<double> b = model.bin_probabilities(grid, deg_to_rad(r.theta_deg), 0.0);
      const double want[4] = {r.R, r.TT, r.TRT, r.rest};
      for (int l = 0; l < 4; ++l)
        EXPECT_NEAR(lobe_sum(b, grid, l, 1, 0), want[l], 6e-6)
            << "theta_i " << r.theta_deg << " beta " << beta << " lobe " << l;
    }
}

// Absorbing fiber: lobe energies equal the exact smooth cylinder's with chord
// absorption (SPEC s7, independent code path: analytic/smooth_cylinder).
// Mutation tried and caught: Absorption::Published (4 cos^2 gamma_t) for the chord.
TEST(Chiang2016, AbsorbingLobeEnergiesAreTheSmoothCylinders) {
  const std::vector<double> sigma_a{0.2, 0.8, 2.0};
  for (double ti_deg : {0.0, 35.0, 70.0}) {
    const double ti = deg_to_rad(ti_deg);
    const SmoothCylinderPrediction exact =
        smooth_cylinder_prediction(1.55, ti, sigma_a, Absorption::Chord, 4, 36, 1e-14, 400);
    Chiang2016Params p;
    p.sigma_a = sigma_a;
    p.beta_m = 0.25;
    p.beta_n = 0.35;
    p.alpha = deg_to_rad(2.0);
    const Chiang2016 model(p);
    const std::vector<double> e = model.lobe_energies(ti);
    const BinGrid grid = BinGrid::make(30, 36, ThetaBinning::Uniform);
    const std::vector<double> b = model.bin_probabilities(grid, ti, 0.0);
    for (int l = 0; l < 4; ++l)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(e[l * 3 + c], exact.energy[l * 3 + c], 1e-10) << ti_deg << " lobe " << l << " c " << c;
        EXPECT_NEAR(lobe_sum(b, grid, l, 3, c), exact.energy[l * 3 + c], 1e-9) << ti_deg << " lobe " << l;
      }
  }
}

// Zero roughness is the exact smooth cylinder, bin for bin (the delta
// limits of M_p and of the logistic), with absorption, for R, TT and TRT.
// Mutation tried and caught: the residual off by one order (its total).
TEST(Chiang2016, ZeroRoughnessIsTheSmoothCylinder) {
  const BinGrid grid = BinGrid::make(18, 72, ThetaBinning::Uniform);
  ExactParams mp;
  mp.sigma_a = {0.0, 0.6};
  mp.absorption = Absorption::Chord;
  const SmoothCylinder exact(mp);
  Chiang2016Params p;
  p.sigma_a = mp.sigma_a;
  p.beta_m = p.beta_n = 0.0;
  const Chiang2016 model(p);
  for (double ti : {5.0, 47.0, 83.0}) {
    const std::vector<double> a = model.bin_probabilities(grid, deg_to_rad(ti), 0.0);
    const std::vector<double> b = exact.bin_probabilities(grid, deg_to_rad(ti), 0.0);
    ASSERT_EQ(a.size(), b.size());
    // R, TT, TRT bin for bin; the residual p >= 3 is uniform in phi in this
    // model, so only its total matches.
    const std::size_t per_lobe = a.size() / 4;
    for (std::size_t k = 0; k < 3 * per_lobe; ++k) ASSERT_NEAR(a[k], b[k], 1e-12) << ti << " bin " << k;
    for (int c = 0; c < 2; ++c)
      EXPECT_NEAR(lobe_sum(a, grid, 3, 2, c), lobe_sum(b, grid, 3, 2, c), 1e-7) << ti;
  }
}

// Small roughness (beta_m = beta_n = 0.01: s = 0.0017 rad, sqrt(v) = 0.42
// deg) converges to the smooth cylinder: each lobe's phi histogram (36 bins)
// within 1e-3 per bin and the theta mass in the specular bin above 0.999.
// At this s the fine zones (40 s about each bin edge) leave coarse panels
// between them, so both node kinds are exercised.
// Mutations tried and caught: the logistic's mass deposited one bin off; the
// far (coarse) pieces dropped. (Not a mutation: depositing about -Phi, the
// h -> -h mirror image, which the average over h makes identical.)
TEST(Chiang2016, SmallRoughnessIsTheSmoothCylinder) {
  const BinGrid grid = BinGrid::make(6, 36, ThetaBinning::Uniform);  // centres +-15, 45, 75 deg
  ExactParams mp;
  mp.sigma_a = {0.3};
  mp.absorption = Absorption::Chord;
  Chiang2016Params p;
  p.sigma_a = mp.sigma_a;
  p.beta_m = p.beta_n = 0.01;
  const Chiang2016 model(p);
  for (double ti_deg : {15.0, 45.0, 75.0}) {
    const double ti = deg_to_rad(ti_deg);
    const std::vector<double> a = model.bin_probabilities(grid, ti, 0.0);
    const SmoothCylinderPrediction exact = smooth_cylinder_prediction(1.55, ti, mp.sigma_a, Absorption::Chord, 4, 36);
    const int i = grid.theta_bin(-ti);
    for (int l = 0; l < 4; ++l) {
      double in_bin = 0.0, worst = 0.0;
      for (int j = 0; j < 36; ++j) {
        const double x = a[(l * 6 + i) * 36 + j];
        in_bin += x;
        worst = std::max(worst, std::abs(x - exact.phi_bins[l * 36 + j]));
      }
      EXPECT_GT(in_bin, 0.999 * exact.energy[l]) << ti_deg << " lobe " << l;
      EXPECT_LT(worst, 1e-3) << ti_deg << " lobe " << l;
    }
  }
}

// SPEC s7's shifts for scale_tilt alpha: the lobes' theta_r centres move to
// -theta_i - 2 alpha (R), + alpha (TT), + 4 alpha (TRT); the residual stays.
// Measured as each lobe's mean theta_r over 1-degree bins at small beta_m.
// Mutations tried and caught: pbrt-v4's sign (R at -theta_i + 2 alpha); TT
// rotated by 2 alpha.
TEST(Chiang2016, TiltMovesLobeCentresAsSpecSection7) {
  const BinGrid grid = BinGrid::make(180, 4, ThetaBinning::Uniform);
  Chiang2016Params p = white(0.05, 0.3);
  p.alpha = deg_to_rad(3.0);
  const Chiang2016 model(p);
  const double ti = deg_to_rad(20.0);
  const std::vector<double> b = model.bin_probabilities(grid, ti, 0.0);
  const double want[4] = {-20.0 - 6.0, -20.0 + 3.0, -20.0 + 12.0, -20.0};
  for (int l = 0; l < 4; ++l) {
    double m0 = 0.0, m1 = 0.0;
    for (int i = 0; i < 180; ++i)
      for (int j = 0; j < 4; ++j) {
        const double x = b[(l * 180 + i) * 4 + j];
        m0 += x;
        m1 += x * rad_to_deg(0.5 * (grid.theta_edges[i] + grid.theta_edges[i + 1]));
      }
    EXPECT_NEAR(m1 / m0, want[l], 0.3) << "lobe " << l;
  }
}

// Quadrature convergence: doubling every node density changes no bin by more
// than 1e-12 (far below any Monte Carlo standard error), at the sharpest
// roughness users set and at the default.
// Mutation tried and caught: every piece over h with coarse pi/64 panels
// (the 2 s panels in the logistic's zones dropped).
TEST(Chiang2016, BinProbabilitiesConverged) {
  const BinGrid grid = BinGrid::make(90, 180, ThetaBinning::Uniform);
  for (double beta : {0.05, 0.3}) {
    Chiang2016Params p;
    p.sigma_a = {0.0, 0.4};
    p.beta_m = beta;
    p.beta_n = beta;
    p.alpha = deg_to_rad(2.0);
    Chiang2016 model(p);
    const std::vector<double> a = model.bin_probabilities(grid, deg_to_rad(37.0), 0.0);
    model.set_refinement(2.0);
    const std::vector<double> b = model.bin_probabilities(grid, deg_to_rad(37.0), 0.0);
    double worst = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::abs(a[k] - b[k]));
    EXPECT_LT(worst, 1e-12) << "beta " << beta;
  }
}

// The two evaluation paths agree: bin probabilities equal the integral of
// density() over the bin (2D Gauss-Legendre, 32 x 32 points per bin), at a
// roughness where the density is smooth on the bin scale, with absorption
// and tilt.
// Mutation tried and caught: density() using the R variance v for every lobe
// (TT's v/4 and TRT's 4v then differ between the two paths).
TEST(Chiang2016, BinsAreTheIntegralOfTheDensity) {
  Chiang2016Params p;
  p.sigma_a = {0.3, 1.2};
  p.beta_m = 0.5;
  p.beta_n = 0.5;
  p.alpha = deg_to_rad(4.0);
  const Chiang2016 model(p);
  const BinGrid grid = BinGrid::make(12, 12, ThetaBinning::Uniform);
  const double ti = deg_to_rad(25.0);
  const std::vector<double> b = model.bin_probabilities(grid, ti, 0.0);
  std::vector<double> d;
  const GaussLegendre& gl = gauss_legendre(8);
  for (int lobe = 0; lobe < 4; ++lobe)
    for (int i : {3, 6, 9})
      for (int j : {0, 7}) {
        const double t0 = grid.theta_edges[i], t1 = grid.theta_edges[i + 1];
        const double f0 = grid.phi_edges[j], f1 = grid.phi_edges[j + 1];
        double v[2] = {0.0, 0.0};
        constexpr int kPanels = 4;
        for (int a = 0; a < kPanels * 8; ++a)
          for (int e = 0; e < kPanels * 8; ++e) {
            const double ht = (t1 - t0) / kPanels, hf = (f1 - f0) / kPanels;
            const double tr = t0 + (a / 8 + 0.5 + 0.5 * gl.x[a % 8]) * ht;
            const double ph = f0 + (e / 8 + 0.5 + 0.5 * gl.x[e % 8]) * hf;
            model.density(lobe, ti, 0.0, tr, ph, d);
            for (int c = 0; c < 2; ++c) v[c] += 0.25 * ht * hf * gl.w[a % 8] * gl.w[e % 8] * d[c];
          }
        for (int c = 0; c < 2; ++c)
          EXPECT_NEAR(b[((lobe * 12 + i) * 12 + j) * 2 + c], v[c], 1e-7 * std::max(v[c], 1e-3))
              << "lobe " << lobe << " bin " << i << "," << j << " channel " << c;
      }
}

// The paper's per-lobe variances: the theta_r spread of R, TT, TRT and the
// residual is sqrt(v), sqrt(v)/2, 2 sqrt(v), 2 sqrt(v) (M_p is a Gaussian of
// variance v_p in theta_r for small v), measured on 0.5-degree bins with
// Sheppard's correction, within 3%.
// Mutation tried and caught: TT with v instead of v / 4.
TEST(Chiang2016, LobeWidthsAreThePapers) {
  const BinGrid grid = BinGrid::make(360, 2, ThetaBinning::Uniform);
  const Chiang2016 model(white(0.1, 0.3));
  const std::vector<double> b = model.bin_probabilities(grid, 0.0, 0.0);
  const double sv = rad_to_deg(std::sqrt(chiang2016::longitudinal_variance(0.1)));
  const double want[4] = {sv, 0.5 * sv, 2.0 * sv, 2.0 * sv};
  for (int l = 0; l < 4; ++l) {
    double m0 = 0.0, m1 = 0.0, m2 = 0.0;
    for (int i = 0; i < 360; ++i) {
      const double t = rad_to_deg(0.5 * (grid.theta_edges[i] + grid.theta_edges[i + 1]));
      const double x = b[(l * 360 + i) * 2] + b[(l * 360 + i) * 2 + 1];
      m0 += x, m1 += x * t, m2 += x * t * t;
    }
    const double var = m2 / m0 - (m1 / m0) * (m1 / m0) - 0.25 / 12.0;
    EXPECT_NEAR(std::sqrt(var), want[l], 0.03 * want[l]) << "lobe " << l;
  }
}

// Lobe merging: with 2 lobes the last one is TT + TRT + residual.
TEST(Chiang2016, FewerLobesSumTheHigherOrders) {
  Chiang2016Params p = white(0.3, 0.3);
  const std::vector<double> four = Chiang2016(p).lobe_energies(0.4);
  p.lobes = 2;
  const std::vector<double> two = Chiang2016(p).lobe_energies(0.4);
  EXPECT_DOUBLE_EQ(two[0], four[0]);
  EXPECT_NEAR(two[1], four[1] + four[2] + four[3], 1e-15);
}

// The inverses used for defaults from a simulation round-trip the mappings.
TEST(Chiang2016, InverseMappingsRoundTrip) {
  for (double b : {0.0, 0.01, 0.2, 0.5, 0.93, 1.0}) {
    EXPECT_NEAR(chiang2016::beta_m_for_width(std::sqrt(chiang2016::longitudinal_variance(b))), b, 1e-12);
    EXPECT_NEAR(chiang2016::beta_n_for_scale(chiang2016::logistic_scale(b)), b, 1e-12);
  }
  EXPECT_THROW(chiang2016::beta_m_for_width(6.0), Error);
  EXPECT_THROW(chiang2016::beta_n_for_scale(-1.0), Error);
}

TEST(Chiang2016, RejectsParametersOutOfRange) {
  auto make = [](auto edit) {
    Chiang2016Params p;
    edit(p);
    return Chiang2016(p);
  };
  EXPECT_THROW(make([](Chiang2016Params& p) { p.beta_m = 1.01; }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.beta_n = -0.1; }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.eta = 1.0; }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.alpha = deg_to_rad(45.0); }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.lobes = 5; }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.sigma_a = {}; }), Error);
  EXPECT_THROW(make([](Chiang2016Params& p) { p.sigma_a = {-1.0}; }), Error);
}
