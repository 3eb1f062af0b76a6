// TRT caustics (SPEC section 8) and the cuticle tilt's lobe shifts (SPEC
// section 7, Marschner 2003 section 2.2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

// Bravais' index for the projection into the normal plane (SPEC section 7).
double eta_prime(double eta, double theta) {
  return std::sqrt(eta * eta - std::sin(theta) * std::sin(theta)) / std::cos(theta);
}

// Descartes: the caustic sits where dPhi(2, h)/dh = 0, h^2 = (4 - eta'^2) / 3,
// Phi(2, h) = 4 gamma_t - 2 gamma_i + 2 pi (Marschner 2003 Eq. 3).
double descartes_phi(double eta_p) {
  const double h = std::sqrt((4.0 - eta_p * eta_p) / 3.0);
  return wrap_angle(4.0 * std::asin(h / eta_p) - 2.0 * std::asin(h) + 2.0 * kPi);
}

// The sharpest bin of a phi histogram relative to its neighbours two bins away:
// a caustic (an inverse-square-root singularity with a dark side) gives ~6,
// a smooth distribution ~1.
struct Peak {
  int bin;
  double sharpness;
};
Peak sharpest_bin(const std::vector<double>& h) {
  const int n = static_cast<int>(h.size());
  const double total = [&] { double s = 0; for (double x : h) s += x; return s; }();
  Peak best{-1, 0.0};
  for (int j = 0; j < n; ++j) {
    if (h[j] < 1e-3 * total) continue;  // ignore near-empty bins
    const double neighbours = 0.5 * (h[(j + 2) % n] + h[(j - 2 + n) % n]);
    const double s = h[j] / std::max(neighbours, 1e-300);
    if (s > best.sharpness) best = {j, s};
  }
  return best;
}

TEST(Caustics, TrtCausticsWhereDescartesPutsThem) {
  for (double theta_deg : {0.0, 30.0}) {
    Settings s = testing::smooth_circle(theta_deg + 0.3, 4000000);
    s.tally.n_phi = 360;  // 1-degree bins
    const ResultFile r = testing::run(s);
    const std::vector<double> trt = testing::phi_marginal(r, 0, 2, 0);
    const double phi_c = descartes_phi(eta_prime(1.55, deg_to_rad(theta_deg + 0.3)));
    // Both caustics (+phi_c and -phi_c) are the sharpest features on their side.
    for (double sign : {1.0, -1.0}) {
      std::vector<double> half(trt.size(), 0.0);
      for (int j = 0; j < r.grid.n_phi(); ++j) {
        const double centre = 0.5 * (r.grid.phi_edges[j] + r.grid.phi_edges[j + 1]);
        if (sign * centre > 0.0) half[j] = trt[j];
      }
      const Peak p = sharpest_bin(half);
      const double centre = 0.5 * (r.grid.phi_edges[p.bin] + r.grid.phi_edges[p.bin + 1]);
      std::printf("theta_i %.1f: caustic expected at %.2f deg, sharpest bin at %.2f deg (x%.1f)\n",
                  theta_deg + 0.3, rad_to_deg(sign * phi_c), rad_to_deg(centre), p.sharpness);
      EXPECT_NEAR(centre, sign * phi_c, deg_to_rad(1.5));
      EXPECT_GT(p.sharpness, 3.0);
    }
  }
}

TEST(Caustics, NoCausticOnceEtaPrimeExceedsTwo) {
  const double theta = deg_to_rad(60.3);
  ASSERT_GT(eta_prime(1.55, theta), 2.0);
  Settings s = testing::smooth_circle(60.3, 4000000);
  s.tally.n_phi = 360;
  const ResultFile r = testing::run(s);
  const Peak p = sharpest_bin(testing::phi_marginal(r, 0, 2, 0));
  std::printf("theta_i 60.3: sharpest TRT bin x%.2f\n", p.sharpness);
  EXPECT_LT(p.sharpness, 1.5);
}

// Mean theta_r + theta_i of each lobe, from the histogram's bin centres.
double mean_shift(const ResultFile& r, int lobe, double theta_i) {
  const std::vector<double> m = testing::theta_marginal(r, 0, lobe, 0);
  double s = 0.0, w = 0.0;
  for (int i = 0; i < r.grid.n_theta(); ++i) {
    s += m[i] * 0.5 * (r.grid.theta_edges[i] + r.grid.theta_edges[i + 1]);
    w += m[i];
  }
  return s / w + theta_i;
}

// Tilt: R moves towards the root (theta_r decreases), TT and TRT towards the
// tip. SPEC section 7 gives the h = 0 estimates -2 alpha, +alpha, +4 alpha and
// says an exact simulation moves R by about -1.2 alpha on average.
TEST(Tilt, LobesShiftTheWayTheCuticleScalesPoint) {
  const double alpha = deg_to_rad(3.0), theta_i = deg_to_rad(30.1);
  Settings s = testing::smooth_circle(30.1, 1000000);
  s.fiber.scale_tilt = alpha;
  s.tally.n_theta = 720;  // 0.25-degree bins
  s.tally.n_phi = 4;
  const ResultFile r = testing::run(s);
  const double r_shift = mean_shift(r, 0, theta_i) / alpha;
  const double tt_shift = mean_shift(r, 1, theta_i) / alpha;
  const double trt_shift = mean_shift(r, 2, theta_i) / alpha;
  std::printf("measured mean shifts of theta_r in units of alpha: R %.3f, TT %.3f, TRT %.3f\n",
              r_shift, tt_shift, trt_shift);
  RecordProperty("shift_R_alpha", std::to_string(r_shift));
  RecordProperty("shift_TT_alpha", std::to_string(tt_shift));
  RecordProperty("shift_TRT_alpha", std::to_string(trt_shift));
  EXPECT_LT(r_shift, -0.5);
  EXPECT_GT(r_shift, -2.5);
  EXPECT_GT(tt_shift, 0.2);
  EXPECT_GT(trt_shift, 1.0);
}

}  // namespace
}  // namespace fiberlab::sim
