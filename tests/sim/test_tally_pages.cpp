// Tally (sim/tally.h) keeps its sums on lazily zeroed pages and visits only
// the pages it wrote when adding, clearing, copying and exporting. Oracle: the
// same sums kept densely by this test, in plain 128-bit integers.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "sim/tally.h"

namespace fiberlab::sim {
namespace {

// A large enough tally to live on its own mapping (> 1 MiB): 4 x 90 x 180
// bins of 7 cells of 16 bytes.
constexpr int kLobes = 4, kTheta = 90, kPhi = 180, kChannels = 3;

struct DenseSums {
  std::vector<std::uint64_t> count = std::vector<std::uint64_t>(kLobes * kTheta * kPhi, 0);
  std::vector<ExactTally::Word> s1 = std::vector<ExactTally::Word>(count.size() * kChannels, 0);
  std::vector<ExactTally::Word> s2 = s1;
  std::uint64_t photons = 0;
};

ExactTally::Word fixed(double w) { return static_cast<ExactTally::Word>(static_cast<std::int64_t>(w * 0x1.0p60 + 0.5)); }

// Scores n photons into a few scattered bins (some pages never touched),
// into both the tally and the dense oracle.
void score(Tally& t, DenseSums& d, int n, std::uint32_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_int_distribution<int> lobe(0, kLobes - 1), theta(20, 30), phi(0, kPhi - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const int l = lobe(g), a = theta(g), p = phi(g);
    const double w[kChannels] = {u(g), u(g), u(g)};
    t.score_exit(l, a, p, w);
    const std::size_t b = (static_cast<std::size_t>(l) * kTheta + a) * kPhi + p;
    ++d.count[b];
    for (int c = 0; c < kChannels; ++c) {
      d.s1[b * kChannels + c] += fixed(w[c]);
      d.s2[b * kChannels + c] += fixed(w[c] * w[c]);
    }
  }
  t.add_launched(n);
  d.photons += n;
}

void expect_equal(const Tally& t, const DenseSums& d) {
  const ExactTally e = t.exact();
  EXPECT_EQ(e.photons, d.photons);
  EXPECT_TRUE(e.count == d.count);
  EXPECT_TRUE(e.weight_sum == d.s1);
  EXPECT_TRUE(e.weight_sq_sum == d.s2);
  std::vector<std::uint64_t> counted = t.count();
  EXPECT_TRUE(counted == d.count);
}

TEST(TallyPages, ScoredClearedReusedCopiedAndAddedEqualDenseSums) {
  Tally t(kLobes, kTheta, kPhi, kChannels);
  DenseSums first;
  score(t, first, 5000, 1);
  expect_equal(t, first);
  // Cleared and reused (what a thread's tally does between directions).
  t.clear();
  expect_equal(t, DenseSums{});
  DenseSums second;
  score(t, second, 3000, 2);
  expect_equal(t, second);
  // A copy holds the same sums; adding doubles them.
  Tally copy = t;
  expect_equal(copy, second);
  copy.add(t);
  DenseSums doubled = second;
  doubled.photons *= 2;
  for (auto& c : doubled.count) c *= 2;
  for (auto& w : doubled.s1) w *= 2;
  for (auto& w : doubled.s2) w *= 2;
  expect_equal(copy, doubled);
  // Back from exact integers into an empty tally.
  Tally from_exact(kLobes, kTheta, kPhi, kChannels);
  from_exact.add(copy.exact());
  expect_equal(from_exact, doubled);
}

}  // namespace
}  // namespace fiberlab::sim
