// SPEC section 8: lobe energies of a smooth circular fiber, eta = 1.55,
// sigma_a = 0, unpolarised Fresnel. The table below is copied from SPEC.md
// section 8 (E_p = 1/2 integral of A(p, h) dh), not from this code.
#include <gtest/gtest.h>

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

struct KnownEnergies {
  double theta_i_deg;
  double e[4];  // R, TT, TRT, p >= 3
};

constexpr KnownEnergies kSpecSection8[] = {
    {0.0, {0.07496, 0.86179, 0.05567, 0.00758}},
    {60.0, {0.17347, 0.69735, 0.10201, 0.02717}},
    {80.0, {0.48968, 0.27305, 0.12312, 0.11415}},
    {85.0, {0.68759, 0.10366, 0.06814, 0.14061}},
};

TEST(SmoothCircle, LobeEnergiesMatchSpecSection8) {
  for (const KnownEnergies& known : kSpecSection8) {
    const ResultFile r = testing::run(testing::smooth_circle(known.theta_i_deg, 2000000));
    for (int lobe = 0; lobe < 4; ++lobe) {
      const Estimate e = lobe_energy(r, 0, lobe, 0);
      // Within 4 standard errors (the table's rounding, 5e-6, is far below).
      EXPECT_NEAR(e.mean, known.e[lobe], 4.0 * e.std_error)
          << "theta_i " << known.theta_i_deg << " lobe " << lobe << " se " << e.std_error;
    }
    EXPECT_EQ(r.truncated[0], 0.0);
  }
}

// SPEC section 8, `polarization: stokes` (smooth circle, no tilt, sigma_a 0):
// exact 3D Jones-matrix products over h, copied from SPEC.md. The scalar
// values at 40 and 75 deg differ from these by 6-40 standard errors per lobe,
// and SPEC section 3 notes that the other sign of r_p, or an unsigned psi,
// moves TRRT by 10-17% at oblique incidence: this test tells them apart.
constexpr KnownEnergies kSpecSection8Stokes[] = {
    {0.0, {0.07496, 0.86518, 0.05082, 0.00904}},
    {40.0, {0.09934, 0.81562, 0.07646, 0.00858}},
    {75.0, {0.36024, 0.44316, 0.11259, 0.08401}},
};

TEST(SmoothCircle, StokesLobeEnergiesMatchSpecSection8) {
  for (const KnownEnergies& known : kSpecSection8Stokes) {
    Settings s = testing::smooth_circle(known.theta_i_deg, 2000000);
    s.polarization = Polarization::Stokes;
    const ResultFile r = testing::run(s);
    for (int lobe = 0; lobe < 4; ++lobe) {
      const Estimate e = lobe_energy(r, 0, lobe, 0);
      EXPECT_NEAR(e.mean, known.e[lobe], 4.0 * e.std_error)
          << "stokes theta_i " << known.theta_i_deg << " lobe " << lobe << " se " << e.std_error;
    }
  }
}

// Every photon of a smooth untilted fiber leaves on the specular cone
// theta_r = -theta_i (SPEC section 7), for a circle and for an ellipse.
TEST(SmoothCircle, EveryPhotonInSpecularThetaBin) {
  for (double e : {1.0, 0.7}) {
    Settings s = testing::smooth_circle(23.3, 100000);  // 23.3 deg: off the 2-deg bin edges
    s.fiber.eccentricity = e;
    s.source.phi_i = {deg_to_rad(40.0)};
    const ResultFile r = testing::run(s);
    const int specular = r.grid.theta_bin(-deg_to_rad(23.3));
    for (int l = 0; l < r.lobes; ++l)
      for (int i = 0; i < r.grid.n_theta(); ++i)
        for (int j = 0; j < r.grid.n_phi(); ++j)
          if (i != specular) {
            ASSERT_EQ(r.count[(static_cast<std::size_t>(l) * r.grid.n_theta() + i) * r.grid.n_phi() + j], 0u)
                << "e " << e << " lobe " << l << " theta bin " << i;
          }
  }
}

}  // namespace
}  // namespace fiberlab::sim
