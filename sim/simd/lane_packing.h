#pragma once
// Packing the lanes of a SIMD vector that a mask selects (sim/simd/lanes.h):
// what the batched tracer (sim/life/batch_tracer.cpp) uses to keep its photons in
// flight at the front of its pool and to hand the finished ones over, a
// vector at a time instead of a lane at a time.
//
// pack_store(x, lanes, p) writes the selected lanes of x, lowest first, to
// p[0], p[1], ... . With AVX-512 it packs in a register (one compress
// instruction; AVX2: one permutation from a table of the 16 masks of 4
// lanes) and writes a whole vector from p, so p must have room for W values
// and the values past the selected ones are scratch. (A compress straight
// to memory is avoided: it is microcoded and slow on AMD Zen 4.) Other
// instruction sets write the selected lanes one at a time.
#include <bit>
#include <cstdint>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim::life {

// Bit k set where lane k of m is (one lane: the reference tracer's).
inline std::uint64_t lane_bits(bool m) { return m ? 1 : 0; }
inline std::uint64_t lane_bits(const MaskOf<Batch>& m) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) return static_cast<std::uint64_t>(static_cast<__mmask8>(m.data));
#elif defined(__AVX2__)
  if constexpr (kBatchWidth == 4) return static_cast<std::uint64_t>(_mm256_movemask_pd(m.data));
#endif
  alignas(64) bool b[kBatchWidth];
  m.store_aligned(b);
  std::uint64_t bits = 0;
  for (int k = 0; k < kBatchWidth; ++k) bits |= static_cast<std::uint64_t>(b[k]) << k;
  return bits;
}

// The bits of `bits` at the lanes `lanes` selects, lowest first: what
// pack_store does to a vector, done to a mask's lane bits (so that a
// finished lane's flags need no trip through memory). BMI2's pext where
// there is one.
inline std::uint64_t pack_bits(std::uint64_t bits, std::uint64_t lanes) {
#if defined(__BMI2__)
  return _pext_u64(bits, lanes);
#else
  std::uint64_t out = 0;
  for (int j = 0; lanes != 0; lanes &= lanes - 1, ++j)
    out |= ((bits >> std::countr_zero(lanes)) & 1) << j;
  return out;
#endif
}

#if !defined(__AVX512F__) && defined(__AVX2__)
namespace packing_detail {
// For each mask of 4 lanes, the permutation of 32-bit elements that moves
// its lanes (two elements each) to the front, lowest first.
struct PackTable {
  alignas(32) std::int32_t index[16][8];
  constexpr PackTable() : index{} {
    for (int m = 0; m < 16; ++m) {
      int j = 0;
      for (int k = 0; k < 4; ++k)
        if ((m >> k) & 1) {
          index[m][2 * j] = 2 * k;
          index[m][2 * j + 1] = 2 * k + 1;
          ++j;
        }
    }
  }
};
inline constexpr PackTable kPackTable{};
inline __m256i pack_index(std::uint64_t lanes) {
  return _mm256_load_si256(reinterpret_cast<const __m256i*>(kPackTable.index[lanes & 15]));
}
}  // namespace packing_detail
#endif

inline void pack_store(const Batch& x, std::uint64_t lanes, double* p) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) {
    _mm512_storeu_pd(p, _mm512_maskz_compress_pd(static_cast<__mmask8>(lanes), x));
    return;
  }
#elif defined(__AVX2__)
  if constexpr (kBatchWidth == 4) {
    const __m256 v = _mm256_permutevar8x32_ps(_mm256_castpd_ps(x), packing_detail::pack_index(lanes));
    _mm256_storeu_pd(p, _mm256_castps_pd(v));
    return;
  }
#endif
  alignas(64) double v[kBatchWidth];
  x.store_aligned(v);
  for (; lanes != 0; lanes &= lanes - 1) *p++ = v[std::countr_zero(lanes)];
}

inline void pack_store(const BitsOf<Batch>& x, std::uint64_t lanes, std::uint64_t* p) {
#if defined(__AVX512F__)
  if constexpr (kBatchWidth == 8) {
    _mm512_storeu_si512(p, _mm512_maskz_compress_epi64(static_cast<__mmask8>(lanes), x));
    return;
  }
#elif defined(__AVX2__)
  if constexpr (kBatchWidth == 4) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(p),
                        _mm256_permutevar8x32_epi32(x, packing_detail::pack_index(lanes)));
    return;
  }
#endif
  alignas(64) std::uint64_t v[kBatchWidth];
  x.store_aligned(v);
  for (; lanes != 0; lanes &= lanes - 1) *p++ = v[std::countr_zero(lanes)];
}

// The same for a Pair of vectors (sim/simd/lane_pair.h): lanes [0, W) are the
// first vector's, [W, 2 W) the second's.
template <class M>
std::uint64_t lane_bits(const Pair<M>& m) {
  return lane_bits(m.a) | (lane_bits(m.b) << (Pair<M>::size / 2));
}
template <class V, class P>
void pack_store(const Pair<V>& x, std::uint64_t lanes, P* p) {
  constexpr int kHalf = Pair<V>::size / 2;
  const std::uint64_t low = lanes & ((std::uint64_t{1} << kHalf) - 1);
  pack_store(x.a, low, p);
  pack_store(x.b, lanes >> kHalf, p + std::popcount(low));
}

}  // namespace fiberlab::sim::life
