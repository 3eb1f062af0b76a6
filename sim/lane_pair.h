#pragma once
// Two SIMD vectors as one number type of the photon life (sim/lanes.h):
// Pair<Batch> holds 2 W photons (16 with AVX-512) and applies every
// operation to both halves. The batched tracer steps a Pair at a time so that
// each step has two independent chains of dependent operations (the
// sampler's log, square roots and polynomials, Fresnel's, the segment's
// division): the core runs one while the other waits, where a single vector
// leaves its units idle. The halves are computed exactly as a Batch each, so
// a photon's numbers do not depend on the type (tests/sim/test_batch_tracer.cpp).
#include <bit>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "sim/lanes.h"

namespace fiberlab::sim::life {

template <class V>
struct Pair {
  V a, b;
  Pair() = default;
  Pair(const V& a_, const V& b_) : a(a_), b(b_) {}
  // The same value in every lane.
  template <class S>
    requires std::is_arithmetic_v<S> || std::is_enum_v<S>
  Pair(S s) : a(s), b(s) {}

  static constexpr std::size_t size = 2 * V::size;
  template <class P>
  static Pair load_aligned(const P* p) {
    return {V::load_aligned(p), V::load_aligned(p + V::size)};
  }
  template <class P>
  void store_aligned(P* p) const {
    a.store_aligned(p);
    b.store_aligned(p + V::size);
  }
  template <class P>
  void store_unaligned(P* p) const {
    a.store_unaligned(p);
    b.store_unaligned(p + V::size);
  }
};

using Batch2 = Pair<Batch>;

template <class V>
Pair<V> pair_of(const V& a, const V& b) {
  return {a, b};
}

#define FIBERLAB_PAIR_BINARY(op)                                      \
  template <class V>                                                  \
  auto operator op(const Pair<V>& x, const Pair<V>& y) {              \
    return pair_of(x.a op y.a, x.b op y.b);                           \
  }
FIBERLAB_PAIR_BINARY(+)
FIBERLAB_PAIR_BINARY(-)
FIBERLAB_PAIR_BINARY(*)
FIBERLAB_PAIR_BINARY(/)
FIBERLAB_PAIR_BINARY(&)
FIBERLAB_PAIR_BINARY(|)
FIBERLAB_PAIR_BINARY(^)
FIBERLAB_PAIR_BINARY(<)
FIBERLAB_PAIR_BINARY(<=)
FIBERLAB_PAIR_BINARY(>)
FIBERLAB_PAIR_BINARY(>=)
FIBERLAB_PAIR_BINARY(==)
FIBERLAB_PAIR_BINARY(!=)
#undef FIBERLAB_PAIR_BINARY

template <class V>
Pair<V> operator-(const Pair<V>& x) {
  return {-x.a, -x.b};
}
template <class V>
Pair<V> operator!(const Pair<V>& x) {
  return {!x.a, !x.b};
}
template <class V>
Pair<V> operator<<(const Pair<V>& x, int k) {
  return {x.a << k, x.b << k};
}
template <class V>
Pair<V> operator>>(const Pair<V>& x, int k) {
  return {x.a >> k, x.b >> k};
}

template <>
struct NumberTraits<Batch2> {
  using Mask = Pair<Batch::batch_bool_type>;
  using Bits = Pair<NumberTraits<Batch>::Bits>;
  static constexpr int kWidth = 2 * kBatchWidth;
};

template <class M, class V>
Pair<V> select(const Pair<M>& m, const Pair<V>& x, const Pair<V>& y) {
  return {select(m.a, x.a, y.a), select(m.b, x.b, y.b)};
}
template <class M>
bool any(const Pair<M>& m) {
  return xsimd::any(m.a) || xsimd::any(m.b);
}
template <class M>
bool all(const Pair<M>& m) {
  return xsimd::all(m.a) && xsimd::all(m.b);
}
inline Batch2 sqrt(const Batch2& x) { return {xsimd::sqrt(x.a), xsimd::sqrt(x.b)}; }
inline Batch2 log(const Batch2& x) { return {xsimd::log(x.a), xsimd::log(x.b)}; }
inline Batch2 abs(const Batch2& x) { return {xsimd::abs(x.a), xsimd::abs(x.b)}; }
inline Batch2 asin(const Batch2& x) { return {xsimd::asin(x.a), xsimd::asin(x.b)}; }
inline Batch2 floor(const Batch2& x) { return {xsimd::floor(x.a), xsimd::floor(x.b)}; }
inline Batch2 min(const Batch2& x, const Batch2& y) { return {xsimd::min(x.a, y.a), xsimd::min(x.b, y.b)}; }
inline Batch2 max(const Batch2& x, const Batch2& y) { return {xsimd::max(x.a, y.a), xsimd::max(x.b, y.b)}; }
inline Batch2 fma(const Batch2& x, const Batch2& y, const Batch2& z) {
  return {xsimd::fma(x.a, y.a, z.a), xsimd::fma(x.b, y.b, z.b)};
}
inline std::pair<Batch2, Batch2> sincos(const Batch2& x) {
  const auto [sa, ca] = xsimd::sincos(x.a);
  const auto [sb, cb] = xsimd::sincos(x.b);
  return {Batch2(sa, sb), Batch2(ca, cb)};
}

inline auto bits_mask(const NumberTraits<Batch2>::Mask& m) { return pair_of(bits_mask(m.a), bits_mask(m.b)); }
inline NumberTraits<Batch2>::Bits to_bits(const Batch2& x) { return {to_bits(x.a), to_bits(x.b)}; }
inline Batch2 to_double(const NumberTraits<Batch2>::Bits& x) { return {to_double(x.a), to_double(x.b)}; }

inline void store(const Batch2& x, double* p) { x.store_aligned(p); }
inline void store_bits(const NumberTraits<Batch2>::Bits& x, std::uint64_t* p) { x.store_aligned(p); }
inline void store_unaligned(const Batch2& x, double* p) { x.store_unaligned(p); }
inline void store_unaligned(const NumberTraits<Batch2>::Bits& x, std::uint64_t* p) { x.store_unaligned(p); }

// The sum of the lanes (work counters).
inline double lane_sum(double x) { return x; }
inline double lane_sum(const Batch& x) { return xsimd::hadd(x); }
inline double lane_sum(const Batch2& x) { return xsimd::hadd(x.a) + xsimd::hadd(x.b); }

}  // namespace fiberlab::sim::life
