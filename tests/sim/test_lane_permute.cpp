// sim/simd/lane_permute.h: permute_lanes puts lane index[j] of its vector
// in lane j, for a vector of doubles and of words, and for a Pair across
// both halves; mask_of_bits is the inverse of lane_bits. Every index is
// compared lane by lane with the vector as stored in memory.
#include <gtest/gtest.h>

#include <cstdint>

#include "sim/simd/lane_packing.h"
#include "sim/simd/lane_pair.h"
#include "sim/simd/lane_permute.h"

namespace fiberlab::sim::life {
namespace {

// Lane j of a vector of n lanes takes index (j * step + shift) mod n:
// every lane from every lane over the steps and shifts below.
template <class V, class I, int n>
void expect_permutes(const V& x, const double* v) {
  for (int step = 0; step < n; ++step)
    for (int shift = 0; shift < n; ++shift) {
      alignas(64) std::uint64_t index[n];
      for (int j = 0; j < n; ++j) index[j] = static_cast<std::uint64_t>((j * step + shift) % n);
      const I k = I::load_aligned(index);
      alignas(64) double out[n];
      permute_lanes(x, k).store_aligned(out);
      for (int j = 0; j < n; ++j) EXPECT_EQ(out[j], v[index[j]]) << "step " << step << " shift " << shift;
    }
}

TEST(LanePermute, APermutationTakesEachLaneFromItsIndex) {
  constexpr int W = kBatchWidth, W2 = 2 * kBatchWidth;
  alignas(64) double v[W2];
  alignas(64) std::uint64_t w[W2];
  for (int k = 0; k < W2; ++k) {
    v[k] = 10.0 + k;
    w[k] = 0xabc0000000000000ULL + static_cast<std::uint64_t>(k);
  }
  expect_permutes<Batch, BitsOf<Batch>, W>(Batch::load_aligned(v), v);
  expect_permutes<Batch2, BitsOf<Batch2>, W2>(Batch2::load_aligned(v), v);
  // Words: the same permutation of 64-bit patterns.
  for (int shift = 0; shift < W2; ++shift) {
    alignas(64) std::uint64_t index[W2], out[W2];
    for (int j = 0; j < W2; ++j) index[j] = static_cast<std::uint64_t>((W2 - 1 - j + shift) % W2);
    permute_lanes(BitsOf<Batch2>::load_aligned(w), BitsOf<Batch2>::load_aligned(index)).store_aligned(out);
    for (int j = 0; j < W2; ++j) EXPECT_EQ(out[j], w[index[j]]) << "shift " << shift;
  }
  EXPECT_EQ(permute_lanes(2.5, std::uint64_t{0}), 2.5);
}

TEST(LanePermute, MaskOfBitsIsTheInverseOfLaneBits) {
  constexpr int W2 = 2 * kBatchWidth;
  for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << W2); bits += (bits < 512 ? 1 : 97))
    EXPECT_EQ(lane_bits(mask_of_bits<Batch2>(bits)), bits);
  for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << kBatchWidth); ++bits)
    EXPECT_EQ(lane_bits(mask_of_bits<Batch>(bits)), bits);
  EXPECT_TRUE(mask_of_bits<double>(1));
  EXPECT_FALSE(mask_of_bits<double>(0));
  EXPECT_EQ(lane_bits(true), 1u);
}

}  // namespace
}  // namespace fiberlab::sim::life
