// The medulla (docs/FUR.md) against oracles that use no simulator code:
// - a clear medulla (sigma_s = 0, eta_m = eta, the fiber's sigma_a) is no
//   medulla: the exact smooth cylinder of SPEC section 7 on a circle, and
//   a two-sample chi-square against the plain fiber on a rough tilted ellipse;
// - on a smooth circle with eta_m = eta every internal segment of a photon
//   at impact parameter h runs at distance |h| / eta' from the axis (SPEC
//   section 7), so it crosses the medulla along a chord of known length c(h)
//   and the photon that has not scattered yet follows the exact cylinder's
//   path. Per pass it escapes scattering with x = exp(-sigma_s c / cos
//   theta_t); with Fresnel f, P(scattered | h) = (1 - f)(1 - x) / (1 - f x),
//   and the unscattered lobe p carries A(p, h) x^p. Integrated over h by
//   quadrature here;
// - its first order, sigma_s times the mean chord through the medulla, is
//   (pi / 2) eta sigma_s k^2 at theta_i = 0 in closed form;
// - a white furnace (every sigma_a 0) with scattering, Fresnel at the
//   medulla, roughness, tilt and an ellipse loses nothing;
// - a vanishing medulla (k -> 0) changes nothing;
// - the Henyey-Greenstein sampler against its closed-form CDF, the frame it
//   turns in, and the inner ellipse's distances;
// - any number of threads gives the same bits.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "sim/life/medulla.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

Medulla medulla(double k, double sigma_s, std::vector<double> sigma_a, double g, double eta) {
  Medulla m;
  m.radius = k;
  m.sigma_s = sigma_s;
  m.sigma_a = std::move(sigma_a);
  m.g = g;
  m.eta = eta;
  return m;
}

// Unpolarised dielectric Fresnel reflectance (written here, not the project's).
double fresnel(double eta, double cos_i) {
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i)) / eta;
  if (sin_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// Energies on a smooth circle with a medulla of radius k, eta_m = eta: the
// unscattered lobes R, TT, TRT, p >= 3 and `scattered` (which is exact only
// where nothing is absorbed after a scattering: sigma_a = 0 everywhere).
// sa_cortex, sa_medulla: absorption in the cortex and in the medulla.
struct Energies {
  double lobe[4] = {0, 0, 0, 0};
  double scattered = 0.0;
};
Energies medulla_circle(double eta, double theta_i, double k, double sigma_s, double sa_cortex,
                        double sa_medulla) {
  const double st = std::sin(theta_i), ct = std::cos(theta_i);
  const double eta_p = std::sqrt(eta * eta - st * st) / ct;  // Bravais
  const double sin_tt = st / eta, cos_tt = std::sqrt(1.0 - sin_tt * sin_tt);
  Energies e;
  const int n = 400000;
  const double dh = 2.0 / n;
  for (int i = 0; i < n; ++i) {
    const double h = -1.0 + (i + 0.5) * dh;
    const double f = fresnel(eta, ct * std::sqrt(1.0 - h * h));
    const double b = std::abs(h) / eta_p;  // the internal ray's distance from the axis
    const double chord = 2.0 * std::sqrt(1.0 - b * b) / cos_tt;
    const double c = b < k ? 2.0 * std::sqrt(k * k - b * b) / cos_tt : 0.0;
    const double x = std::exp(-sigma_s * c);  // no scattering on one pass
    const double t = x * std::exp(-sa_cortex * (chord - c) - sa_medulla * c);
    e.lobe[0] += f;
    e.lobe[1] += (1 - f) * (1 - f) * t;
    e.lobe[2] += (1 - f) * (1 - f) * f * t * t;
    e.lobe[3] += (1 - f) * (1 - f) * f * f * t * t * t / (1.0 - f * t);
    e.scattered += (1 - f) * (1 - x) / (1 - f * x);
  }
  for (double& v : e.lobe) v *= 0.5 * dh;
  e.scattered *= 0.5 * dh;
  return e;
}

double z_score(const ResultFile& r, int lobe, int c, double expected) {
  const Estimate e = lobe_energy(r, 0, lobe, c);
  return (e.mean - expected) / e.std_error;
}

class MedullaCircle : public ::testing::TestWithParam<double> {};

// White: every lobe and `scattered` against the quadrature, within 5 sigma.
TEST_P(MedullaCircle, ScatteredAndUnscatteredEnergiesMatchChordQuadrature) {
  const double theta_i = deg_to_rad(GetParam());
  Settings s = testing::smooth_circle(GetParam(), 1000000);
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.fiber.medulla = medulla(0.55, 2.0, {0.0}, 0.7, 1.55);
  const ResultFile r = testing::run(s);
  ASSERT_EQ(r.lobes, 5);
  const Energies e = medulla_circle(1.55, theta_i, 0.55, 2.0, 0.0, 0.0);
  for (int l = 0; l < 4; ++l) {
    std::printf("theta_i %.1f lobe %d: z = %.2f (expected %.5f)\n", GetParam(), l,
                z_score(r, l, 0, e.lobe[l]), e.lobe[l]);
    EXPECT_LT(std::abs(z_score(r, l, 0, e.lobe[l])), 5.0) << "lobe " << l;
  }
  std::printf("theta_i %.1f scattered: z = %.2f (expected %.5f)\n", GetParam(),
              z_score(r, 4, 0, e.scattered), e.scattered);
  EXPECT_LT(std::abs(z_score(r, 4, 0, e.scattered)), 5.0);
}

// Absorbing cortex and medulla, each with its own sigma_a: the unscattered
// lobes split their path between the two.
TEST_P(MedullaCircle, UnscatteredLobesAbsorbInCortexAndMedullaSeparately) {
  const double theta_i = deg_to_rad(GetParam());
  Settings s = testing::smooth_circle(GetParam(), 1000000);
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.fiber.sigma_a = {0.3, 0.0};
  s.fiber.medulla = medulla(0.6, 1.0, {0.0, 1.5}, -0.3, 1.55);
  const ResultFile r = testing::run(s);
  const Energies e0 = medulla_circle(1.55, theta_i, 0.6, 1.0, 0.3, 0.0);
  const Energies e1 = medulla_circle(1.55, theta_i, 0.6, 1.0, 0.0, 1.5);
  for (int l = 0; l < 3; ++l) {
    EXPECT_LT(std::abs(z_score(r, l, 0, e0.lobe[l])), 5.0) << "lobe " << l << " channel 0";
    EXPECT_LT(std::abs(z_score(r, l, 1, e1.lobe[l])), 5.0) << "lobe " << l << " channel 1";
  }
}

INSTANTIATE_TEST_SUITE_P(NormalAndOblique, MedullaCircle, ::testing::Values(0.7, 40.3));

// First order in sigma_s: P(scattered) = sigma_s times the mean 3D chord
// through the medulla over h (each pass enters with the probability 1 - f
// that the expected number of passes, 1 / (1 - f), cancels); at theta_i = 0
// the chord at distance |h| / eta is 2 sqrt(k^2 - h^2 / eta^2), whose mean
// over h in (-1, 1) is (pi / 2) eta k^2. The second order is about
// -sigma_s c (1/2 + f / (1 - f)) relative: 0.3% here, below the 1% error.
TEST(MedullaSingleScattering, FirstOrderIsSigmaTimesMeanChord) {
  const double k = 0.5, sigma_s = 0.005, eta = 1.55;
  Settings s = testing::smooth_circle(0.0, 4000000);
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.fiber.medulla = medulla(k, sigma_s, {0.0}, 0.0, eta);
  const ResultFile r = testing::run(s);
  const double first_order = 0.5 * M_PI * eta * sigma_s * k * k;
  std::printf("scattered %.6f, first order %.6f, z = %.2f\n", lobe_energy(r, 0, 4, 0).mean,
              first_order, z_score(r, 4, 0, first_order));
  EXPECT_LT(std::abs(z_score(r, 4, 0, first_order)), 5.0);
}

// sigma_s = 0 and eta_m = eta: the exact absorbing cylinder, bin by bin in
// phi (as tests/sim/test_smooth_circle_phi.cpp for the plain fiber), and an
// empty `scattered` lobe.
TEST(ClearMedulla, SmoothCircleIsTheExactCylinder) {
  Settings s = testing::smooth_circle(40.3, 2000000);
  s.fiber.sigma_a = {0.3, 1.0};
  s.fiber.medulla = medulla(0.5, 0.0, {0.3, 1.0}, 0.0, 1.55);
  const ResultFile r = testing::run(s);
  const auto exact = analytic::smooth_cylinder_prediction(
      1.55, deg_to_rad(40.3), s.fiber.sigma_a, analytic::Absorption::Chord, 4, 180);
  for (int lobe = 0; lobe < 4; ++lobe)
    for (int c = 0; c < 2; ++c) {
      std::vector<double> s2;
      const std::vector<double> s1 = testing::phi_marginal(r, 0, lobe, c, &s2);
      double chi2 = 0.0;
      int dof = 0;
      for (int j = 0; j < r.grid.n_phi(); ++j) {
        const double p = exact.phi_bins[(static_cast<std::size_t>(lobe) * exact.n_phi + j) * 2 + c];
        if (s2[j] <= 0.0 || s1[j] * s1[j] / s2[j] < 30.0 || p < 1e-9) continue;
        const Estimate e = bin_estimate(s1[j], s2[j], r.photons[0]);
        chi2 += (e.mean - p) * (e.mean - p) / (e.std_error * e.std_error);
        ++dof;
      }
      ASSERT_GT(dof, 10);
      EXPECT_LT(chi2, testing::chi2_threshold(dof)) << "lobe " << lobe << " channel " << c;
    }
  for (int c = 0; c < 2; ++c) EXPECT_EQ(lobe_energy(r, 0, 4, c).mean, 0.0);
}

// The same on a rough, tilted, absorbing ellipse, against the plain fiber
// run with another seed: two-sample chi-square over each lobe's phi bins.
TEST(ClearMedulla, RoughTiltedEllipseEqualsThePlainFiber) {
  Settings plain = testing::smooth_circle(23.0, 1000000);
  plain.fiber.eccentricity = 0.75;
  plain.fiber.sigma_a = {0.4};
  plain.source.phi_i = {deg_to_rad(35.0)};
  plain.tally.n_theta = 18;
  plain.tally.n_phi = 72;
  testing::make_rough(plain, 6.0, 3.0);
  Settings clear = plain;
  clear.seed = 777;
  clear.fiber.medulla = medulla(0.6, 0.0, {0.4}, 0.5, plain.fiber.eta);
  const ResultFile a = testing::run(plain), b = testing::run(clear);
  for (int lobe = 0; lobe < 4; ++lobe) {
    std::vector<double> a2, b2;
    const std::vector<double> a1 = testing::phi_marginal(a, 0, lobe, 0, &a2);
    const std::vector<double> b1 = testing::phi_marginal(b, 0, lobe, 0, &b2);
    double chi2 = 0.0;
    int dof = 0;
    for (int j = 0; j < a.grid.n_phi(); ++j) {
      if (a2[j] <= 0.0 || b2[j] <= 0.0 || a1[j] * a1[j] / a2[j] < 30.0 || b1[j] * b1[j] / b2[j] < 30.0)
        continue;
      const Estimate x = bin_estimate(a1[j], a2[j], a.photons[0]);
      const Estimate y = bin_estimate(b1[j], b2[j], b.photons[0]);
      chi2 += (x.mean - y.mean) * (x.mean - y.mean) /
              (x.std_error * x.std_error + y.std_error * y.std_error);
      ++dof;
    }
    std::printf("lobe %d: chi2 %.1f over %d bins\n", lobe, chi2, dof);
    ASSERT_GT(dof, 10);
    EXPECT_LT(chi2, testing::chi2_threshold(dof)) << "lobe " << lobe;
  }
  EXPECT_EQ(lobe_energy(b, 0, 4, 0).mean, 0.0);
}

// Every sigma_a 0: whatever scatters, reflects at the medulla or is
// truncated, nothing is absorbed (the ledger's absorbed is what the exits
// and truncations leave of N, exactly: SPEC section 4).
TEST(MedullaFurnace, WhiteFiberConservesEnergy) {
  for (const Polarization light : {Polarization::Scalar, Polarization::Stokes}) {
    Settings s = testing::smooth_circle(31.0, 200000);
    s.fiber.eccentricity = 0.7;
    s.source.phi_i = {deg_to_rad(20.0)};
    s.tally.n_theta = 18;
    s.tally.n_phi = 36;
    s.polarization = light;
    testing::make_rough(s, 5.0, 3.0);
    s.fiber.medulla = medulla(0.6, 4.0, {0.0}, 0.8, 1.33);
    const ResultFile r = testing::run(s);
    const double n = static_cast<double>(r.photons[0]);
    EXPECT_LT(std::abs(r.absorbed[0]), 1e-9 * n) << to_string(light);
    EXPECT_LT(r.truncated[0], 1e-3 * n) << to_string(light);
    EXPECT_GT(lobe_energy(r, 0, 4, 0).mean, 0.2) << to_string(light);
  }
}

// A medulla of radius k is met by the chords at distance below k from the
// axis, a fraction of about k eta' of them per pass: as k -> 0 its effect
// vanishes however strongly it scatters (sigma_s k = 1, eta_m 1.2) and the
// lobes are SPEC section 8's (smooth circle, theta_i = 0).
TEST(MedullaVanishing, ThinMedullaChangesNothing) {
  const double table[4] = {0.07496, 0.86179, 0.05567, 0.00758};  // SPEC s8, theta_i = 0
  for (const double k : {1e-3, 1e-5}) {
    Settings s = testing::smooth_circle(0.0, 400000);
    s.tally.n_theta = 18;
    s.tally.n_phi = 36;
    s.fiber.medulla = medulla(k, 1.0 / k, {0.0}, 0.0, 1.2);
    const ResultFile r = testing::run(s);
    const double scattered = lobe_energy(r, 0, 4, 0).mean;
    std::printf("k %g: scattered %.2e\n", k, scattered);
    EXPECT_LE(scattered, 2.0 * k * 1.55);
    for (int l = 0; l < 4; ++l) {
      const Estimate e = lobe_energy(r, 0, l, 0);
      EXPECT_LT(std::abs(e.mean - table[l]), 5.0 * e.std_error + 2.0 * k * 1.55 + 1e-5)
          << "k " << k << " lobe " << l;
    }
  }
}

// A visit to the medulla is bounded by max_segments events: a photon still
// scattering after them is truncated (SPEC section 5's rule), never lost or
// dropped, and the ledger still closes (white fiber: nothing absorbed).
TEST(MedullaBound, EventsBeyondMaxSegmentsAreTruncated) {
  Settings s = testing::smooth_circle(10.0, 50000);
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.max_segments = 3;
  s.fiber.medulla = medulla(0.6, 200.0, {0.0}, 0.0, 1.55);
  const ResultFile r = testing::run(s);
  const double n = static_cast<double>(r.photons[0]);
  EXPECT_GT(r.truncated[0], 0.3 * n);
  EXPECT_EQ(r.lost[0], 0.0);
  EXPECT_LT(std::abs(r.absorbed[0]), 1e-9 * n);
}

// Scattering turns the direction: on a smooth untilted circle every
// unscattered photon leaves on the specular cone theta_r = -theta_i, while
// isotropic scattering spreads the inclination (inside, sin theta is uniform
// in [-1, 1] after a scattering, and only |sin theta| < 1/eta gets out
// through a smooth boundary): well under half of `scattered` stays in the
// 10-degree theta bin of the cone.
TEST(MedullaScattering, ScatteredLightLeavesTheSpecularCone) {
  Settings s = testing::smooth_circle(0.7, 100000);
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.fiber.medulla = medulla(0.6, 3.0, {0.0}, 0.0, 1.55);
  const ResultFile r = testing::run(s);
  const std::vector<double> theta = testing::theta_marginal(r, 0, 4, 0);
  double total = 0.0;
  for (double x : theta) total += x;
  ASSERT_GT(total, 0.0);
  const int cone = r.grid.theta_bin(deg_to_rad(-0.7));
  std::printf("scattered in the specular theta bin: %.3f\n", theta[cone] / total);
  EXPECT_LT(theta[cone] / total, 0.5);
  // The unscattered lobes stay on the cone.
  const std::vector<double> tt = testing::theta_marginal(r, 0, 1, 0);
  double tt_total = 0.0;
  for (double x : tt) tt_total += x;
  EXPECT_EQ(tt[cone], tt_total);
}

TEST(MedullaThreads, BitIdenticalForAnyThreadCount) {
  Settings s = testing::smooth_circle(25.0, 60000);
  s.fiber.eccentricity = 0.8;
  s.fiber.sigma_a = {0.2, 0.5};
  s.polarization = Polarization::Stokes;
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  testing::make_rough(s, 5.0, 3.0);
  s.fiber.medulla = medulla(0.5, 3.0, {0.1, 0.9}, 0.6, 1.4);
  const ResultFile one = testing::run(s, 1);
  const ResultFile three = testing::run(s, 3);
  EXPECT_EQ(one.weight_sum, three.weight_sum);
  EXPECT_EQ(one.weight_sq_sum, three.weight_sq_sum);
  EXPECT_EQ(one.count, three.count);
  EXPECT_EQ(one.truncated, three.truncated);
}

// fiber.medulla in the config: defaults, the round trip through to_yaml
// (the result file's config_yaml), and one-line errors naming the field.
TEST(MedullaSettings, ParsedCheckedAndRoundTripped) {
  const Settings s = parse_settings_yaml(
      "fiber: {eta: 1.6, sigma_a: [0.1, 0.2], medulla: {radius: 0.4, sigma_s: 5}}\n", "m.yaml");
  ASSERT_TRUE(s.fiber.medulla.has_value());
  EXPECT_EQ(s.fiber.medulla->sigma_a, (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(s.fiber.medulla->eta, 1.6);
  EXPECT_EQ(s.fiber.medulla->g, 0.0);
  EXPECT_EQ(s.tally_lobes(), s.tally.lobes + 1);
  EXPECT_EQ(parse_settings_yaml(to_yaml(s), "again"), s) << to_yaml(s);
  EXPECT_FALSE(parse_settings_yaml("{}\n", "plain").fiber.medulla.has_value());
  auto error_of = [](const std::string& yaml) {
    try {
      parse_settings_yaml(yaml, "m.yaml");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string f = "fiber: {sigma_a: [0.1, 0.2], medulla: ";
  EXPECT_EQ(error_of(f + "{radius: 0, sigma_s: 1}}\n"),
            "m.yaml: fiber.medulla.radius = 0 is out of range (must be in (0, 1): a fraction of the "
            "fiber's semi-axes)");
  EXPECT_NE(error_of(f + "{radius: 0.5}}\n").find("fiber.medulla.sigma_s is missing"), std::string::npos);
  EXPECT_NE(error_of(f + "{radius: 0.5, sigma_s: .nan}}\n").find("fiber.medulla.sigma_s"), std::string::npos);
  EXPECT_NE(error_of(f + "{radius: 0.5, sigma_s: 1, g: -1}}\n").find("fiber.medulla.g = -1 is out of range"),
            std::string::npos);
  EXPECT_NE(error_of(f + "{radius: 0.5, sigma_s: 1, sigma_a: [1, 2, 3]}}\n")
                .find("must have the fiber's 2 channels"),
            std::string::npos);
  EXPECT_NE(error_of(f + "{radius: 0.5, sigma_s: 1, eta: 0.5}}\n").find("fiber.medulla.eta = 0.5"),
            std::string::npos);
  EXPECT_NE(error_of(f + "{radius: 0.5, sigma_s: 1}}\nroughness: {model: ggx, alpha: 0.2, masking: smith_g1}\n")
                .find("fiber.medulla is not allowed with roughness.masking"),
            std::string::npos);
}

// Henyey-Greenstein: P(cos <= mu) = (1 - g^2) / (2 g) ((1 + g^2 - 2 g mu)^(-1/2)
// - 1 / (1 + g)) (the integral of (1 - g^2) / (2 (1 + g^2 - 2 g mu)^(3/2))),
// (1 + mu) / 2 for g = 0. Chi-square over 40 bins of cos from stratified-free
// uniforms.
TEST(HenyeyGreenstein, CosineFollowsTheClosedFormCdf) {
  for (const double g : {-0.5, 0.0, 0.3, 0.9}) {
    auto cdf = [g](double mu) {
      if (g == 0.0) return 0.5 * (1.0 + mu);
      return (1 - g * g) / (2 * g) * (1.0 / std::sqrt(1 + g * g - 2 * g * mu) - 1.0 / (1 + g));
    };
    std::mt19937_64 gen(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int bins = 40, n = 400000;
    std::vector<int> count(bins, 0);
    for (int i = 0; i < n; ++i) {
      const double mu = life::henyey_greenstein_cos(g, u(gen));
      ++count[std::min(bins - 1, static_cast<int>((mu + 1.0) / 2.0 * bins))];
    }
    double chi2 = 0.0;
    for (int b = 0; b < bins; ++b) {
      const double p = cdf(-1.0 + 2.0 * (b + 1) / bins) - cdf(-1.0 + 2.0 * b / bins);
      chi2 += (count[b] - n * p) * (count[b] - n * p) / (n * p);
    }
    EXPECT_LT(chi2, testing::chi2_threshold(bins - 1)) << "g " << g;
  }
}

// The new direction is a unit vector whose mean over the azimuth is g d
// (the frame is orthonormal and the turn symmetric), for directions on both
// sides of the frame's branch (d.z >= 0 and < 0).
TEST(HenyeyGreenstein, TurnedDirectionsAverageToGTimesD) {
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double g = 0.6;
  for (const life::Vec3Of<double> d :
       {life::Vec3Of<double>(0.6, 0.0, 0.8), life::Vec3Of<double>(0.0, 0.28, -0.96),
        life::Vec3Of<double>(0.0, 0.0, -1.0)}) {
    const int n = 200000;
    double m[3] = {0, 0, 0}, m2[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      const double cos_t = life::henyey_greenstein_cos(g, u(gen));
      const auto [sp, cp] = life::sincos_turn(std::floor(u(gen) * 0x1.0p52) * 0x1.0p-52);
      const life::Vec3Of<double> o = life::turn_direction(d, cos_t, sp, cp);
      ASSERT_NEAR(o.norm(), 1.0, 1e-12);
      ASSERT_NEAR(o.dot(d), cos_t, 1e-9);
      const double c[3] = {o.x, o.y, o.z};
      for (int k = 0; k < 3; ++k) m[k] += c[k], m2[k] += c[k] * c[k];
    }
    const double want[3] = {g * d.x, g * d.y, g * d.z};
    for (int k = 0; k < 3; ++k) {
      const double mean = m[k] / n, se = std::sqrt((m2[k] / n - mean * mean) / n);
      EXPECT_LT(std::abs(mean - want[k]), 5.0 * se + 1e-12) << "component " << k;
    }
  }
}

// From points inside an ellipse, the distance ahead lands on the boundary.
TEST(MedullaGeometry, ExitDistanceReachesTheEllipse) {
  const life::AxisEllipse e{1.0 / (0.7 * 0.7), 1.0 / (0.4 * 0.4)};
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 100000; ++i) {
    double pv = 0.7 * u(gen), pw = 0.4 * u(gen);
    if (pv * pv * e.inv_v2 + pw * pw * e.inv_w2 > 1.0) continue;
    if (i % 7 == 0) e.snap(pv, pw);  // start on the boundary too
    const double a = M_PI * u(gen), dv = std::cos(a), dw = std::sin(a);
    bool along = false;
    const double t = e.exit_distance(pv, pw, dv, dw, along);
    ASSERT_FALSE(along);
    ASSERT_GE(t, 0.0);
    const double qv = pv + t * dv, qw = pw + t * dw;
    ASSERT_NEAR(qv * qv * e.inv_v2 + qw * qw * e.inv_w2, 1.0, 1e-9) << i;
  }
}

}  // namespace
}  // namespace fiberlab::sim
