// The vector forms of 64-bit word operations: life::to_bits (sim/lanes.h: a
// whole number in [0, 2^53) as a word) and life::times (sim/random.h: a word
// times a constant modulo 2^64, built from 32-bit products on AVX2, which has
// no 64-bit multiply). Each lane must equal the scalar C++ operation, at the
// edges and on random words.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "sim/random.h"

namespace fiberlab::sim::life {
namespace {

constexpr int W = kBatchWidth;

// Runs `check` on the values a vector at a time, lanes compared one by one.
template <class In, class Check>
void for_vectors(const std::vector<In>& values, Check&& check) {
  for (std::size_t i = 0; i + W <= values.size(); i += W) check(values.data() + i);
}

std::vector<double> whole_numbers() {
  const double two_52 = 0x1.0p52, two_53 = 0x1.0p53;
  std::vector<double> v = {0.0, 1.0, 2.0, 3.0, two_52 - 2.0, two_52 - 1.0, two_52, two_52 + 1.0,
                           two_52 + 2.0, two_52 + 3.0, two_53 - 3.0, two_53 - 2.0, two_53 - 1.0,
                           4095.0, 4096.0, 1e15, 1e15 + 1.0};
  std::mt19937_64 gen(20261203);
  for (int k = 0; k < 4000; ++k) v.push_back(static_cast<double>(gen() >> 11));  // [0, 2^53)
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

}  // namespace
}  // namespace fiberlab::sim::life
