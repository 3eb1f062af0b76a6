// The exact smooth circular cylinder (SPEC s7) against known values (SPEC s8),
// textbook geometry (the Descartes rainbow angle) and an independent
// root-finding evaluation of N_p.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "analytic/smooth_cylinder.h"
#include "common/bin_grid.h"
#include "common/fresnel.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

namespace {

// SPEC section 8, smooth circle, eta 1.55, sigma_a 0, scalar Fresnel.
struct Known {
  double theta_deg, R, TT, TRT, rest;
};
constexpr Known kSpec8[] = {
    {0, 0.07496, 0.86179, 0.05567, 0.00758},
    {60, 0.17347, 0.69735, 0.10201, 0.02717},
    {80, 0.48968, 0.27305, 0.12312, 0.11415},
    {85, 0.68759, 0.10366, 0.06814, 0.14061},
};

}  // namespace

TEST(SmoothCylinder, LobeEnergiesMatchSpecSection8) {
  for (const Known& k : kSpec8) {
    for (double sign : {1.0, -1.0}) {
      const auto r = smooth_cylinder_prediction(1.55, sign * deg_to_rad(k.theta_deg), {0.0},
                                                Absorption::Published, 4, 180);
      EXPECT_NEAR(r.energy[0], k.R, 1e-4) << k.theta_deg;
      EXPECT_NEAR(r.energy[1], k.TT, 1e-4) << k.theta_deg;
      EXPECT_NEAR(r.energy[2], k.TRT, 1e-4) << k.theta_deg;
      EXPECT_NEAR(r.energy[3], k.rest, 1e-4) << k.theta_deg;
      EXPECT_NEAR(r.energy[0] + r.energy[1] + r.energy[2] + r.energy[3], 1.0, 1e-10);
      for (int l = 0; l < 4; ++l) {
        double s = 0.0;
        for (int j = 0; j < 180; ++j) s += r.phi_bins[l * 180 + j];
        EXPECT_NEAR(s, r.energy[l], 1e-12);
      }
    }
  }
}

TEST(SmoothCylinder, AbsorptionAgainstBruteForceMidpointRule) {
  // TT at theta_i = 30 deg with absorption, by a 2e5-point midpoint rule over h
  // written out here from SPEC s7 (chord and published lengths).
  const double eta = 1.55, theta = deg_to_rad(30.0), sigma = 0.7;
  const double eta_p = std::sqrt(eta * eta - std::sin(theta) * std::sin(theta)) / std::cos(theta);
  const double cos_tt = std::sqrt(1.0 - std::pow(std::sin(theta) / eta, 2));
  for (Absorption a : {Absorption::Chord, Absorption::Published}) {
    const int n = 200000;
    double e = 0.0;
    for (int k = 0; k < n; ++k) {
      const double h = -1.0 + (k + 0.5) * 2.0 / n;
      const double f = fresnel_dielectric(std::cos(theta) * std::sqrt(1.0 - h * h), eta);
      const double cgt = std::sqrt(1.0 - h * h / (eta_p * eta_p));
      const double len = a == Absorption::Chord ? 2.0 * cgt : 2.0 * (1.0 + (2.0 * cgt * cgt - 1.0));
      e += 0.5 * (2.0 / n) * (1.0 - f) * (1.0 - f) * std::exp(-sigma / cos_tt * len);
    }
    const auto r = smooth_cylinder_prediction(eta, theta, {sigma}, a, 4, 36);
    EXPECT_NEAR(r.energy[1], e, 2e-6);
  }
}

TEST(SmoothCylinder, TrtFoldAtDescartesAngleAndMergeAtEtaPrime2) {
  for (double eta_p : {1.2, 1.55, 1.8, 1.99}) {
    const double gc = cylinder::fold_gamma(2, eta_p);
    ASSERT_GT(gc, 0.0);
    EXPECT_NEAR(std::sin(gc) * std::sin(gc), (4.0 - eta_p * eta_p) / 3.0, 1e-12);
    // Independent: the extremum of Phi(2, .) on (0, pi/2) by a dense scan.
    double best = -1e9, best_g = 0.0;
    for (int k = 1; k < 200000; ++k) {
      const double g = k * (kPi / 2) / 200000;
      const double v = cylinder::Phi(2, g, eta_p);
      if (v > best) best = v, best_g = g;
    }
    EXPECT_NEAR(best_g, gc, 1e-4) << eta_p;
  }
  EXPECT_LT(cylinder::fold_gamma(2, 2.0), 0.0);
  EXPECT_LT(cylinder::fold_gamma(2, 2.5), 0.0);
  // The caustic bin stands out of the TRT phi distribution when it exists...
  const double theta = 0.0, eta = 1.55;
  const auto r = smooth_cylinder_prediction(eta, theta, {0.0}, Absorption::Published, 4, 360);
  const double phi_c = wrap_angle(cylinder::Phi(2, cylinder::fold_gamma(2, eta), eta));
  const int jc = cylinder::phi_bin(phi_c, 360);
  const double* trt = &r.phi_bins[2 * 360];
  EXPECT_GT(trt[jc], 2.0 * trt[(jc + 5) % 360]);
  EXPECT_GT(trt[jc], 2.0 * trt[(jc + 355) % 360]);
  // ...and TRT is smooth (no bin above 3x the mean of its neighbours) when eta' >= 2.
  const auto s = smooth_cylinder_prediction(2.2, 0.0, {0.0}, Absorption::Published, 4, 360);
  for (int j = 2; j < 358; ++j) {
    const double* t = &s.phi_bins[2 * 360];
    EXPECT_LT(t[j], 3.0 * 0.5 * (t[j - 2] + t[j + 2]) + 1e-12) << j;
  }
}

TEST(SmoothCylinder, BinsAgreeWithRootSumDensity) {
  // density() sums A / |2 dPhi/dh| over the roots (a different algorithm):
  // integrate it over bins away from caustics and compare.
  ExactParams p;
  p.sigma_a = {0.3};
  p.lobes = 4;
  const SmoothCylinder m(p);
  const double theta_i = deg_to_rad(25.0);
  const auto r = smooth_cylinder_prediction(p.eta, theta_i, p.sigma_a, p.absorption, 4, 90);
  std::vector<double> d;
  for (int lobe = 0; lobe < 3; ++lobe) {
    for (int j = 0; j < 90; j += 7) {
      const double a = -kPi + j * kTwoPi / 90, w = kTwoPi / 90;
      double s = 0.0;
      const int n = 400;
      for (int q = 0; q < n; ++q) {
        m.density(lobe, theta_i, 0.0, -theta_i, a + (q + 0.5) * w / n, d);
        s += d[0] * w / n;
      }
      const double want = r.phi_bins[lobe * 90 + j];
      if (lobe == 2) {
        const double phi_c = wrap_angle(cylinder::Phi(2, cylinder::fold_gamma(2, cylinder::eta_prime(p.eta, theta_i)),
                                                      cylinder::eta_prime(p.eta, theta_i)));
        if (std::abs(wrap_angle(a + w / 2 - phi_c)) < 3 * w || std::abs(wrap_angle(a + w / 2 + phi_c)) < 3 * w)
          continue;  // caustics: density infinite
      }
      EXPECT_NEAR(s, want, 2e-4 * want + 1e-9) << lobe << " " << j;
    }
  }
}

TEST(SmoothCylinder, FiniteAtTheEdges) {
  std::vector<double> a(3), t(3);
  for (double theta : {-kPi / 2, -1.5, 0.0, 1.5707, kPi / 2}) {
    const cylinder::Attenuation att(1.55, theta, {0.0, 1.0, 1e4}, Absorption::Chord);
    for (double g : {-kPi / 2, -1.0, 0.0, 1.0, kPi / 2}) {
      for (int p = 0; p < 6; ++p) {
        att.A(p, g, a.data());
        att.A_beyond(p, g, t.data());
        for (int c = 0; c < 3; ++c) {
          EXPECT_TRUE(std::isfinite(a[c]) && a[c] >= 0.0 && a[c] <= 1.0);
          EXPECT_TRUE(std::isfinite(t[c]) && t[c] >= 0.0 && t[c] <= 1.0);
        }
      }
    }
  }
  for (double ti : {-89.99, 89.99}) {
    const auto r = smooth_cylinder_prediction(1.55, deg_to_rad(ti), {0.0, 50.0}, Absorption::Published, 3, 180);
    for (double x : r.phi_bins) EXPECT_TRUE(std::isfinite(x) && x >= 0.0);
    EXPECT_NEAR(r.energy[0] + r.energy[2] + r.energy[4], 1.0, 1e-9);
  }
}
