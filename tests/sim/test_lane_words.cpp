// The vector forms of 64-bit word operations that AVX2 lacks and the tracer
// builds from other instructions: life::to_bits (sim/simd/lanes.h: a whole number
// in [0, 2^52) as a word, through 2^52) and life::times (sim/life/random.h: a word
// times a constant modulo 2^64, built from 32-bit products on AVX2, which has
// no 64-bit multiply). Each lane must equal the scalar C++ operation, at the
// edges and on random words. Also the two operations xsimd 8.1 gets wrong
// with AVX-512 (sim/simd/lanes.h): fma, which must fuse as std::fma does, and a
// mask's exclusive or, written a != b. And mask_not, the inline ! the
// photon life uses (built from the mask register's bits with AVX-512).
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "sim/life/random.h"

namespace fiberlab::sim::life {
namespace {

constexpr int W = kBatchWidth;

// Runs `check` on the values a vector at a time, lanes compared one by one.
template <class In, class Check>
void for_vectors(const std::vector<In>& values, Check&& check) {
  for (std::size_t i = 0; i + W <= values.size(); i += W) check(values.data() + i);
}

std::vector<double> whole_numbers() {
  const double two_51 = 0x1.0p51, two_52 = 0x1.0p52;
  std::vector<double> v = {0.0, 1.0, 2.0, 3.0, two_51 - 1.0, two_51, two_51 + 1.0, two_52 - 3.0,
                           two_52 - 2.0, two_52 - 1.0, 4095.0, 4096.0, 1e15, 1e15 + 1.0};
  std::mt19937_64 gen(20261203);
  for (int k = 0; k < 4000; ++k) v.push_back(static_cast<double>(gen() >> 12));  // [0, 2^52)
  for (int k = 0; k < 4000; ++k) v.push_back(static_cast<double>(gen() >> (12 + k % 40)));
  while (v.size() % W != 0) v.push_back(7.0);
  return v;
}

TEST(LaneWords, ToBitsIsTheWholeNumber) {
  for_vectors(whole_numbers(), [](const double* x) {
    alignas(64) std::uint64_t out[W];
    to_bits(Batch::load_unaligned(x)).store_aligned(out);
    for (int k = 0; k < W; ++k)
      ASSERT_EQ(out[k], static_cast<std::uint64_t>(x[k])) << "x = " << x[k];
  });
}

TEST(LaneWords, ToDoubleUndoesToBits) {
  for_vectors(whole_numbers(), [](const double* x) {
    alignas(64) double out[W];
    to_double(to_bits(Batch::load_unaligned(x))).store_aligned(out);
    for (int k = 0; k < W; ++k) ASSERT_EQ(out[k], x[k]);
  });
}

TEST(LaneWords, TimesIsTheProductModulo2To64) {
  std::vector<std::uint64_t> words = {0, 1, 2, 0xFFFFFFFFULL, 0x100000000ULL, 0x100000001ULL,
                                      ~0ULL, ~0ULL - 1, 0x8000000000000000ULL, 0x7FFFFFFFFFFFFFFFULL};
  std::mt19937_64 gen(7);
  for (int k = 0; k < 4000; ++k) words.push_back(gen());
  while (words.size() % W != 0) words.push_back(gen());
  // SplitMix64's two constants, and constants with one half zero or all ones.
  for (std::uint64_t c : {0xbf58476d1ce4e5b9ULL, 0x94d049bb133111ebULL, 0xFFFFFFFFULL,
                          0xFFFFFFFF00000000ULL, ~0ULL, 3ULL}) {
    for_vectors(words, [c](const std::uint64_t* z) {
      alignas(64) std::uint64_t out[W];
      times(BitsOf<Batch>::load_unaligned(z), c).store_aligned(out);
      for (int k = 0; k < W; ++k) ASSERT_EQ(out[k], z[k] * c) << z[k] << " * " << c;
    });
  }
}

// Triples whose product needs more than 53 bits, so that rounding it before
// the add changes the result (an unfused x * y + z fails most of them).
// xsimd 8.1's own AVX-512 fma may pass here, where GCC contracts its inlined
// x * y + z; in the photon life it did not, and LifeLog.VectorLanesGiveTheScalarBits
// catches that mutation.
TEST(LaneWords, FmaRoundsOnceAsStdFma) {
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<double> xs, ys, zs;
  for (int k = 0; k < 4000 * W; ++k) {
    const double x = u(gen), y = u(gen);
    xs.push_back(x), ys.push_back(y), zs.push_back(-x * y + u(gen) * 0x1.0p-40);
  }
  int unfused_differs = 0;
  for (std::size_t i = 0; i < xs.size(); i += W) {
    alignas(64) double out[W];
    store_unaligned(fma(Batch::load_unaligned(&xs[i]), Batch::load_unaligned(&ys[i]),
                        Batch::load_unaligned(&zs[i])),
                    out);
    for (int k = 0; k < W; ++k) {
      const std::size_t j = i + k;
      ASSERT_EQ(out[k], std::fma(xs[j], ys[j], zs[j])) << xs[j] << " " << ys[j] << " " << zs[j];
      volatile double product = xs[j] * ys[j];  // rounded: GCC would contract x * y + z
      unfused_differs += out[k] != product + zs[j];
    }
  }
  EXPECT_GT(unfused_differs, 1000);  // the inputs do tell fused from unfused
}

TEST(LaneWords, MasksDifferIsExclusiveOr) {
  alignas(64) double a[W], b[W];
  for (int pattern = 0; pattern < (1 << W) && pattern < 256; ++pattern) {
    for (int k = 0; k < W; ++k) a[k] = (pattern >> k) & 1, b[k] = (pattern >> (k / 2 + 1)) & 1;
    const MaskOf<Batch> x = Batch::load_aligned(a) > Batch(0.5), y = Batch::load_aligned(b) > Batch(0.5);
    const MaskOf<Batch> differ = x != y;
    for (int k = 0; k < W; ++k)
      ASSERT_EQ(differ.get(k), (a[k] > 0.5) != (b[k] > 0.5)) << "pattern " << pattern << " lane " << k;
  }
}

TEST(LaneWords, MaskNotFlipsEveryLane) {
  alignas(64) double a[W];
  for (int pattern = 0; pattern < (1 << W) && pattern < 256; ++pattern) {
    for (int k = 0; k < W; ++k) a[k] = (pattern >> k) & 1;
    const MaskOf<Batch> m = Batch::load_aligned(a) > Batch(0.5);
    const MaskOf<Batch> flipped = mask_not(m);
    for (int k = 0; k < W; ++k) ASSERT_EQ(flipped.get(k), !(a[k] > 0.5)) << "pattern " << pattern << " lane " << k;
    EXPECT_EQ(xsimd::any(flipped), pattern != (1 << W) - 1) << "pattern " << pattern;
  }
}

}  // namespace
}  // namespace fiberlab::sim::life
