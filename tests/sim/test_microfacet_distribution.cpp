// Microfacet distributions (sim/roughness/microfacet_distribution.h) against their
// definitions: D's projected-area normalisation, Smith's G1 as the
// normalisation of the VNDF (G1(w) = w.n / integral max(0, w.m) D(m) dm),
// and the sampled normals against the VNDF by chi-square on a histogram
// (fixed seeds; threshold n + 5 sqrt(2n) over the n bins with >= 20
// expected), isotropic and anisotropic, about an untilted and a tilted normal.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "common/error.h"
#include "common/units.h"
#include "sim/roughness/microfacet_distribution.h"
#include "sim/life/random.h"

using namespace fiberlab;
using namespace fiberlab::sim;

namespace {

Vec3 spherical(double theta, double phi) {
  return Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

// Integral over the upper hemisphere of f(m) dm, by composite Gauss-Legendre
// (boost) in theta (nt panels, clustered near the pole as theta = (pi/2) t^2)
// and phi (np panels).
double hemisphere(const std::function<double(const Vec3&)>& f, int nt = 200, int np = 48) {
  static const std::vector<double> x = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                        -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                        0.7966664774136267,  0.9602898564975363};
  static const std::vector<double> w = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                        0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                        0.2223810344533745, 0.1012285362903763};
  double total = 0.0;
  for (int a = 0; a < nt; ++a)
    for (int qa = 0; qa < 8; ++qa) {
      const double t = (a + 0.5 + 0.5 * x[qa]) / nt;
      const double theta = 0.5 * kPi * t * t, dtheta = kPi * t / nt * 0.5 * w[qa];
      double ring = 0.0;
      for (int b = 0; b < np; ++b)
        for (int qb = 0; qb < 8; ++qb) {
          const double phi = -kPi + (b + 0.5 + 0.5 * x[qb]) * kTwoPi / np;
          ring += 0.5 * w[qb] * kTwoPi / np * f(spherical(theta, phi));
        }
      total += dtheta * std::sin(theta) * ring;
    }
  return total;
}

struct Case {
  MicrofacetModel model;
  double ax, ay;
};
const Case kCases[] = {{MicrofacetModel::GGX, 0.05, 0.05},      {MicrofacetModel::GGX, 0.3, 0.3},
                       {MicrofacetModel::GGX, 0.1, 0.6},        {MicrofacetModel::GGX, 1.0, 1.0},
                       {MicrofacetModel::Beckmann, 0.05, 0.05}, {MicrofacetModel::Beckmann, 0.3, 0.3},
                       {MicrofacetModel::Beckmann, 0.6, 0.1},   {MicrofacetModel::Beckmann, 1.0, 1.0}};

const char* name(MicrofacetModel m) { return m == MicrofacetModel::GGX ? "ggx" : "beckmann"; }

}  // namespace

// Oracle: integral D(m) (m.n) dm = 1 (the definition of a microfacet
// distribution), to 1e-6 by quadrature.
TEST(MicrofacetDistribution, ProjectedAreaIsOne) {
  for (const Case& c : kCases) {
    const MicrofacetDistribution dist(c.model, c.ax, c.ay);
    const double total = hemisphere([&](const Vec3& m) { return dist.D(m) * m.z(); });
    EXPECT_NEAR(total, 1.0, 1e-6) << name(c.model) << " " << c.ax << " " << c.ay;
  }
}

// Oracle: the VNDF integrates to 1, i.e. G1(w) w.n-normalises the projected
// area seen from w (Heitz 2014 eq. 18: cos theta_w = integral G1 max(0, w.m) D).
// Also, for these D, the projected area seen from w equals w.n (1 + Lambda(w)).
// Mutation tried and caught: Beckmann's exp(-a^2) / (2 a sqrt pi) without the 2.
TEST(MicrofacetDistribution, G1NormalisesTheVisibleNormals) {
  for (const Case& c : kCases) {
    const MicrofacetDistribution dist(c.model, c.ax, c.ay);
    for (double theta_deg : {0.0, 60.0, 89.0})
      for (double phi_deg : {0.0, 35.0}) {
        const Vec3 w = spherical(deg_to_rad(theta_deg), deg_to_rad(phi_deg));
        const double total = hemisphere([&](const Vec3& m) { return dist.visible_density(w, m); });
        EXPECT_NEAR(total, 1.0, 2e-5) << name(c.model) << " alpha " << c.ax << "," << c.ay << " theta_w "
                                      << theta_deg << " phi_w " << phi_deg;
      }
  }
}

TEST(MicrofacetDistribution, RejectsNonPositiveAlpha) {
  EXPECT_THROW(MicrofacetDistribution(MicrofacetModel::GGX, 0.0, 0.1), Error);
  EXPECT_THROW(MicrofacetDistribution(MicrofacetModel::Beckmann, 0.1, -1.0), Error);
  EXPECT_THROW(MicrofacetDistribution(MicrofacetModel::GGX, NAN, 0.1), Error);
}

namespace {

// Chi-square of `n` sampled normals (in the local frame returned by
// `sample`) against the VNDF of direction w, on bins uniform in
// u = tan(theta_m) / (3 alpha_max) (24 bins up to u = 1, one to infinity)
// and 16 bins in phi_m; bins with < 20 expected are pooled.
struct ChiSquare {
  double chi2;
  int dof;
};
ChiSquare chi_square(const MicrofacetDistribution& dist, const Vec3& w, double alpha_max, int n,
                     const std::function<Vec3(PhotonRandom&)>& sample) {
  constexpr int kU = 25, kPhi = 16;
  const double scale = 3.0 * alpha_max;
  auto theta_edge = [&](int i) { return i >= kU - 1 ? 0.5 * kPi : std::atan(scale * i / (kU - 1.0)); };
  std::vector<double> observed(kU * kPhi, 0.0), expected(kU * kPhi, 0.0);
  PhotonRandom rng(/*key=*/20260101, /*photon=*/7);
  for (int k = 0; k < n; ++k) {
    const Vec3 m = sample(rng);
    const double theta = std::acos(std::clamp(m.z(), -1.0, 1.0));
    const double phi = std::atan2(m.y(), m.x());
    int i = 0;
    while (i < kU - 1 && theta >= theta_edge(i + 1)) ++i;
    const int j = std::clamp(static_cast<int>((phi + kPi) / kTwoPi * kPhi), 0, kPhi - 1);
    observed[i * kPhi + j] += 1.0;
  }
  // Expected counts: Gauss-Legendre over each bin (8 x 8 per sub-panel).
  static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                              0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static const double wq[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  for (int i = 0; i < kU; ++i)
    for (int j = 0; j < kPhi; ++j) {
      const double t0 = theta_edge(i), t1 = theta_edge(i + 1);
      const double p0 = -kPi + j * kTwoPi / kPhi, p1 = p0 + kTwoPi / kPhi;
      constexpr int kSub = 3;
      double s = 0.0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b)
          for (int qa = 0; qa < 8; ++qa)
            for (int qb = 0; qb < 8; ++qb) {
              const double h = (t1 - t0) / kSub, g = (p1 - p0) / kSub;
              const double th = t0 + (a + 0.5 + 0.5 * x[qa]) * h, ph = p0 + (b + 0.5 + 0.5 * x[qb]) * g;
              s += 0.25 * h * g * wq[qa] * wq[qb] * std::sin(th) * dist.visible_density(w, spherical(th, ph));
            }
      expected[i * kPhi + j] = s * n;
    }
  ChiSquare r{0.0, 0};
  double pool_o = 0.0, pool_e = 0.0;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] < 20.0) {
      pool_o += observed[k];
      pool_e += expected[k];
      continue;
    }
    r.chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++r.dof;
  }
  if (pool_e >= 20.0) {
    r.chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    ++r.dof;
  } else {
    EXPECT_LT(pool_o, 20.0 + 5.0 * std::sqrt(20.0));
  }
  return r;
}

}  // namespace

// Sampled normals against the VNDF definition (one-sample chi-square; the
// expected counts come from D and G1, themselves checked above against
// their definitions). 200,000 normals per case.
// Mutations tried and caught: GGX's disk warp s = (1 + vh_z) / 2 replaced
// by 1/2; Beckmann's y slope drawn with variance 1 instead of 1/2; the
// Beckmann slopes unstretched with alpha_azim for both axes.
TEST(MicrofacetDistribution, SampledNormalsFollowTheVndf) {
  constexpr int kN = 200000;
  for (const Case& c : kCases) {
    const MicrofacetDistribution dist(c.model, c.ax, c.ay);
    for (double theta_deg : {0.0, 45.0, 75.0, 88.0}) {
      const Vec3 w = spherical(deg_to_rad(theta_deg), deg_to_rad(30.0));
      const ChiSquare r = chi_square(dist, w, std::max(c.ax, c.ay), kN, [&](PhotonRandom& rng) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const Vec3 m = dist.sample_visible(w, u1, u2);
        EXPECT_NEAR(m.norm(), 1.0, 1e-12);
        EXPECT_GT(m.dot(w), -1e-12);  // visible from w
        return m;
      });
      EXPECT_LT(r.chi2, r.dof + 5.0 * std::sqrt(2.0 * r.dof))
          << name(c.model) << " alpha " << c.ax << "," << c.ay << " theta_w " << theta_deg << " dof " << r.dof;
    }
  }
}

// About a tilted normal in the fiber frame (scale tilt 10 deg: n = cos a n0 -
// sin a u), the world-space sampler returns normals that the photon sees
// (d.m < 0) and that, in the frame about n (longitudinal along u), follow the
// VNDF of -d. A photon behind the tilted normal gets nothing (the caller's
// SPEC s3 fallback).
// Mutation tried and caught: the frame's longitudinal and azimuthal axes
// swapped (anisotropic alpha applied to the wrong directions).
TEST(MicrofacetDistribution, TiltedNormalInTheFiberFrame) {
  const double a = deg_to_rad(10.0);
  const Vec3 u(1, 0, 0), n0 = Vec3(0, std::cos(0.4), std::sin(0.4));
  const Vec3 n = std::cos(a) * n0 - std::sin(a) * u;
  const MicrofacetFrame frame = MicrofacetFrame::about(n);  // about the fiber axis u
  EXPECT_NEAR(frame.t.dot(frame.n), 0.0, 1e-15);
  EXPECT_NEAR(frame.b.dot(frame.t), 0.0, 1e-15);
  EXPECT_NEAR(frame.t.cross(frame.b).dot(frame.n), 1.0, 1e-15);
  EXPECT_GT(frame.t.dot(u), 0.0);
  for (MicrofacetModel model : {MicrofacetModel::GGX, MicrofacetModel::Beckmann}) {
    const MicrofacetDistribution dist(model, 0.08, 0.4);
    const Vec3 d = -(0.5 * n + 0.3 * u + 0.4 * n.cross(u)).normalized();  // arriving at n's front
    const Vec3 w = frame.to_local(-d);
    ASSERT_GT(w.z(), 0.0);
    const ChiSquare r = chi_square(dist, w, 0.4, 200000, [&](PhotonRandom& rng) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const std::optional<Vec3> m = dist.sample_visible(frame, d, u1, u2);
      EXPECT_TRUE(m.has_value());
      EXPECT_LT(d.dot(*m), 1e-12);
      return frame.to_local(*m);
    });
    EXPECT_LT(r.chi2, r.dof + 5.0 * std::sqrt(2.0 * r.dof)) << name(model) << " dof " << r.dof;
    EXPECT_FALSE(dist.sample_visible(frame, n, 0.3, 0.7).has_value());
  }
}
