// `masking: smith_g1` (issue 12) against its definition at one interface: a
// photon entering a circular, untilted fiber through its axis (h = 0) meets
// the surface once at the entry point (no repeated event: without tilt the
// mean normal is the untilted one), and the weight masking removes there is
// the first entry of PhotonOutcome::losses (at path length 0). Its mean over
// photons must be
//   1 - integral D_w(m) [F(w.m) G1(w_r) + (1 - F(w.m)) G1(-w_t)] dm,
// D_w(m) = G1(w) max(0, w.m) D(m) / (w.n) the VNDF, w_r and w_t the
// reflected and refracted directions about m, G1 = 0 on the wrong side of the
// mean surface. Everything here is written out independently of
// sim/microfacet_*: D and G1 (Heitz 2014, eqs. for GGX and Beckmann), the
// vectors, and the integral by Gauss-Legendre quadrature over the hemisphere;
// only the textbook Fresnel (common/fresnel, tested on its own) is shared.
//
// Mutations this is built to catch (not yet run against it): no G1 factor
// (only wrong-side kills booked), G1 of the incident instead of the
// scattered direction, G1 of a refracted direction judged on the incident
// side (always 0: every refraction killed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "common/fresnel.h"
#include "common/units.h"
#include "sim/source.h"
#include "sim/tracer.h"

namespace fiberlab::sim {
namespace {

struct Definition {
  RoughnessModel model;
  double alpha;  // isotropic

  double D(const Vec3& m) const {  // local frame, z = mean normal
    if (m.z() <= 0.0) return 0.0;
    const double t2 = (m.x() * m.x() + m.y() * m.y()) / (m.z() * m.z());  // tan^2 theta_m
    const double a2 = alpha * alpha, c4 = std::pow(m.z(), 4);
    if (model == RoughnessModel::GGX) return a2 / (kPi * c4 * std::pow(a2 + t2, 2));
    return std::exp(-t2 / a2) / (kPi * a2 * c4);
  }
  double G1(const Vec3& w) const {
    if (w.z() <= 0.0) return 0.0;
    const double tan_t = std::sqrt(w.x() * w.x() + w.y() * w.y()) / w.z();
    if (model == RoughnessModel::GGX) return 2.0 / (1.0 + std::sqrt(1.0 + alpha * alpha * tan_t * tan_t));
    if (tan_t == 0.0) return 1.0;
    const double a = 1.0 / (alpha * tan_t);
    const double lambda = (std::erf(a) - 1.0) / 2.0 + std::exp(-a * a) / (2.0 * a * std::sqrt(kPi));
    return 1.0 / (1.0 + lambda);
  }

  // The expected masking factor of an event seen from w (local frame, eta
  // entering), by quadrature: theta in panels clustered at the pole.
  double expected_factor(const Vec3& w, double eta) const {
    static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                0.7966664774136267,  0.9602898564975363};
    static const double wt[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                 0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                 0.2223810344533745, 0.1012285362903763};
    const int nt = 240, np = 96;
    double total = 0.0, norm = 0.0;
    for (int a = 0; a < nt; ++a)
      for (int qa = 0; qa < 8; ++qa) {
        const double t = (a + 0.5 + 0.5 * x[qa]) / nt;
        const double theta = 0.5 * kPi * t * t, dtheta = kPi * t / nt * 0.5 * wt[qa];
        for (int b = 0; b < np; ++b)
          for (int qb = 0; qb < 8; ++qb) {
            const double phi = -kPi + (b + 0.5 + 0.5 * x[qb]) * kTwoPi / np;
            const Vec3 m(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
            const double cos_i = w.dot(m);
            if (cos_i <= 0.0) continue;
            const double density = cos_i * D(m) * std::sin(theta) * dtheta * 0.5 * wt[qb] * kTwoPi / np;
            const Vec3 d = -w;
            const Vec3 reflected = d + 2.0 * cos_i * m;
            const double F = fresnel_dielectric(cos_i, eta);
            const double r = 1.0 / eta, cos_t = std::sqrt(1.0 - r * r * (1.0 - cos_i * cos_i));
            const Vec3 refracted = (r * d + (r * cos_i - cos_t) * m).normalized();
            total += density * (F * G1(reflected.normalized()) + (1.0 - F) * G1(-refracted));
            norm += density;
          }
      }
    return total / norm;  // norm = w.n / G1(w): the VNDF's normalisation
  }
};

// Photons through the axis at theta_i: the mean first-event loss.
struct Measured {
  double mean, std_error;
};
Measured first_event_loss(RoughnessModel model, double alpha, double theta_i, int n) {
  Settings s;
  s.fiber.eta = 1.55;
  s.fiber.sigma_a = {0.0};
  s.roughness.model = model;
  s.roughness.alpha_long = s.roughness.alpha_azim = alpha;
  s.roughness.masking = Masking::SmithG1;
  const Tracer tracer(s);
  const Vec3 wi = direction_from_angles(theta_i, 0.0);
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    PhotonRandom rng(99, static_cast<std::uint64_t>(i));
    const PhotonOutcome o = tracer.trace(wi, 0.0, rng);
    double loss = 0.0;
    if (!o.losses.empty() && o.losses.front().path_length == 0.0) loss = o.losses.front().weight;
    // A second loss at path 0 would be a repeated event at the entry point: none without tilt.
    if (o.losses.size() > 1) {
      EXPECT_GT(o.losses[1].path_length, 0.0);
    }
    sum += loss;
    sum2 += loss * loss;
  }
  const double mean = sum / n;
  return {mean, std::sqrt((sum2 / n - mean * mean) / (n - 1))};
}

TEST(MicrofacetMasking, FirstEventLossIsOneMinusTheExpectedG1) {
  struct Case {
    RoughnessModel model;
    double alpha, theta_i_deg;
  };
  // (Beckmann masks little but near grazing: its cases are rougher or more oblique.)
  for (const Case c : {Case{RoughnessModel::GGX, 0.3, 0.0}, Case{RoughnessModel::GGX, 0.5, 50.0},
                       Case{RoughnessModel::Beckmann, 0.7, 20.0}, Case{RoughnessModel::Beckmann, 0.5, 50.0}}) {
    const double theta_i = deg_to_rad(c.theta_i_deg);
    const Definition def{c.model, c.alpha};
    // Local frame of the entry point's normal n0 = (0, 1, 0): z = n0, x = u.
    const Vec3 wi = direction_from_angles(theta_i, 0.0);
    const Vec3 w_local(wi.x(), wi.z(), wi.y());
    const double expected = 1.0 - def.expected_factor(w_local, 1.55);
    const Measured m = first_event_loss(c.model, c.alpha, theta_i, 200000);
    std::printf("%s alpha %.1f theta_i %.0f: first-event loss %.5f +- %.5f, definition %.5f\n",
                to_string(c.model).c_str(), c.alpha, c.theta_i_deg, m.mean, m.std_error, expected);
    EXPECT_GT(expected, 0.005);  // a visible effect to test
    EXPECT_NEAR(m.mean, expected, 5.0 * m.std_error + 1e-5);
  }
}

}  // namespace
}  // namespace fiberlab::sim
