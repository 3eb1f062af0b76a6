#pragma once
// Sine and cosine for the angles a photon's life draws (sim/lanes.h number
// types), cheaper than a general sincos because the arguments are known:
//
// - sincos_turn(u) = (sin 2 pi u, cos 2 pi u) for u in [0, 1): a uniform
//   direction in a plane. The quadrant comes from u itself (u - q/4 is exact
//   for the generator's multiples of 2^-53), so no range reduction of an
//   angle is needed.
// - sincos_small(x) for any x: the kernel below where every lane has
//   |x| <= pi/4 (the gaussian sampler's offsets for betas up to about 10
//   degrees), the library's sincos otherwise.
//
// The kernel is the Taylor series of sin (to x^17) and cos (to x^18) in
// Horner form with explicit fused multiply-adds. For |x| <= pi/4 the first
// omitted terms are x^19/19! < 8e-20 and x^20/20! < 3e-21, far below the
// rounding of the sum (about 1e-16), so the result is as accurate as the
// library's, not an approximation of it; the scalar and vector forms perform
// the same operations and give the same bits (photon-by-photon equivalence,
// tests/sim/test_batch_tracer.cpp). tests/sim/test_life_trig.cpp compares
// both with std::sin / std::cos.
#include <utility>

#include "sim/lanes.h"

namespace fiberlab::sim::life {

namespace trig_detail {

inline double fma(double a, double b, double c) { return std::fma(a, b, c); }
inline Batch fma(const Batch& a, const Batch& b, const Batch& c) { return xsimd::fma(a, b, c); }
inline double round_half_up(double x) { return std::floor(x + 0.5); }
inline Batch round_half_up(const Batch& x) { return xsimd::floor(x + Batch(0.5)); }

// sin x and cos x for |x| <= pi/4 (Taylor, see above).
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> kernel(const T& x) {
  const T z = x * x;
  // sin x = x (1 - z/3! + z^2/5! - ... + z^8/17!)
  T s(1.0 / 355687428096000.0);  // 1/17!
  s = fma(s, z, T(-1.0 / 1307674368000.0));
  s = fma(s, z, T(1.0 / 6227020800.0));
  s = fma(s, z, T(-1.0 / 39916800.0));
  s = fma(s, z, T(1.0 / 362880.0));
  s = fma(s, z, T(-1.0 / 5040.0));
  s = fma(s, z, T(1.0 / 120.0));
  s = fma(s, z, T(-1.0 / 6.0));
  s = fma(s * z, x, x);
  // cos x = 1 - z/2! + z^2/4! - ... + z^9/18!
  T c(1.0 / 6402373705728000.0);  // 1/18!
  c = fma(c, z, T(-1.0 / 20922789888000.0));
  c = fma(c, z, T(1.0 / 87178291200.0));
  c = fma(c, z, T(-1.0 / 479001600.0));
  c = fma(c, z, T(1.0 / 3628800.0));
  c = fma(c, z, T(-1.0 / 40320.0));
  c = fma(c, z, T(1.0 / 720.0));
  c = fma(c, z, T(-1.0 / 24.0));
  c = fma(c, z, T(0.5));
  c = fma(-c, z, T(1.0));
  return {s, c};
}

}  // namespace trig_detail

// (sin 2 pi u, cos 2 pi u) for u in [0, 1].
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> sincos_turn(const T& u) {
  const T q = trig_detail::round_half_up(T(4.0) * u);  // nearest quarter turn, 0..4
  const T x = (u - T(0.25) * q) * T(6.283185307179586);  // in [-pi/4, pi/4]
  const auto [s, c] = trig_detail::kernel(x);
  // Rotate by q quarter turns: q = 1: (c, -s); 2: (-s, -c); 3: (-c, s); 0, 4: (s, c).
  const T q4 = select(q == T(4.0), T(0.0), q);  // u near 1 is a whole turn
  const MaskOf<T> odd = (q4 == T(1.0)) | (q4 == T(3.0));
  const T sin_abs = select(odd, c, s), cos_abs = select(odd, s, c);
  const MaskOf<T> sin_neg = q4 >= T(2.0), cos_neg = (q4 == T(1.0)) | (q4 == T(2.0));
  return {select(sin_neg, -sin_abs, sin_abs), select(cos_neg, -cos_abs, cos_abs)};
}

// (sin x, cos x) for any x; fast when every lane has |x| <= pi/4.
template <class T>
[[gnu::always_inline]] inline std::pair<T, T> sincos_small(const T& x) {
  if (!all(abs(x) <= T(0.7853981633974483))) return sincos(x);
  return trig_detail::kernel(x);
}

}  // namespace fiberlab::sim::life
