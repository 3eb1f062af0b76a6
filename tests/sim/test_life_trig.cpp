// sim/simd/life_trig.h against the C library's sin and cos (the oracle), and its
// scalar and vector forms against each other (the photon-by-photon
// equivalence of the two tracers rests on them giving the same bits).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "sim/simd/life_trig.h"

namespace fiberlab::sim::life {
namespace {

// |a - b| in units of b's last place (b the correctly rounded-ish libm value).
double ulps(double a, double b) {
  const double ulp = std::nextafter(std::abs(b), INFINITY) - std::abs(b);
  return std::abs(a - b) / ulp;
}

// Error of one pair against libm: at most 2 ulps of the result, or 2^-53
// absolute where the result is near 0 (a relative bound means nothing there:
// the angle itself carries an absolute rounding of that size).
void expect_close(double got, double want, const char* what, double arg) {
  if (std::abs(want) < 1e-3) {
    EXPECT_LE(std::abs(got - want), 0x1.0p-52) << what << " at " << arg;
  } else {
    EXPECT_LE(ulps(got, want), 2.0) << what << " at " << arg << ": " << got << " vs " << want;
  }
}

TEST(LifeTrig, SmallAnglesMatchTheLibraryToTwoUlps) {
  // Mutations caught: a wrong coefficient anywhere (even the highest of sin's
  // off by 10%: about 60 ulps at pi/4) or a dropped term moves the result by
  // far more than 2 ulps near pi/4.
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> angle(-0.7853981633974483, 0.7853981633974483);
  std::vector<double> xs = {0.0, 1e-300, -1e-8, 0.1, -0.5, 0.7853981633974483, -0.7853981633974483};
  for (int i = 0; i < 200000; ++i) xs.push_back(angle(gen));
  for (double x : xs) {
    const auto [s, c] = sincos_small(x);
    expect_close(s, std::sin(x), "sin", x);
    expect_close(c, std::cos(x), "cos", x);
  }
}

TEST(LifeTrig, LargeAnglesMatchTheLibraryToTwoUlps) {
  // Beyond pi/4 (the gaussian sampler's far offsets): the reduction by
  // multiples of pi/2. Mutations caught: a quadrant's cosine sign wrong, or
  // q not taken modulo 4 (errors ~1e-4 and more), pi/2's second part dropped
  // (sin near multiples of pi/2 off by ~q 6e-17: 1e-14, 45 times the bound).
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> angle(-100.0, 100.0);
  std::vector<double> xs = {0.79, -1.0, 3.0, 100.0, -1e4, 0x1.0p20, -0x1.0p20};
  for (int q = -1000; q <= 1000; ++q) {  // at and next to multiples of pi/2
    const double x = q * 1.5707963267948966;
    xs.insert(xs.end(), {x, std::nextafter(x, -INFINITY), std::nextafter(x, INFINITY)});
  }
  for (int q = 1; q <= 200; ++q) xs.push_back(q * 4999.3 * 1.5707963267948966);
  for (int i = 0; i < 200000; ++i) xs.push_back(angle(gen));
  for (double x : xs) {
    const auto [s, c] = sincos_small(x);
    expect_close(s, std::sin(x), "sin", x);
    expect_close(c, std::cos(x), "cos", x);
  }
  for (double x : {2e6, -1e9}) {  // beyond 2^20: the library itself
    EXPECT_EQ(sincos_small(x).first, std::sin(x));
    EXPECT_EQ(sincos_small(x).second, std::cos(x));
  }
}

TEST(LifeTrig, TurnsMatchTheLibraryInEveryQuadrant) {
  // Mutations caught: a quadrant's sign or sin/cos swap wrong (errors of
  // order 1), the quarter rounded down instead of to nearest (arguments up
  // to pi/2 outside the kernel's range: errors of ~1e-9 and more).
  std::vector<double> us = {0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0 - 0x1.0p-53};
  std::mt19937_64 gen(11);
  for (int i = 0; i < 200000; ++i) us.push_back(static_cast<double>(gen() >> 11) * 0x1.0p-53);
  for (double u : us) {
    const double a = 6.283185307179586 * u;
    const auto [s, c] = sincos_turn(u);
    // 2 pi u itself is rounded (relative 2^-53, absolute up to 2^-50 near
    // u = 1), so compare with an absolute bound of a few of those.
    EXPECT_LE(std::abs(s - std::sin(a)), 4 * 0x1.0p-52) << "sin at u = " << u;
    EXPECT_LE(std::abs(c - std::cos(a)), 4 * 0x1.0p-52) << "cos at u = " << u;
  }
}

TEST(LifeTrig, VectorLanesGiveTheScalarBits) {
  alignas(64) double x[kBatchWidth], u[kBatchWidth];
  std::mt19937_64 gen(3);
  for (int round = 0; round < 10000; ++round) {
    for (int k = 0; k < kBatchWidth; ++k) {
      u[k] = static_cast<double>(gen() >> 11) * 0x1.0p-53;
      x[k] = (u[k] - 0.5) * (round % 2 == 0 ? 1.5 : 200.0);  // the kernel, or the reduction
    }
    const auto [vs, vc] = sincos_small(Batch::load_aligned(x));
    const auto [ts, tc] = sincos_turn(Batch::load_aligned(u));
    for (int k = 0; k < kBatchWidth; ++k) {
      ASSERT_EQ(vs.get(k), sincos_small(x[k]).first);
      ASSERT_EQ(vc.get(k), sincos_small(x[k]).second);
      ASSERT_EQ(ts.get(k), sincos_turn(u[k]).first);
      ASSERT_EQ(tc.get(k), sincos_turn(u[k]).second);
    }
  }
}

}  // namespace
}  // namespace fiberlab::sim::life
