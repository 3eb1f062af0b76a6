// The gaussian roughness sampler (SPEC section 3) against the plain
// definition: propose n_f rotated by Normal offsets, accept with probability
// max(0, -d.m). The sampler under test uses an envelope at grazing incidence;
// the accepted distribution must be the same.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/units.h"
#include "sim/roughness/roughness_gaussian.h"
#include "tests/sim/normal_samples_chi2.h"

namespace fiberlab::sim {
namespace {

// The definition, written out independently of sim/roughness/microfacet_normal.cpp.
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

void compare_samplers(const Vec3& d, const Vec3& nf, double bl, double ba, const char* what,
                      int n = 200000) {
  PhotonRandom ra(1, 2.0, 0.0, 3), rb(4, 5.0, 0.0, 6);
  long tries = 0;
  std::vector<Vec3> sa, sb;
  for (int k = 0; k < n; ++k) {
    auto m = gaussian_normal(d, nf, bl, ba, ra, 100000, tries);
    ASSERT_TRUE(m.has_value()) << what;
    ASSERT_LT(d.dot(*m), 0.0);
    ASSERT_NEAR(m->norm(), 1.0, 1e-12);
    sa.push_back(*m);
    sb.push_back(reference_normal(d, nf, bl, ba, rb));
  }
  const testing::NormalsChi2 r = testing::two_sample_normals_chi2(sa, sb, nf);
  std::printf("%s: %.1f draws per normal, chi2 %.1f over %d bins (threshold %.1f)\n", what,
              static_cast<double>(tries) / n, r.chi2, r.dof, r.threshold());
  ASSERT_GT(r.dof, 30);
  EXPECT_LT(r.chi2, r.threshold()) << what;
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

namespace fiberlab::sim {
namespace {

// A photon direction d that sees the facet normal nf from behind: d.nf =
// sin(eps), eps the angle by which the tilted normal faces away (SPEC
// section 3, small beta on a tilted fiber at oblique incidence). d is
// nf's "grazing" partner turned by eps, with some inclination.
Vec3 facing_away_direction(const Vec3& nf, double eps) {
  const Vec3 t = nf.cross(Vec3(0.3, 0.2, 0.9)).normalized();  // tangent at nf
  return (std::sin(eps) * nf + std::cos(eps) * t).normalized();
}

// The far-tail sampler: the tilted normal faces away by eps = 1.5 beta (and
// 1.4 beta_long for unequal betas), so every visible normal is 1.5 or more
// standard deviations out. The reference rejection sampler needs ~400
// candidates per normal here (the samples are smaller to keep it fast).
TEST(GaussianNormal, SameDistributionInTheFarTail) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);
  const double beta = deg_to_rad(5.0);
  const Vec3 d = facing_away_direction(nf, 1.5 * beta);
  ASSERT_GT(d.dot(nf), 0.0);  // n_f faces away: the envelope starts in the tail
  compare_samplers(d, nf, beta, beta, "far tail, eps = 1.5 beta", 40000);
  const Vec3 d2 = facing_away_direction(nf, deg_to_rad(7.0));
  compare_samplers(d2, nf, deg_to_rad(5.0), deg_to_rad(3.0), "far tail, beta 5/3, eps 7 deg",
                   40000);
}

// A steep case: beta 0.5 deg with the normal 3 deg away (eps / beta = 6):
// plain rejection (probability ~1e-9 a candidate) hit any cap; the tail
// sampler must find every normal in a few dozen candidates.
TEST(GaussianNormal, FarTailNeverReachesTheCap) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);
  const double beta = deg_to_rad(0.5);
  PhotonRandom rng(7, 8.0, 0.0, 9);
  for (double eps_deg : {0.6, 3.0, 10.0}) {
    const Vec3 d = facing_away_direction(nf, deg_to_rad(eps_deg));
    long tries = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
      const auto m = gaussian_normal(d, nf, beta, beta, rng, 100000, tries);
      ASSERT_TRUE(m.has_value()) << "eps " << eps_deg << " deg";
      ASSERT_LT(d.dot(*m), 0.0);
    }
    std::printf("beta 0.5 deg, eps %.1f deg: %.1f candidates per normal\n", eps_deg,
                static_cast<double>(tries) / n);
    EXPECT_LT(static_cast<double>(tries) / n, 200.0);
  }
}

// sim/roughness/roughness_model.h's contract, which the photon life relies on (its
// event acts on `ready` lanes alone): a draw that gives up is never also
// ready. One candidate a call, from one try short of the cap, so that every
// call ends ready or failed; about a fifth are accepted here.
TEST(GaussianNormal, AGivenUpDrawIsNeverReady) {
  const Vec3 nf = Vec3(-std::sin(0.05), std::cos(0.05), 0.0);
  const Vec3 d = facing_away_direction(nf, deg_to_rad(4.0));
  const life::GaussianRoughness model(deg_to_rad(5.0), deg_to_rad(5.0));
  const auto frame = life::BoundaryFrame<double>::from_facing(life::Vec3Of<double>(nf));
  PhotonRandom rng(11, 12.0, 0.0, 13);
  life::LifeCounts<double> counts;
  int ready = 0, failed = 0;
  for (int k = 0; k < 20000; ++k) {
    double tries = life::kMaxNormalTries - 1;
    const life::FacetDraw<double> f =
        model.draw_normal(life::Vec3Of<double>(d), frame, true, rng.core(), tries, counts, 1);
    ASSERT_FALSE(f.ready && f.failed) << "call " << k;
    ASSERT_TRUE(f.ready || f.failed) << "call " << k;
    ready += f.ready;
    failed += f.failed;
  }
  std::printf("from one try short of the cap: %d ready, %d given up\n", ready, failed);
  EXPECT_GT(ready, 1000);
  EXPECT_GT(failed, 1000);
}

}  // namespace
}  // namespace fiberlab::sim
