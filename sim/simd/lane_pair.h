#pragma once
// Two SIMD vectors as one number type of the photon life (sim/simd/lanes.h):
// Pair<Batch> holds 2 W photons (16 with AVX-512) and applies every
// operation to both halves. The batched tracer steps a Pair at a time so that
// each step has two independent chains of dependent operations (the
// sampler's log, square roots and polynomials, Fresnel's, the segment's
// division): the core runs one while the other waits, where a single vector
// leaves its units idle. The halves are computed exactly as a Batch each, so
// a photon's numbers do not depend on the type (tests/sim/test_batch_tracer.cpp).
// (A Pair of Pairs, 4 chains, compiles too, but its values do not fit in 32
// registers and are spilled.)
#include <bit>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "sim/simd/lanes.h"

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
FIBERLAB_PAIR_BINARY(<)
FIBERLAB_PAIR_BINARY(<=)
FIBERLAB_PAIR_BINARY(>)
FIBERLAB_PAIR_BINARY(>=)
FIBERLAB_PAIR_BINARY(==)
FIBERLAB_PAIR_BINARY(!=)
#undef FIBERLAB_PAIR_BINARY
// Exclusive or of the random streams' words only: xsimd 8.1's ^ of two
// AVX-512 masks is their or (sim/simd/lanes.h), so the photon life writes a != b
// for masks, and a mask ^ here does not compile.
template <class V>
  requires(!xsimd::is_batch_bool<V>::value)
auto operator^(const Pair<V>& x, const Pair<V>& y) {
  return pair_of(x.a ^ y.a, x.b ^ y.b);
}

template <class V>
Pair<V> operator-(const Pair<V>& x) {
  return {-x.a, -x.b};
}
template <class V>
[[gnu::always_inline]] inline Pair<V> operator!(const Pair<V>& x) {
  return {mask_not(x.a), mask_not(x.b)};  // (sim/simd/lanes.h: why not !)
}
template <class V>
Pair<V> operator<<(const Pair<V>& x, int k) {
  return {x.a << k, x.b << k};
}
template <class V>
Pair<V> operator>>(const Pair<V>& x, int k) {
  return {x.a >> k, x.b >> k};
}

template <class V>
struct NumberTraits<Pair<V>> {
  using Mask = Pair<MaskOf<V>>;
  using Bits = Pair<BitsOf<V>>;
  static constexpr int kWidth = 2 * NumberTraits<V>::kWidth;
};

// The functions of sim/simd/lanes.h, half by half (xsimd's for a Batch half, by
// argument-dependent lookup; these again for a Pair half).
template <class M, class V>
Pair<V> select(const Pair<M>& m, const Pair<V>& x, const Pair<V>& y) {
  return {select(m.a, x.a, y.a), select(m.b, x.b, y.b)};
}
template <class M>
bool any(const Pair<M>& m) {
  return any(m.a) || any(m.b);
}
template <class M>
bool all(const Pair<M>& m) {
  return all(m.a) && all(m.b);
}
#define FIBERLAB_PAIR_FUNCTION(f)           \
  template <class V>                        \
  Pair<V> f(const Pair<V>& x) {             \
    return {f(x.a), f(x.b)};                \
  }
FIBERLAB_PAIR_FUNCTION(sqrt)
FIBERLAB_PAIR_FUNCTION(log)
FIBERLAB_PAIR_FUNCTION(abs)
FIBERLAB_PAIR_FUNCTION(asin)
FIBERLAB_PAIR_FUNCTION(floor)
#undef FIBERLAB_PAIR_FUNCTION
template <class V>
Pair<V> min(const Pair<V>& x, const Pair<V>& y) {
  return {min(x.a, y.a), min(x.b, y.b)};
}
template <class V>
Pair<V> max(const Pair<V>& x, const Pair<V>& y) {
  return {max(x.a, y.a), max(x.b, y.b)};
}
template <class V>
Pair<V> fma(const Pair<V>& x, const Pair<V>& y, const Pair<V>& z) {
  return {fma(x.a, y.a, z.a), fma(x.b, y.b, z.b)};
}
template <class V>
std::pair<Pair<V>, Pair<V>> sincos(const Pair<V>& x) {
  const auto [sa, ca] = sincos(x.a);
  const auto [sb, cb] = sincos(x.b);
  return {Pair<V>(sa, sb), Pair<V>(ca, cb)};
}
template <class M>
auto bits_mask(const Pair<M>& m) {
  return pair_of(bits_mask(m.a), bits_mask(m.b));
}
template <class V>
BitsOf<Pair<V>> to_bits(const Pair<V>& x) {
  return {to_bits(x.a), to_bits(x.b)};
}
template <class U>
auto bits_as_double(const Pair<U>& x) {
  return pair_of(bits_as_double(x.a), bits_as_double(x.b));
}
template <class V>
BitsOf<Pair<V>> double_as_bits(const Pair<V>& x) {
  return {double_as_bits(x.a), double_as_bits(x.b)};
}
template <class U>
auto to_double(const Pair<U>& x) {
  return pair_of(to_double(x.a), to_double(x.b));
}
template <class V, class P>
void store(const Pair<V>& x, P* p) {
  x.store_aligned(p);
}
template <class V, class P>
void store_bits(const Pair<V>& x, P* p) {
  x.store_aligned(p);
}
template <class V, class P>
void store_unaligned(const Pair<V>& x, P* p) {
  x.store_unaligned(p);
}

// The sum of the lanes (work counters).
inline double lane_sum(double x) { return x; }
inline double lane_sum(const Batch& x) { return xsimd::hadd(x); }
template <class V>
double lane_sum(const Pair<V>& x) {
  return lane_sum(x.a) + lane_sum(x.b);
}

}  // namespace fiberlab::sim::life
