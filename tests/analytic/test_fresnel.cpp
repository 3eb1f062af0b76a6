// common/fresnel against textbook values (Born & Wolf s1.5; Hecht s4.6):
// the one Fresnel every model and the simulator use.
#include <gtest/gtest.h>

#include <cmath>

#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab {
namespace {

// Normal incidence: R = ((n - 1)/(n + 1))^2 from either side.
TEST(Fresnel, NormalIncidence) {
  for (double n : {1.33, 1.5, 1.55, 2.4}) {
    const double r = std::pow((n - 1.0) / (n + 1.0), 2);
    EXPECT_NEAR(fresnel_dielectric(1.0, n), r, 1e-15) << n;
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.0 / n), r, 1e-15) << n;
  }
  EXPECT_NEAR(fresnel_dielectric(1.0, 1.5), 0.04, 1e-15);
}

// Brewster's angle tan(theta_B) = n: r_p = 0, so F = R_s / 2.
TEST(Fresnel, BrewsterAngleHasNoPReflection) {
  for (double n : {1.5, 1.55, 1.0 / 1.55}) {
    const double theta_b = std::atan(n);
    const FresnelAmplitudes a = fresnel_amplitudes(std::cos(theta_b), n);
    EXPECT_NEAR(a.r_p, 0.0, 1e-15) << n;
    EXPECT_NEAR(fresnel_dielectric(std::cos(theta_b), n), 0.5 * a.r_s * a.r_s, 1e-15);
    // Textbook R_s at Brewster: ((n^2 - 1)/(n^2 + 1))^2.
    EXPECT_NEAR(a.r_s * a.r_s, std::pow((n * n - 1.0) / (n * n + 1.0), 2), 1e-14) << n;
  }
}

// Leaving glass of index n: total internal reflection from the critical
// angle asin(1/n) on; just below it F < 1 and rises to 1 continuously.
TEST(Fresnel, CriticalAngleAndTotalInternalReflection) {
  const double n = 1.55, eta_rel = 1.0 / n;
  const double crit = std::asin(1.0 / n);
  EXPECT_EQ(fresnel_dielectric(std::cos(crit + 1e-9), eta_rel), 1.0);
  EXPECT_EQ(fresnel_dielectric(std::cos(deg_to_rad(60.0)), eta_rel), 1.0);
  EXPECT_TRUE(std::isnan(fresnel_amplitudes(std::cos(deg_to_rad(60.0)), eta_rel).cos_t));
  const double below = fresnel_dielectric(std::cos(crit - 1e-6), eta_rel);
  EXPECT_LT(below, 1.0);
  EXPECT_GT(below, 0.99);
  // Grazing incidence from outside reflects everything.
  EXPECT_NEAR(fresnel_dielectric(0.0, n), 1.0, 1e-15);
}

// A textbook value at oblique incidence: n = 1.5, 45 deg:
// R_s = 0.092013, R_p = 0.008466 (Hecht, Fig. 4.49 data).
TEST(Fresnel, ObliqueIncidenceTextbookValue) {
  const FresnelAmplitudes a = fresnel_amplitudes(std::cos(deg_to_rad(45.0)), 1.5);
  EXPECT_NEAR(a.r_s * a.r_s, 0.0920134, 1e-6);
  EXPECT_NEAR(a.r_p * a.r_p, 0.0084663, 1e-6);
  // SPEC s3 sign convention: r_p = -r_s at normal incidence.
  const FresnelAmplitudes z = fresnel_amplitudes(1.0, 1.5);
  EXPECT_NEAR(z.r_p, -z.r_s, 1e-15);
}

}  // namespace
}  // namespace fiberlab
