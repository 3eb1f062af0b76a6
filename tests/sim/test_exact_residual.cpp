// Format 2 stores a bin's exact sum E (a 128-bit integer, value E / 2^60) as
// its float64 value v and the residual r = E - v 2^60 (ExactTally::split and
// join, sim/store/exact_tally.h). The oracle is the definition of correct rounding,
// checked on integers: v 2^60 + r == E, |r| <= half an ulp of v 2^60, and on
// a tie the even neighbour (so v is the one nearest double, ties to even).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "common/error.h"
#include "sim/store/exact_tally.h"

namespace fiberlab::sim {
namespace {

using Word = ExactTally::Word;

Word pow2(int k) { return Word{1} << k; }

// The whole number v 2^60 (v 2^60 is a whole number below 2^128 here).
Word scaled(double v) { return static_cast<Word>(std::ldexp(v, 60)); }

// The ulp of the double x (> 0, whole).
Word ulp(double x) {
  int e = 0;
  std::frexp(x, &e);  // x = m 2^e, 0.5 <= m < 1: the last of 53 bits is 2^(e - 53)
  return e - 53 <= 0 ? Word{1} : pow2(e - 53);
}

// Probes: zero, the 53-bit boundary with its ties (2^53 + 1 rounds down to
// 2^53, 2^53 + 3 up to 2^53 + 4), the 64-bit boundary, and the largest sum
// split() stores.
std::vector<Word> probes() {
  std::vector<Word> v{0, 1, 12345, pow2(53) - 1, pow2(53), pow2(53) + 1, pow2(53) + 2,
                      pow2(53) + 3, pow2(64) - 1, pow2(64), pow2(64) + 1, pow2(64) + pow2(11),
                      pow2(64) + pow2(11) * 3, pow2(80) + pow2(27), pow2(116) - 1};
  std::mt19937_64 g(20261204);
  for (int i = 0; i < 4000; ++i) {
    const int bits = 1 + static_cast<int>(g() % 116);  // below 2^116
    const Word w = (static_cast<Word>(g()) << 64 | g()) & (pow2(bits) - 1);
    v.push_back(w);
  }
  return v;
}

TEST(ExactResidual, SplitRoundsToNearestEvenAndKeepsTheRest) {
  const std::vector<Word> e = probes();
  std::vector<double> value;
  std::vector<std::int64_t> residual;
  ExactTally::split(e, value, residual);
  ASSERT_EQ(value.size(), e.size());
  for (std::size_t i = 0; i < e.size(); ++i) {
    const Word base = scaled(value[i]);
    const __int128 r = residual[i];
    // v 2^60 + r is E.
    EXPECT_TRUE(static_cast<__int128>(e[i] - base) == r) << i;
    if (e[i] < pow2(53)) {
      EXPECT_EQ(residual[i], 0) << "exact as a double below 2^53: " << i;
      continue;
    }
    // Nearest: |r| at most half an ulp; on a tie the even neighbour.
    const Word half = ulp(static_cast<double>(base)) / 2;
    const Word magnitude = r >= 0 ? static_cast<Word>(r) : static_cast<Word>(-r);
    EXPECT_LE(static_cast<double>(magnitude), static_cast<double>(half)) << i;
    if (magnitude == half) EXPECT_EQ((base / (2 * half)) % 2, 0u) << "a tie rounds to even: " << i;
  }
  // The ties next to 2^53 by hand: 2^53 + 1 -> 2^53 (r = 1), 2^53 + 3 -> 2^53 + 4 (r = -1).
  EXPECT_EQ(residual[5], 1);
  EXPECT_EQ(scaled(value[5]), pow2(53));
  EXPECT_EQ(residual[7], -1);
  EXPECT_EQ(scaled(value[7]), pow2(53) + 4);
}

TEST(ExactResidual, SplitGivesTheFloatSumsToDouble) {
  const std::vector<Word> e = probes();
  std::vector<double> value, plain;
  std::vector<std::int64_t> residual;
  ExactTally::split(e, value, residual);
  ExactTally::to_double(e, plain);
  for (std::size_t i = 0; i < e.size(); ++i) EXPECT_EQ(value[i], plain[i]) << i;
}

TEST(ExactResidual, JoinInvertsSplit) {
  const std::vector<Word> e = probes();
  std::vector<double> value;
  std::vector<std::int64_t> residual;
  ExactTally::split(e, value, residual);
  std::vector<Word> back;
  EXPECT_EQ(ExactTally::join(value, residual, back), -1);
  EXPECT_TRUE(back == e);
}

TEST(ExactResidual, SplitRefusesSumsItCannotStore) {
  std::vector<double> value;
  std::vector<std::int64_t> residual;
  EXPECT_THROW(ExactTally::split({pow2(116)}, value, residual), Error);
  EXPECT_THROW(ExactTally::split({~Word{0}}, value, residual), Error);
}

// What split() never writes is refused, cell by cell: the first bad index.
TEST(ExactResidual, JoinRefusesWhatSplitNeverWrites) {
  std::vector<Word> out;
  const double one = 1.0;  // E = 2^60
  auto first_bad = [&](double v, std::int64_t r) {
    return ExactTally::join({one, v}, {0, r}, out);
  };
  EXPECT_EQ(first_bad(one, 0), -1);
  EXPECT_EQ(first_bad(NAN, 0), 1);
  EXPECT_EQ(first_bad(INFINITY, 0), 1);
  EXPECT_EQ(first_bad(-one, 0), 1);
  EXPECT_EQ(first_bad(0x1.0p-70, 0), 1);  // not a whole multiple of 2^-60
  EXPECT_EQ(first_bad(0x1.0p68, 0), 1);   // 2^128: beyond 128 bits
  EXPECT_EQ(first_bad(0.0, 1), 1);        // E = 1 rounds to 2^-60, not 0
  EXPECT_EQ(first_bad(0.0, -1), 1);       // E < 0
  // 2^60 + r rounds back to 2^60 for r in [-64, 128]: ulps 2^7 below 2^60,
  // 2^8 above, and both ties go to 2^60 (even).
  EXPECT_EQ(first_bad(one, 64), -1);
  EXPECT_EQ(first_bad(one, -32), -1);
  EXPECT_EQ(first_bad(one, 129), 1);
  EXPECT_EQ(first_bad(one, 128), -1);
  EXPECT_EQ(first_bad(one, -64), -1);
  EXPECT_EQ(first_bad(one, -65), 1);
}

}  // namespace
}  // namespace fiberlab::sim
