// Tally (sim/store/tally.h) keeps its sums on lazily zeroed pages and visits only
// the pages it wrote when adding, clearing, copying and exporting, and the
// result writer (sim/store/result_stream.h) reads it in place, a lobe at a time.
// Oracle: the same sums kept densely by this test, in plain 128-bit integers.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "sim/store/checkpoint.h"
#include "sim/store/result_stream.h"
#include "sim/store/tally.h"

#include "tests/sim/sim_test_support.h"
#include "tests/unique_temp_dir.h"

namespace fiberlab::sim {
namespace {

// A large enough tally to live on its own mapping (> 1 MiB): 4 x 90 x 180
// bins of 7 cells of 16 bytes.
constexpr int kLobes = 4, kTheta = 90, kPhi = 180, kChannels = 3;

struct DenseSums {
  std::vector<std::uint64_t> count = std::vector<std::uint64_t>(kLobes * kTheta * kPhi, 0);
  std::vector<ExactTally::Word> s1 = std::vector<ExactTally::Word>(count.size() * kChannels, 0);
  std::vector<ExactTally::Word> s2 = s1;
  std::vector<ExactTally::Word> truncated = std::vector<ExactTally::Word>(kChannels, 0);
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
    const int l = lobe(g), a = theta(g) + 15 * l, p = phi(g);  // rows 20-75: lobes touch different pages
    const double w[kChannels] = {u(g), u(g), u(g)};
    t.score_exit(l, a, p, w);
    const std::size_t b = (static_cast<std::size_t>(l) * kTheta + a) * kPhi + p;
    ++d.count[b];
    for (int c = 0; c < kChannels; ++c) {
      d.s1[b * kChannels + c] += fixed(w[c]);
      d.s2[b * kChannels + c] += fixed(w[c] * w[c]);
    }
  }
  // A few photons truncated (the ledger's third term).
  for (int i = 0; i < n / 100; ++i) {
    const double w[kChannels] = {u(g), u(g), u(g)};
    t.score_truncated(w);
    for (int c = 0; c < kChannels; ++c) d.truncated[c] += fixed(w[c]);
  }
  t.add_launched(n + n / 100);
  d.photons += n + n / 100;
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

// The result file at `path` holds the dense sums exactly, as exact pairs and
// as float64 = exact / 2^60, with the ledger derived from them.
void expect_holds_dense_sums(const std::string& path, const std::vector<DenseSums>& dense) {
  const ResultReader reader(path);
  const ResultFile doubles = read_result(path);
  for (std::size_t k = 0; k < dense.size(); ++k) {
    const DenseSums& d = dense[k];
    const ExactTally e = reader.read(k);
    EXPECT_EQ(e.photons, d.photons);
    EXPECT_TRUE(e.count == d.count);
    EXPECT_TRUE(e.weight_sum == d.s1);
    EXPECT_TRUE(e.weight_sq_sum == d.s2);
    EXPECT_TRUE(e.truncated == d.truncated);
    const std::size_t per_lobe = static_cast<std::size_t>(kTheta) * kPhi;
    for (int c = 0; c < kChannels; ++c) {
      ExactTally::Word exited_total = 0;
      for (int l = 0; l < kLobes; ++l) {
        ExactTally::Word exited = 0;
        for (std::size_t b = 0; b < per_lobe; ++b) exited += d.s1[(l * per_lobe + b) * kChannels + c];
        EXPECT_TRUE(e.exited[l * kChannels + c] == exited) << "lobe " << l << " channel " << c;
        exited_total += exited;
      }
      const ExactTally::Word launched = static_cast<ExactTally::Word>(d.photons) << 60;
      EXPECT_TRUE(e.absorbed[c] == launched - exited_total - d.truncated[c]) << "channel " << c;
    }
    const std::size_t cells = d.s1.size();
    for (std::size_t i = 0; i < cells; ++i) {
      ASSERT_EQ(doubles.weight_sum[k * cells + i], static_cast<double>(d.s1[i]) / 0x1.0p60) << i;
      ASSERT_EQ(doubles.weight_sq_sum[k * cells + i], static_cast<double>(d.s2[i]) / 0x1.0p60) << i;
    }
  }
}

// `run` writes each direction's tally in place (ResultWriter::write(k,
// Tally), lobe by lobe into rows of the datasets, the lobes on the writer's
// threads): the file must hold the dense sums exactly.
TEST(TallyPages, WrittenInPlaceReadsBackAsTheDenseSums) {
  Settings s = testing::smooth_circle(30.0, 1);
  s.fiber.sigma_a = {0.1, 0.2, 0.3};
  s.source.theta_i = {deg_to_rad(10.0), deg_to_rad(40.0)};
  const BinGrid grid = BinGrid::make(kTheta, kPhi, s.tally.theta_bins);
  ASSERT_EQ(s.tally.lobes, kLobes);
  std::vector<Tally> tallies(2, Tally(kLobes, kTheta, kPhi, kChannels));
  std::vector<DenseSums> dense(2);
  score(tallies[0], dense[0], 5000, 3);
  score(tallies[1], dense[1], 2000, 4);
  const auto dir = test_support::unique_temp_dir("fiberlab_test_tally_write");
  // One writing thread, and more threads than lobes divide evenly among.
  for (int threads : {1, 3}) {
    SCOPED_TRACE(::testing::Message() << threads << " writing threads");
    const std::string path = (dir / ("r" + std::to_string(threads) + ".h5")).string();
    ResultWriter w(path, result_header(s, grid));
    w.set_compression_threads(threads);
    for (std::size_t k = 0; k < 2; ++k) w.write(k, tallies[k]);
    w.commit();
    expect_holds_dense_sums(path, dense);
  }
}

// The float64 datasets are the exact sums / 2^60 rounded once, below and
// above 2^64 (where the high word is used): values whose doubles are known.
// The result writer's cost hint: per lobe, the bins on pages (64 bins) the
// tally wrote. Oracle: the pages worked out by hand for 90 x 180 bins a lobe.
TEST(TallyPages, TouchedBinsPerLobeCountTheWrittenPagesOfEachLobe) {
  Tally t(kLobes, kTheta, kPhi, kChannels);
  EXPECT_EQ(t.touched_bins_per_lobe(), (std::vector<std::size_t>{0, 0, 0, 0}));
  const double w[kChannels] = {0.5, 0.25, 0.125};
  // Bin 16200 (lobe 1's first): page 253 = bins 16192..16255, of which
  // 16192..16199 are lobe 0's last 8 and the rest lobe 1's.
  t.score_exit(1, 0, 0, w);
  // Bin 64799 (lobe 3's last): page 1012 = bins 64768..64799, the last page.
  t.score_exit(3, kTheta - 1, kPhi - 1, w);
  EXPECT_EQ(t.touched_bins_per_lobe(), (std::vector<std::size_t>{8, 56, 0, 32}));
  t.clear();
  EXPECT_EQ(t.touched_bins_per_lobe(), (std::vector<std::size_t>{0, 0, 0, 0}));
}

TEST(ExactTallyToDouble, RoundsOnceBelowAndAbove2To64) {
  using Word = ExactTally::Word;
  const Word two64 = Word{1} << 64;
  const std::vector<Word> v{0,
                            Word{3} << 59,            // 1.5
                            two64 - 1,                // rounds up to 2^64: 16
                            two64 + (Word{1} << 12),  // 2^64 + one ulp: 16 + 2^-48
                            two64 + (Word{1} << 11),  // half an ulp, ties to even: 16
                            (Word{5} << 100) + 7};    // 5 * 2^40
  const std::vector<double> expected{0.0, 1.5, 16.0, 16.0 + 0x1.0p-48, 16.0, 5.0 * 0x1.0p40};
  EXPECT_EQ(ExactTally::to_double(v), expected);
}

}  // namespace
}  // namespace fiberlab::sim
