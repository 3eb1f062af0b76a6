#pragma once
// Natural log for the gaussian sampler's exponential variates (E = -log u,
// sim/roughness_gaussian.h), for the number types of sim/lanes.h, cheaper
// than the library's vector log because it needs no division.
//
// Domain: positive normal doubles (the sampler's u and u1 u2, with u in
// (0, 1] on a 2^-53 grid, are >= 2^-106). Zero, negatives, subnormals,
// infinities and NaN are not handled.
//
// Method (table-driven reduction, as in many libm's): x = 2^k m with m in
// [0.75, 1.5); the 7 bits of x's representation below that split pick one of
// 128 subintervals of m, whose centre c has a stored reciprocal inv_c and
// log_c = -log(inv_c) (the log of the reciprocal actually used, so the
// identity below is exact, not off by inv_c's rounding):
//   log x = k log 2 + log_c + log1p(r),   r = m inv_c - 1 (one fma),
// |r| <= 2^-8 + rounding. The two subintervals either side of m = 1 use
// inv_c = 1 exactly, so near x = 1 the result is log1p(x - 1) with x - 1
// exact and the relative accuracy holds there too; they are wider, |r| <
// 2^-7. log1p(r) is its Taylor series to r^8 (omitted terms below 2^-63 / 9
// absolute and 2^-56 / 9 relative to log1p r), far below the rounding of
// the sum. k log 2 is added in two parts (log 2 split so that k times its
// high part is exact). Measured against std::log on 800,000 arguments
// (tests/sim/test_life_log.cpp): at most 1 ulp; the bound the test holds it
// to is 2 (the table's log_c, rounded to 0.5 ulp, can be up to twice the
// result where they partly cancel). The scalar and
// vector forms perform the same operations and give the same bits (the
// photon-by-photon equivalence of the two tracers rests on it).
#include <array>
#include <cmath>
#include <cstdint>

#include "sim/lanes.h"

namespace fiberlab::sim::life {

namespace log_detail {

inline constexpr int kTableBits = 7;
inline constexpr int kTableSize = 1 << kTableBits;
// Bits of 0.75: subtracting them puts m's split at [0.75, 1.5).
inline constexpr std::uint64_t kSplit = 0x3FE8000000000000ULL;
inline constexpr std::uint64_t kMantissaMask = (std::uint64_t{1} << 52) - 1;
// log 2 = kLn2Hi + kLn2Lo, kLn2Hi with 37 significant bits so that k kLn2Hi
// is exact for every binade |k| <= 1075.
inline constexpr double kLn2Hi = 0x1.62e42fefap-1;
inline constexpr double kLn2Lo = 0x1.cf79abc9e3b3ap-40;

struct Table {
  std::array<double, kTableSize> inv_c, log_c;
};
// Entry j covers the representations [kSplit + j 2^45, kSplit + (j+1) 2^45)
// after the shift to exponent 0 or -1: m in [0.75, 1) for j < 64 (width
// 2^-8), m in [1, 1.5) for j >= 64 (width 2^-7).
inline const Table& table() {
  static const Table t = [] {
    Table out{};
    for (int j = 0; j < kTableSize; ++j) {
      const double lo = j < 64 ? 0.75 + j * 0x1.0p-8 : 1.0 + (j - 64) * 0x1.0p-7;
      const double width = j < 64 ? 0x1.0p-8 : 0x1.0p-7;
      const bool next_to_one = j == 63 || j == 64;
      out.inv_c[j] = next_to_one ? 1.0 : 1.0 / (lo + 0.5 * width);
      out.log_c[j] = next_to_one ? 0.0 : -std::log(out.inv_c[j]);
    }
    return out;
  }();
  return t;
}

// log1p(r) for |r| < 2^-7: r + r^2 q(r), q = -1/2 + r/3 - r^2/4 + ... - r^6/8.
template <class T>
[[gnu::always_inline]] inline T log1p_small(const T& r) {
  T q(-1.0 / 8.0);
  q = fma(q, r, T(1.0 / 7.0));
  q = fma(q, r, T(-1.0 / 6.0));
  q = fma(q, r, T(1.0 / 5.0));
  q = fma(q, r, T(-1.0 / 4.0));
  q = fma(q, r, T(1.0 / 3.0));
  q = fma(q, r, T(-0.5));
  return fma(q * r, r, r);
}

// The reduction x = 2^k m of the comment above, on the bits: with the
// exponent field biased by 1024 so that a logical shift gives k + 1024 >= 0
// for every positive normal x.
inline constexpr std::uint64_t kBiasedSplit = kSplit - (std::uint64_t{1024} << 52);
// 2^52 + n as a double has n in its low mantissa bits: the exact conversion
// of a small non-negative integer without an int64 -> double instruction.
inline constexpr std::uint64_t kTwo52Bits = 0x4330000000000000ULL;
inline constexpr double kTwo52PlusBias = 0x1.0p52 + 1024.0;

}  // namespace log_detail

// Natural log of a positive normal double (see above).
template <class T>
T log_positive(const T& x) {
  using namespace log_detail;
  using U = BitsOf<T>;
  const U bits = to_bits(x);
  const U shifted = bits - U(kBiasedSplit);
  const U k_biased = shifted >> 52;  // k + 1024
  const U j = (shifted >> (52 - kTableBits)) & U(kTableSize - 1);
  const T m = from_bits<T>(bits - (k_biased << 52) + U(std::uint64_t{1024} << 52));
  const T k = from_bits<T>(k_biased | U(kTwo52Bits)) - T(kTwo52PlusBias);
  const Table& t = table();
  const T r = fma(m, gather<T>(t.inv_c.data(), j), T(-1.0));
  // k log 2 + log_c in two parts: the large one with one rounding (k kLn2Hi
  // is exact), the small one carrying log 2's remainder.
  const T large = fma(k, T(kLn2Hi), gather<T>(t.log_c.data(), j));
  return large + fma(k, T(kLn2Lo), log1p_small(r));
}

}  // namespace fiberlab::sim::life
