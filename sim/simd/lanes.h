#pragma once
// The number types a photon's life is written for (sim/life/photon_life.h): a
// scalar `double` (one photon, the readable reference) or an
// xsimd::batch<double> (one photon per SIMD lane, 8 with AVX-512). Generic
// code calls the functions below unqualified: the scalar forms are defined
// here, the batch forms are xsimd's, found by argument-dependent lookup.
// A comparison gives a mask (bool, or a batch_bool); select(mask, a, b)
// replaces every branch that depends on a photon.
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

#include "common/fiber_frame.h"

namespace fiberlab::sim {

using Batch = xsimd::batch<double>;
inline constexpr int kBatchWidth = static_cast<int>(Batch::size);

namespace life {

template <class T>
struct NumberTraits;
template <>
struct NumberTraits<double> {
  using Mask = bool;
  using Bits = std::uint64_t;  // a random stream's state word
  static constexpr int kWidth = 1;
};
template <>
struct NumberTraits<Batch> {
  using Mask = Batch::batch_bool_type;
  using Bits = xsimd::batch<std::uint64_t>;
  static constexpr int kWidth = kBatchWidth;
};
template <class T>
using MaskOf = typename NumberTraits<T>::Mask;
template <class T>
using BitsOf = typename NumberTraits<T>::Bits;

// Scalar forms of xsimd's functions.
inline double select(bool m, double a, double b) { return m ? a : b; }
inline std::uint64_t select(bool m, std::uint64_t a, std::uint64_t b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline bool all(bool m) { return m; }
inline double sqrt(double x) { return std::sqrt(x); }
inline double log(double x) { return std::log(x); }
inline double abs(double x) { return std::abs(x); }
inline double min(double a, double b) { return std::min(a, b); }
inline double max(double a, double b) { return std::max(a, b); }
inline double asin(double x) { return std::asin(x); }
inline std::pair<double, double> sincos(double x) { return {std::sin(x), std::cos(x)}; }
inline double fma(double a, double b, double c) { return std::fma(a, b, c); }

// Where xsimd 8.1 (Debian 12's libxsimd-dev) is wrong with AVX-512, and what
// the photon life uses instead (tests/sim/test_lane_words.cpp checks both):
// - its fma there is the generic x * y + z, rounded twice unless the
//   compiler happens to contract it, so a vector lane and std::fma differed
//   in the last bit: this overload (found before xsimd's by overload
//   resolution: not a template) fuses on every instruction set;
// - its ^ of two masks is their or: generic code writes a != b instead
//   (a Pair of masks has no ^, sim/simd/lane_pair.h, so a mask ^ in the photon
//   life fails to compile on every instruction set).
inline Batch fma(const Batch& a, const Batch& b, const Batch& c) {
#if defined(__AVX512F__)
  return _mm512_fmadd_pd(a, b, c);
#else
  return xsimd::fma(a, b, c);
#endif
}

// Not m, always inline. xsimd 8.1's ! of a mask compares it with a false
// mask, which GCC 12 leaves out of line on AVX-512 (28 calls in the photon
// life, each passing the mask through memory; bench/bench_sim.cpp shows the
// cost, docs/PERFORMANCE.md).
[[gnu::always_inline]] inline bool mask_not(bool m) { return !m; }
[[gnu::always_inline]] inline MaskOf<Batch> mask_not(const MaskOf<Batch>& m) {
#if defined(__AVX512F__)
  return MaskOf<Batch>(static_cast<MaskOf<Batch>::register_type>(~m.data));
#else
  return !m;
#endif
}

// A mask over doubles as a mask over the random streams' 64-bit words.
inline bool bits_mask(bool m) { return m; }
inline NumberTraits<Batch>::Bits::batch_bool_type bits_mask(const MaskOf<Batch>& m) {
  using U = NumberTraits<Batch>::Bits;
  return xsimd::bitwise_cast<U>(xsimd::select(m, Batch(1.0), Batch(0.0))) != U(0);
}

template <class T>
T ones(const MaskOf<T>& m) {  // 1 where m, else 0
  return select(m, T(1.0), T(0.0));
}

// Loads and stores of one lane (double) or W lanes (Batch) from aligned arrays.
template <class T>
T load(const double* p) {
  if constexpr (std::is_same_v<T, double>) return *p;
  else return T::load_aligned(p);
}
inline void store(double x, double* p) { *p = x; }
inline void store(const Batch& x, double* p) { x.store_aligned(p); }
template <class T>
BitsOf<T> load_bits(const std::uint64_t* p) {
  if constexpr (std::is_same_v<T, double>) return *p;
  else return BitsOf<T>::load_aligned(p);
}
inline void store_bits(std::uint64_t x, std::uint64_t* p) { *p = x; }
inline void store_bits(const BitsOf<Batch>& x, std::uint64_t* p) { x.store_aligned(p); }
// The same at any address (a vector of lanes starting anywhere in a column).
inline void store_unaligned(double x, double* p) { *p = x; }
inline void store_unaligned(const Batch& x, double* p) { x.store_unaligned(p); }
inline void store_unaligned(std::uint64_t x, std::uint64_t* p) { *p = x; }
inline void store_unaligned(const BitsOf<Batch>& x, std::uint64_t* p) { x.store_unaligned(p); }

// A word's 64 bits read as a double's, and back.
inline double bits_as_double(std::uint64_t x) { return std::bit_cast<double>(x); }
inline Batch bits_as_double(const BitsOf<Batch>& x) { return xsimd::bitwise_cast<Batch>(x); }
inline std::uint64_t double_as_bits(double x) { return std::bit_cast<std::uint64_t>(x); }
inline BitsOf<Batch> double_as_bits(const Batch& x) {
  return xsimd::bitwise_cast<BitsOf<Batch>>(x);
}
// A whole number in [0, 2^52) as a stream word, and back (exact both ways).
// Vectors: x + 2^52 is exact and its low bits are x (AVX2 has no double to
// 64-bit integer conversion, and xsimd's to_int converts one lane at a time).
inline std::uint64_t to_bits(double x) { return static_cast<std::uint64_t>(x); }
inline BitsOf<Batch> to_bits(const Batch& x) {
  const Batch two_52(0x1.0p52);
  return double_as_bits(x + two_52) - double_as_bits(two_52);
}
inline double to_double(std::uint64_t x) { return static_cast<double>(x); }
inline Batch to_double(const BitsOf<Batch>& x) {
  return xsimd::to_float(xsimd::bitwise_cast<xsimd::batch<std::int64_t>>(x));
}

// A 3-vector of numbers: one direction, or W directions side by side.
template <class T>
struct Vec3Of {
  T x, y, z;
  Vec3Of() = default;
  Vec3Of(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  explicit Vec3Of(const Vec3& v) : x(v.x()), y(v.y()), z(v.z()) {}
  Vec3 to_vec3() const { return Vec3(x, y, z); }  // T = double only
  T dot(const Vec3Of& o) const { return x * o.x + y * o.y + z * o.z; }
  Vec3Of cross(const Vec3Of& o) const {
    return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x};
  }
  T norm() const { return sqrt(dot(*this)); }
  Vec3Of normalized() const {
    const T inv = T(1.0) / norm();
    return {x * inv, y * inv, z * inv};
  }
  Vec3Of operator-() const { return {-x, -y, -z}; }
};
template <class T>
Vec3Of<T> operator*(const T& s, const Vec3Of<T>& v) {
  return {s * v.x, s * v.y, s * v.z};
}
template <class T>
Vec3Of<T> operator+(const Vec3Of<T>& a, const Vec3Of<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
Vec3Of<T> operator-(const Vec3Of<T>& a, const Vec3Of<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
Vec3Of<T> select(const MaskOf<T>& m, const Vec3Of<T>& a, const Vec3Of<T>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

}  // namespace life
}  // namespace fiberlab::sim
