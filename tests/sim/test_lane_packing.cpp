// sim/simd/lane_packing.h: for every mask of a vector's lanes, lane_bits gives
// its bits and pack_store writes exactly the selected lanes, lowest first,
// leaving what lies past the vector's room untouched.
#include <gtest/gtest.h>

#include <bit>

#include <cstdint>
#include <vector>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lane_packing.h"

namespace fiberlab::sim::life {
namespace {

constexpr int W = kBatchWidth;
constexpr double kSentinel = -7.0;

MaskOf<Batch> mask_of(std::uint64_t bits) {
  alignas(64) double v[W];
  for (int k = 0; k < W; ++k) v[k] = (bits >> k) & 1 ? 1.0 : 0.0;
  return Batch::load_aligned(v) == Batch(1.0);
}

TEST(LanePacking, LaneBitsAreTheMask) {
  for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << W); ++bits)
    EXPECT_EQ(lane_bits(mask_of(bits)), bits);
}

TEST(LanePacking, PackStoreWritesTheSelectedLanesInOrder) {
  alignas(64) double v[W];
  alignas(64) std::uint64_t w[W];
  for (int k = 0; k < W; ++k) {
    v[k] = 10.0 + k;
    w[k] = 0x1000000000000000ULL + static_cast<std::uint64_t>(k);
  }
  const Batch x = Batch::load_aligned(v);
  const BitsOf<Batch> y = BitsOf<Batch>::load_aligned(w);
  for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << W); ++bits) {
    // Room for a whole vector at offset 3, sentinels around it.
    std::vector<double> out(W + 6, kSentinel);
    std::vector<std::uint64_t> out_bits(W + 6, 0);
    pack_store(x, bits, out.data() + 3);
    pack_store(y, bits, out_bits.data() + 3);
    int j = 3;
    for (int k = 0; k < W; ++k) {
      if (!((bits >> k) & 1)) continue;
      EXPECT_EQ(out[j], v[k]) << "mask " << bits << " lane " << k;
      EXPECT_EQ(out_bits[j], w[k]) << "mask " << bits << " lane " << k;
      ++j;
    }
    for (int i = 0; i < 3; ++i) EXPECT_EQ(out[i], kSentinel) << "mask " << bits;
    for (int i = 3 + W; i < W + 6; ++i) EXPECT_EQ(out[i], kSentinel) << "mask " << bits;
  }
}

// A Pair of vectors (sim/simd/lane_pair.h) packs as one vector of 2 W lanes.
TEST(LanePacking, APairPacksAsOneVectorOfTwiceTheLanes) {
  constexpr int W2 = NumberTraits<Batch2>::kWidth;
  alignas(64) double v[W2];
  for (int k = 0; k < W2; ++k) v[k] = 100.0 + k;
  const Batch2 x = Batch2::load_aligned(v);
  for (std::uint64_t bits = 0; bits < (std::uint64_t{1} << W2); bits += 1 + (bits % 7)) {
    const std::uint64_t low = bits & ((std::uint64_t{1} << W) - 1);
    const MaskOf<Batch2> m(mask_of(low), mask_of(bits >> W));
    EXPECT_EQ(lane_bits(m), bits);
    std::vector<double> out(W2 + 2, kSentinel);
    pack_store(x, bits, out.data());
    int j = 0;
    for (int k = 0; k < W2; ++k) {
      if (!((bits >> k) & 1)) continue;
      EXPECT_EQ(out[j++], v[k]) << "mask " << bits << " lane " << k;
    }
    for (int i = W2; i < W2 + 2; ++i) EXPECT_EQ(out[i], kSentinel) << "mask " << bits;
  }
}

// pack_bits packs a mask's lane bits as pack_store packs lanes: bit j of the
// result is the bit of the j-th selected lane, lowest first (oracle: that
// definition, one lane at a time), for every selection of 16 lanes.
TEST(LanePacking, PackBitsKeepsTheSelectedLanesBitsInOrder) {
  std::uint64_t bits = 0x9e3779b97f4a7c15u;  // a fixed pattern, rotated per selection
  for (std::uint64_t lanes = 0; lanes < (std::uint64_t{1} << 16); ++lanes) {
    bits = std::rotl(bits, 5);
    std::uint64_t expected = 0;
    int j = 0;
    for (int k = 0; k < 16; ++k)
      if ((lanes >> k) & 1) expected |= ((bits >> k) & 1) << j++;
    ASSERT_EQ(pack_bits(bits, lanes), expected) << "lanes " << lanes << " bits " << bits;
  }
}

}  // namespace
}  // namespace fiberlab::sim::life
