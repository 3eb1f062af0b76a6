// sim/simd/life_log.h against the C library's log (the oracle) on the arguments
// the sampler gives it (uniforms, products of two, their extremes, and both
// sides of the reduction's sqrt(2) threshold), and its scalar and vector
// forms against each other (the two tracers must draw the same bits).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/simd/life_log.h"
#include "sim/life/random.h"

namespace fiberlab::sim::life {
namespace {

double ulps(double a, double b) {
  const double ulp = std::nextafter(std::abs(b), INFINITY) - std::abs(b);
  return std::abs(a - b) / ulp;
}

std::vector<double> sampler_arguments() {
  std::vector<double> xs = {0x1.0p-53, 0x1.0p-106, 0x1.0p-53 * 0x1.0p-52, 1.0 - 0x1.0p-53,
                            1.0 - 0x1.0p-52, 0.5, 0.25, 0x1.0p-1022, 0.7, 0.9999};
  // Both sides of the reduction's threshold, sqrt(2)'s mantissa, at many exponents.
  for (int e = -60; e <= 0; ++e) {
    const double t = std::ldexp(0x1.6a09e00000000p0, e - 1);
    xs.insert(xs.end(), {t, std::nextafter(t, 0.0), std::nextafter(t, 1.0),
                         std::ldexp(std::sqrt(2.0), e - 1)});
  }
  PhotonRandom rng(PhotonRandom::stream_key(9, 0.4, 0.0), 2);
  for (int i = 0; i < 200000; ++i) {
    const double u1 = rng.uniform_open0(), u2 = rng.uniform_open0();
    xs.insert(xs.end(), {u1, u1 * u2});
  }
  return xs;
}

// Mutations caught: any coefficient off by 1e-9 relative (the highest one by
// 1%), ln 2's low part dropped (k ulps off), the threshold constant off by
// one in its last hex digit (x just above sqrt(2)'s mantissa reduced wrong).
TEST(LifeLog, MatchesTheLibraryToOneUlp) {
  double worst = 0.0, worst_at = 0.0;
  for (double x : sampler_arguments()) {
    const double got = log_normal(x), want = std::log(x);
    ASSERT_LE(ulps(got, want), 1.0) << "log at " << x << ": " << got << " vs " << want;
    if (ulps(got, want) > worst) worst = ulps(got, want), worst_at = x;
  }
  std::printf("largest difference from std::log: %.3f ulp at %a\n", worst, worst_at);
}

TEST(LifeLog, VectorLanesGiveTheScalarBits) {
  const std::vector<double> xs = sampler_arguments();
  constexpr int W = NumberTraits<Batch2>::kWidth;
  for (std::size_t i = 0; i + W <= xs.size(); i += W) {
    alignas(64) double in[W], out[W];
    for (int k = 0; k < W; ++k) in[k] = xs[i + k];
    store_unaligned(log_normal(load<Batch2>(in)), out);
    for (int k = 0; k < W; ++k) ASSERT_EQ(out[k], log_normal(xs[i + k])) << xs[i + k];
  }
}

}  // namespace
}  // namespace fiberlab::sim::life
