#pragma once
// The natural logarithm of the uniforms a photon's life draws (sim/simd/lanes.h
// number types), cheaper than a general log because its argument is known
// to be a positive normal double (the gaussian sampler's u1 or u1 u2, each
// uniform at least 2^-53): no zeros, infinities, NaNs or subnormals to test
// for, the exponent read off the bits without an integer-to-double
// conversion (which AVX2 lacks for 64-bit words), and one operation sequence
// for one photon and for a vector of them, so the two tracers draw the same
// bits (the library's log and xsimd's could differ in the last one).
//
// The method is the classic reduction x = 2^k m with m in [sqrt(2)/2,
// sqrt(2)), f = m - 1, s = f / (2 + f), z = s^2 and
//   log(m) = f - f^2/2 + s (f^2/2 + z P(z)),
// exact for P(z) = sum_k 2 z^(k-1) / (2k + 1) (log(m) = log((1+s)/(1-s)) =
// 2s + s z P(z) and 2s = f - s f). P here is a degree-6 polynomial
// interpolating that series at Chebyshev nodes, computed in 60-digit
// decimals by scripts/life_kernel_coefficients.py: s z P(z) is within 0.04
// units of 2^-53 of its target relative to log(m), below the rounding of the
// evaluation. k ln 2 is added in two parts (ln 2's first 32 bits, exact
// when multiplied by any k here, and the rest). tests/sim/test_life_log.cpp
// compares with std::log.
#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim::life {

namespace log_detail {

// ln 2 = kLn2Hi + kLn2Lo: kLn2Hi has 32 significant bits.
inline constexpr double kLn2Hi = 0x1.62e42fee00000p-1;
inline constexpr double kLn2Lo = 0x1.a39ef35793c76p-33;

}  // namespace log_detail

// log x for a positive normal double x (every lane).
template <class T>
[[gnu::always_inline]] inline T log_normal(const T& x) {
  using Bits = BitsOf<T>;
  using namespace log_detail;
  // Adding sqrt(2)'s mantissa complement to the bits carries into the
  // exponent exactly when x's mantissa is at least sqrt(2): then k is one
  // more than x's exponent and m half its mantissa.
  const Bits b = double_as_bits(x) + Bits(0x00095f6200000000ULL);  // 0x3ff00000 - 0x3fe6a09e, high word
  const T m = bits_as_double((b & Bits(0x000fffffffffffffULL)) + Bits(0x3fe6a09e00000000ULL));
  // k + 1023 as the low bits of 2^52's mantissa, then 2^52 + 1023 off: k exactly.
  const T k = bits_as_double((b >> 52) | Bits(0x4330000000000000ULL)) - T(0x1.0p52 + 1023.0);
  const T f = m - T(1.0);
  const T s = f / (T(2.0) + f);
  const T z = s * s;
  T p(0x1.2b584aae78a57p-3);  // written out, as in sim/simd/life_trig.h's kernel
  p = fma(p, z, T(0x1.39fe606542ddep-3));
  p = fma(p, z, T(0x1.7462b4ab2ef6bp-3));
  p = fma(p, z, T(0x1.c71c62e5800a1p-3));
  p = fma(p, z, T(0x1.2492492df148dp-2));
  p = fma(p, z, T(0x1.99999999952e2p-2));
  p = fma(p, z, T(0x1.5555555555558p-1));
  const T hfsq = fma(T(0.5) * f, f, T(0.0));  // f^2/2, never contracted into a sum below
  const T tail = fma(s, fma(z, p, hfsq), k * T(kLn2Lo));
  return fma(k, T(kLn2Hi), (tail - hfsq) + f);
}

}  // namespace fiberlab::sim::life
