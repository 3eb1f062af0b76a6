// The photon streams (sim/life/random.h) against the generators' published
// definitions: SplitMix64 (Steele, Lea & Flood 2014) for seeding and
// xoshiro256+ (Blackman & Vigna, ACM TOMS 2021) for the stream, written here
// again in plain 64-bit arithmetic; a uniform is the output's top 52 bits
// times 2^-52. Also: the lanes of a vector draw their photons' own streams,
// the uniforms' end points, and a chi-square of their leading and lowest
// kept bits.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "sim/simd/lane_pair.h"
#include "sim/life/random.h"

namespace fiberlab::sim {
namespace {

// Steele, Lea & Flood's SplitMix64 finaliser, as published.
std::uint64_t reference_splitmix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Blackman & Vigna's xoshiro256+ (xoshiro256plus.c), as published.
struct ReferenceXoshiro256Plus {
  std::uint64_t s[4];
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t next() {
    const std::uint64_t result = s[0] + s[3];
    const std::uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
  }
  // The top 52 bits as a multiple of 2^-52, by integer conversion.
  double uniform() { return static_cast<double>(next() >> 12) * 0x1.0p-52; }
};

// A photon's stream as the docs of PhotonRandom say: SplitMix64 of (key ^
// photon), then four more times, one state word each.
ReferenceXoshiro256Plus reference_stream(std::uint64_t key, std::uint64_t photon) {
  ReferenceXoshiro256Plus g{};
  std::uint64_t x = reference_splitmix(key ^ photon);
  for (auto& w : g.s) w = x = reference_splitmix(x);
  return g;
}

TEST(PhotonRandom, IsTheReferenceXoshiro256PlusSeededBySplitMix64) {
  const std::uint64_t key = PhotonRandom::stream_key(42, 0.5, 0.25);
  for (std::uint64_t photon : {0ULL, 1ULL, 977ULL, 0xffffffffffULL}) {
    PhotonRandom rng(key, photon);
    ReferenceXoshiro256Plus ref = reference_stream(key, photon);
    for (int k = 0; k < 1000; ++k)
      ASSERT_EQ(rng.uniform(), ref.uniform()) << "photon " << photon << ", draw " << k;
  }
}

TEST(PhotonRandom, UniformsKeepTheirEndPointsOut) {
  // Output 0 (s0 + s3 = 0) and output 2^64 - 1 (s0 = 2^64 - 1, s3 = 0).
  life::LaneRandom<double> low(0, 1, 2, 0), high(~0ULL, 1, 2, 0);
  life::LaneRandom<double> low_open = low, high_open = high;
  EXPECT_EQ(low.uniform(true), 0.0);
  EXPECT_EQ(high.uniform(true), 1.0 - 0x1.0p-52);
  EXPECT_EQ(low_open.uniform_open0(true), 0x1.0p-53);
  EXPECT_EQ(high_open.uniform_open0(true), 1.0 - 0x1.0p-53);
  EXPECT_GT(std::log(0x1.0p-53), -40.0);
}

// Each lane of a vector draws its own photon's stream, and a lane outside
// the mask keeps its state (the next draw there is the one it skipped).
TEST(LaneRandom, LanesDrawTheirPhotonsStreamsWhereMasked) {
  using Lanes = life::Batch2;
  constexpr int W = life::NumberTraits<Lanes>::kWidth;
  const std::uint64_t key = PhotonRandom::stream_key(3, 0.2, 0.0);
  alignas(64) std::uint64_t photons[W];
  alignas(64) double on[W];
  for (int i = 0; i < W; ++i) {
    photons[i] = 100 + 7 * i;
    on[i] = i % 3 == 1 ? 0.0 : 1.0;
  }
  auto lanes = life::LaneRandom<Lanes>::seeded(key, life::load_bits<Lanes>(photons));
  const auto mask = life::load<Lanes>(on) != Lanes(0.0);
  std::vector<ReferenceXoshiro256Plus> refs;
  for (int i = 0; i < W; ++i) refs.push_back(reference_stream(key, photons[i]));
  for (int round = 0; round < 4; ++round) {
    const auto masked = lanes.uniforms<5>(mask);
    const auto all = lanes.uniforms<5>(Lanes(1.0) == Lanes(1.0));
    for (int i = 0; i < W; ++i) {
      // Masked lanes drew five numbers in the first call; every lane in the second.
      std::array<double, 10> expect{};
      const int n = on[i] != 0.0 ? 10 : 5;
      for (int k = 0; k < n; ++k) expect[k] = refs[i].uniform();
      alignas(64) double got[W];
      for (int k = 0; k < 5; ++k) {
        if (on[i] != 0.0) {
          life::store_unaligned(masked[k], got);
          ASSERT_EQ(got[i], expect[k]) << "lane " << i << ", round " << round;
        }
        life::store_unaligned(all[k], got);
        ASSERT_EQ(got[i], expect[(on[i] != 0.0 ? 5 : 0) + k]) << "lane " << i << ", round " << round;
      }
    }
  }
}

// Chi-square over 1024 bins of 2^20 uniforms: the leading ten bits (u 1024)
// and the lowest ten kept (bits 12-21 of the output, where a sum of two
// words is weakest above the dropped ones). 1023 degrees of freedom: mean
// 1023, sd 45.2; 1300 is 6.1 sd (p ~ 1e-8), so a fixed seed failing means
// the bits are not uniform.
TEST(PhotonRandom, LeadingAndLowestKeptBitsAreUniform) {
  constexpr int kBins = 1024, kDraws = 1 << 20;
  std::vector<double> lead(kBins, 0.0), low(kBins, 0.0);
  PhotonRandom rng(PhotonRandom::stream_key(11, 0.3, 0.0), 5);
  for (int k = 0; k < kDraws; ++k) {
    const double u = rng.uniform();
    lead[static_cast<int>(u * kBins)] += 1.0;
    low[static_cast<std::uint64_t>(u * 0x1.0p52) % kBins] += 1.0;
  }
  const double expected = static_cast<double>(kDraws) / kBins;
  auto chi2 = [&](const std::vector<double>& c) {
    double x = 0.0;
    for (double n : c) x += (n - expected) * (n - expected) / expected;
    return x;
  };
  EXPECT_LT(chi2(lead), 1300.0);
  EXPECT_LT(chi2(low), 1300.0);
}

}  // namespace
}  // namespace fiberlab::sim
