#pragma once
// Moving numbers between the lanes of a vector without a trip through
// memory: a vector assembled in memory a lane at a time and then loaded
// whole stalls the load (store forwarding), which exit splitting's queue
// (sim/life/exit_splitting.h) would pay on every vector it draws.
//
// permute_lanes(x, index): lane j of the result is lane index[j] of x (one
// AVX-512 permutation; a Pair's 16 lanes from both halves at once). Other
// instruction sets go through memory.
// mask_of_bits<T>(bits): the mask whose lane k is bit k of bits (the inverse
// of lane_bits, sim/simd/lane_packing.h).
#include <bit>
#include <cstdint>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim::life {

inline double permute_lanes(double x, std::uint64_t /*index*/) { return x; }
inline std::uint64_t permute_lanes(std::uint64_t x, std::uint64_t /*index*/) { return x; }

inline Batch permute_lanes(const Batch& x, const BitsOf<Batch>& index) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) return _mm512_permutex2var_pd(x, index, x);  // (GCC 12 warns on permutexvar)
#endif
  alignas(64) double v[kBatchWidth], out[kBatchWidth];
  alignas(64) std::uint64_t k[kBatchWidth];
  x.store_aligned(v);
  index.store_aligned(k);
  for (int j = 0; j < kBatchWidth; ++j) out[j] = v[k[j]];
  return Batch::load_aligned(out);
}
inline BitsOf<Batch> permute_lanes(const BitsOf<Batch>& x, const BitsOf<Batch>& index) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) return _mm512_permutex2var_epi64(x, index, x);
#endif
  alignas(64) std::uint64_t v[kBatchWidth], out[kBatchWidth], k[kBatchWidth];
  x.store_aligned(v);
  index.store_aligned(k);
  for (int j = 0; j < kBatchWidth; ++j) out[j] = v[k[j]];
  return BitsOf<Batch>::load_aligned(out);
}

// A Pair: indices 0 .. 2W - 1 over both halves.
template <class V, class I>
Pair<V> permute_lanes(const Pair<V>& x, const Pair<I>& index) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) {
    if constexpr (std::is_same_v<V, Batch>)
      return {V(_mm512_permutex2var_pd(x.a, index.a, x.b)), V(_mm512_permutex2var_pd(x.a, index.b, x.b))};
    else
      return {V(_mm512_permutex2var_epi64(x.a, index.a, x.b)), V(_mm512_permutex2var_epi64(x.a, index.b, x.b))};
  }
#endif
  constexpr int kHalf = static_cast<int>(Pair<V>::size / 2);
  using S = std::conditional_t<std::is_same_v<V, Batch>, double, std::uint64_t>;
  alignas(64) S v[2 * kHalf], out[2 * kHalf];
  alignas(64) std::uint64_t k[2 * kHalf];
  x.store_aligned(v);
  index.store_aligned(k);
  for (int j = 0; j < 2 * kHalf; ++j) out[j] = v[k[j]];
  return Pair<V>::load_aligned(out);
}

template <class T>
MaskOf<T> mask_of_bits(std::uint64_t bits) {
  if constexpr (std::is_same_v<T, double>) {
    return (bits & 1) != 0;
  } else if constexpr (std::is_same_v<T, Batch>) {
#if defined(__AVX512F__)
    if constexpr (kBatchWidth == 8) return MaskOf<Batch>(static_cast<__mmask8>(bits));
#endif
    alignas(64) double v[kBatchWidth];
    for (int j = 0; j < kBatchWidth; ++j) v[j] = (bits >> j) & 1 ? 1.0 : 0.0;
    return Batch::load_aligned(v) != Batch(0.0);
  } else {
    constexpr int kHalf = static_cast<int>(T::size / 2);
    using V = decltype(T::a);
    return {mask_of_bits<V>(bits & ((std::uint64_t{1} << kHalf) - 1)), mask_of_bits<V>(bits >> kHalf)};
  }
}

}  // namespace fiberlab::sim::life
