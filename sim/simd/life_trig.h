#pragma once
// Sine and cosine for the angles a photon's life draws (sim/simd/lanes.h number
// types), cheaper than a general sincos because the arguments are known:
//
// - sincos_turn(u) = (sin 2 pi u, cos 2 pi u) for u in [0, 1): a uniform
//   direction in a plane. The quadrant comes from u itself (u - q/4 is exact
//   for the generator's multiples of 2^-52), so no range reduction of an
//   angle is needed.
// - sincos_small(x) for any x: the kernel below where every lane has
//   |x| <= pi/4 (the gaussian sampler's offsets for betas up to about 10
//   degrees), a reduction by multiples of pi/2 then the kernel where every
//   lane has |x| <= 2^20, the library's sincos beyond.
//
// The kernel: polynomials in z = x^2 of degree 6 (sin x = x + x z S(z)) and
// 5 (cos x = 1 - z (1/2 - z C(z))) in Horner form with explicit fused
// multiply-adds. S and C interpolate at Chebyshev nodes (near-minimax), in
// 60-digit decimals, by scripts/life_kernel_coefficients.py: with the
// coefficients rounded to double, the polynomials differ from sin and cos by
// at most 0.06 and 0.012 units of 2^-53 (relative) on |x| <= pi/4, far below
// the rounding of the evaluation (about 2^-53), so the result is as accurate
// as the library's, not an approximation of it (with five operations per
// pair fewer than the Taylor series to x^17 and x^18). The scalar and
// vector forms perform the same operations and give the same bits
// (photon-by-photon equivalence, tests/sim/test_batch_tracer.cpp).
// tests/sim/test_life_trig.cpp compares both with std::sin / std::cos.
#include <utility>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim::life {

namespace trig_detail {

inline double round_half_up(double x) { return std::floor(x + 0.5); }
inline Batch round_half_up(const Batch& x) { return xsimd::floor(x + Batch(0.5)); }
inline double floor_of(double x) { return std::floor(x); }
inline Batch floor_of(const Batch& x) { return xsimd::floor(x); }
template <class V>
Pair<V> round_half_up(const Pair<V>& x) {
  return floor(x + Pair<V>(0.5));
}
template <class V>
Pair<V> floor_of(const Pair<V>& x) {
  return floor(x);
}

// sin x and cos x for |x| <= pi/4 (near-minimax polynomials, see above).
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> kernel(const T& x) {
  const T z = x * x;
  // The Horner chains are written out: a generic helper over a coefficient
  // array gives the same bits, but GCC then spills more of the sampler's
  // registers in the batched tracer.
  // sin x = x + x z S(z)
  T s(-0x1.ab17d404de5b3p-41);
  s = fma(s, z, T(0x1.61217f0b800d5p-33));
  s = fma(s, z, T(-0x1.ae645412c560cp-26));
  s = fma(s, z, T(0x1.71de3a546095bp-19));
  s = fma(s, z, T(-0x1.a01a01a019938p-13));
  s = fma(s, z, T(0x1.1111111111110p-7));
  s = fma(s, z, T(-0x1.5555555555555p-3));
  s = fma(s * z, x, x);
  // cos x = 1 - z (1/2 - z C(z))
  T c(-0x1.907da367a37cbp-37);
  c = fma(c, z, T(0x1.1eeb68e93b64cp-29));
  c = fma(c, z, T(-0x1.27e4fa17da09ep-22));
  c = fma(c, z, T(0x1.a01a019f4eb01p-16));
  c = fma(c, z, T(-0x1.6c16c16c16967p-10));
  c = fma(c, z, T(0x1.5555555555555p-5));
  c = fma(-c, z, T(0.5));
  c = fma(-c, z, T(1.0));
  return {s, c};
}

// (sin, cos) of y + q pi/2 from (s, c) = (sin y, cos y), q in {0, 1, 2, 3,
// 4}: q = 1: (c, -s); 2: (-s, -c); 3: (-c, s); 0 and 4: (s, c).
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> quarter_turns(const T& s, const T& c, const T& q) {
  const T q4 = select(q == T(4.0), T(0.0), q);
  const MaskOf<T> odd = (q4 == T(1.0)) | (q4 == T(3.0));
  const T sin_abs = select(odd, c, s), cos_abs = select(odd, s, c);
  const MaskOf<T> sin_neg = q4 >= T(2.0), cos_neg = (q4 == T(1.0)) | (q4 == T(2.0));
  return {select(sin_neg, -sin_abs, sin_abs), select(cos_neg, -cos_abs, cos_abs)};
}

// pi/2 = kHalfPi1 + kHalfPi2 + kHalfPi3 (each the rounding of what remains).
inline constexpr double kHalfPi1 = 0x1.921fb54442d18p0;
inline constexpr double kHalfPi2 = 0x1.1a62633145c07p-54;
inline constexpr double kHalfPi3 = -0x1.f1976b7ed8fbcp-110;
// Where the reduction below is used: q < 2^20, so x - q kHalfPi1 is exact
// (its bits run from 2^0 down to kHalfPi1's last, 2^-52) and the three
// parts leave an error far below an ulp of y.
inline constexpr double kReducedLimit = 0x1.0p20;

// (sin x, cos x) for |x| <= kReducedLimit: x = q pi/2 + y with |y| <= pi/4
// (Cody and Waite's reduction, the products exact in the fused
// multiply-adds), the kernel on y, then q quarter turns.
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> reduced(const T& x) {
  const T q = round_half_up(x * T(0.6366197723675814));  // x / (pi/2), nearest
  T y = fma(-q, T(kHalfPi1), x);
  y = fma(-q, T(kHalfPi2), y);
  y = fma(-q, T(kHalfPi3), y);
  const auto [s, c] = kernel(y);
  return quarter_turns(s, c, q - T(4.0) * floor_of(q * T(0.25)));
}

}  // namespace trig_detail

// (sin 2 pi u, cos 2 pi u) for u in [0, 1].
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> sincos_turn(const T& u) {
  const T q = trig_detail::round_half_up(T(4.0) * u);  // nearest quarter turn, 0..4
  const T x = (u - T(0.25) * q) * T(6.283185307179586);  // in [-pi/4, pi/4]
  const auto [s, c] = trig_detail::kernel(x);
  return trig_detail::quarter_turns(s, c, q);  // q = 4 (u near 1) is a whole turn
}

// (sin x, cos x) for any x: the kernel alone when every lane has |x| <=
// pi/4, the reduction when every lane has |x| <= 2^20 (the sampler's
// offsets, whatever beta), the library beyond (scalar and vector may then
// differ in the last bit).
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> sincos_small(const T& x) {
  const T a = abs(x);
  if (all(a <= T(0.7853981633974483))) return trig_detail::kernel(x);
  if (all(a <= T(trig_detail::kReducedLimit))) return trig_detail::reduced(x);
  return sincos(x);
}

}  // namespace fiberlab::sim::life
