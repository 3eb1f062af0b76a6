// The gaussian roughness sampler (SPEC section 3) against the plain
// definition: propose n_f rotated by Normal offsets, accept with probability
// max(0, -d.m). The sampler under test uses an envelope at grazing incidence;
// the accepted distribution must be the same.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "common/units.h"
#include "sim/microfacet_normal.h"

namespace fiberlab::sim {
namespace {

// The definition, written out independently of sim/microfacet_normal.cpp.
Vec3 reference_normal(const Vec3& d, const Vec3& nf, double bl, double ba, PhotonRandom& rng) {
  const double theta_n = std::asin(nf.x());
  const Vec3 perp = Vec3(0.0, nf.y(), nf.z()).normalized();
  while (true) {
    const double t = theta_n + bl * rng.normal();
    const double a = ba * rng.normal();
    const Vec3 rotated_perp(0.0, perp.y() * std::cos(a) - perp.z() * std::sin(a),
                            perp.y() * std::sin(a) + perp.z() * std::cos(a));
    const Vec3 m = std::sin(t) * Vec3::UnitX() + std::cos(t) * rotated_perp;
    if (rng.uniform() < std::max(0.0, -d.dot(m))) return m;
  }
}

// 2D histogram of (m.u, azimuth of m about u relative to n_f), 20 x 20 bins
// over the range the samples cover.
struct Histogram2D {
  std::vector<double> counts = std::vector<double>(400, 0.0);
  double lo_u, hi_u, lo_a, hi_a;
  void add(const Vec3& m, const Vec3& nf) {
    const double a = std::atan2(m.z(), m.y()) - std::atan2(nf.z(), nf.y());
    const int i = static_cast<int>((m.x() - lo_u) / (hi_u - lo_u) * 20);
    const int j = static_cast<int>((wrap_angle(a) - lo_a) / (hi_a - lo_a) * 20);
    if (i >= 0 && i < 20 && j >= 0 && j < 20) counts[i * 20 + j] += 1.0;
  }
};

void compare_samplers(const Vec3& d, const Vec3& nf, double bl, double ba, const char* what) {
  const int n = 200000;
  const double spread = 4.0 * std::max(bl, ba);
  Histogram2D a;
  a.lo_u = nf.x() - spread;
  a.hi_u = nf.x() + spread;
  a.lo_a = -1.5 * spread;
  a.hi_a = 1.5 * spread;
  Histogram2D b = a;
  PhotonRandom ra(1, 2, 3), rb(4, 5, 6);
  long tries = 0;
  for (int k = 0; k < n; ++k) {
    auto m = gaussian_normal(d, nf, bl, ba, ra, 100000, tries);
    ASSERT_TRUE(m.has_value());
    EXPECT_LT(d.dot(*m), 0.0);
    EXPECT_NEAR(m->norm(), 1.0, 1e-12);
    a.add(*m, nf);
    b.add(reference_normal(d, nf, bl, ba, rb), nf);
  }
  // Two-sample chi-square over bins with >= 30 expected counts in both.
  double chi2 = 0.0;
  int dof = 0;
  for (int k = 0; k < 400; ++k) {
    if (a.counts[k] < 30 || b.counts[k] < 30) continue;
    const double diff = a.counts[k] - b.counts[k];
    chi2 += diff * diff / (a.counts[k] + b.counts[k]);
    ++dof;
  }
  // chi2 ~ chi-square(dof) (mean dof, sd sqrt(2 dof)); 5 sd above the mean.
  const double threshold = dof + 5.0 * std::sqrt(2.0 * dof);
  std::printf("%s: %.1f draws per normal, chi2 %.1f over %d bins (threshold %.1f)\n", what,
              static_cast<double>(tries) / n, chi2, dof, threshold);
  ASSERT_GT(dof, 30);
  EXPECT_LT(chi2, threshold) << what;
}

TEST(GaussianNormal, SameDistributionAsDefinitionAtNormalIncidence) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);  // 3-deg tilt
  compare_samplers(-nf, nf, deg_to_rad(10.0), deg_to_rad(10.0), "normal incidence");
}

TEST(GaussianNormal, SameDistributionAsDefinitionAtGrazingIncidence) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);
  // d nearly along the axis, barely facing n_f: the guided-photon case.
  const Vec3 d = Vec3(0.995, -0.02, 0.0998).normalized();
  ASSERT_LT(-d.dot(nf), 0.5);
  compare_samplers(d, nf, deg_to_rad(5.0), deg_to_rad(5.0), "grazing, beta 5");
  compare_samplers(d, nf, deg_to_rad(20.0), deg_to_rad(8.0), "grazing, beta 20/8");
}

TEST(GaussianNormal, SameDistributionWhenTheTiltedNormalFacesAway) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);
  const Vec3 d = Vec3(-0.9, 0.03, 0.4).normalized();  // d.n_f > 0: c = 0
  ASSERT_GT(d.dot(nf), 0.0);
  compare_samplers(d, nf, deg_to_rad(10.0), deg_to_rad(10.0), "n_f facing away");
}

}  // namespace
}  // namespace fiberlab::sim
