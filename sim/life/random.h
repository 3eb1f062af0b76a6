#pragma once
// Random numbers for one photon. Each photon's stream is derived only from
// (seed, the incident direction's value (theta_i, phi_i), photon index), so a
// photon's path depends neither on which thread traces it, in which order,
// nor on where its direction sits in a sweep: a sweep split into jobs and
// merged equals one run (OpenMC's scheme; SPEC section 6, reproducibility).
// Generator: xoshiro256+ (Blackman & Vigna, "Scrambled linear pseudorandom
// number generators", ACM TOMS 2021), seeded through SplitMix64. The authors
// recommend it for floating-point numbers: its output is the sum s0 + s3 of
// two state words, whose lowest bits have low linear complexity, and a
// uniform double keeps only the top 52 bits. It is preferred to
// xoshiro256** (the same state and steps, a scrambler of seven integer
// operations instead of one) for its cheaper draw (docs/PERFORMANCE.md).
//
// LaneRandom<T> is the generator written once for a number type (sim/simd/lanes.h):
// one stream (T = double) or W streams side by side (T = Batch), each
// advancing only where a mask says, so that every photon consumes its own
// stream in the same order whichever way it is traced.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim {

// The whole state of a photon's stream, so that a batched tracer can keep it
// in structure-of-arrays form and hand it back.
struct RandomState {
  std::uint64_t s[4];
  double spare;
  bool has_spare;
};

namespace life {

// z c modulo 2^64 for a word or a vector of words. AVX2 has no 64-bit
// multiply, and xsimd then multiplies lane by lane through memory (splitmix
// below runs for every photon's stream); the 32 x 32 -> 64-bit products
// give the same bits: z c = lo(z) lo(c) + 2^32 (hi(z) lo(c) + lo(z) hi(c))
// mod 2^64.
inline std::uint64_t times(std::uint64_t z, std::uint64_t c) { return z * c; }
inline BitsOf<Batch> times(const BitsOf<Batch>& z, std::uint64_t c) {
#if defined(__AVX2__) && !defined(__AVX512F__)
  const __m256i cv = _mm256_set1_epi64x(static_cast<long long>(c));
  const __m256i low = _mm256_mul_epu32(z, cv);
  const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(z, 32), cv),
                                         _mm256_mul_epu32(z, _mm256_srli_epi64(cv, 32)));
  return _mm256_add_epi64(low, _mm256_slli_epi64(cross, 32));
#else
  return z * BitsOf<Batch>(c);
#endif
}
template <class V>
Pair<V> times(const Pair<V>& z, std::uint64_t c) {
  return {times(z.a, c), times(z.b, c)};
}

// SplitMix64 (Steele, Lea & Flood 2014) on one word or a vector of words.
template <class Bits>
Bits splitmix(Bits z) {
  z = z + Bits(0x9e3779b97f4a7c15ULL);
  z = times(z ^ (z >> 30), 0xbf58476d1ce4e5b9ULL);
  z = times(z ^ (z >> 27), 0x94d049bb133111ebULL);
  return z ^ (z >> 31);
}

template <class T>
class LaneRandom {
 public:
  using Bits = BitsOf<T>;
  LaneRandom() = default;
  LaneRandom(Bits s0, Bits s1, Bits s2, Bits s3) : s_{s0, s1, s2, s3} {}
  // The stream of photon `photon` (one per lane) of the direction whose
  // streams share `key` (PhotonRandom::stream_key): SplitMix64 applied to
  // (key ^ photon), then four more times, one state word each.
  static LaneRandom seeded(std::uint64_t key, const Bits& photon) {
    Bits x = splitmix(Bits(key) ^ photon);
    Bits s[4];
    for (auto& w : s) w = x = splitmix(x);
    return {s[0], s[1], s[2], s[3]};
  }
  const Bits& word(int k) const { return s_[k]; }

  // Uniform in [0, 1) where m (other lanes: any value, stream untouched).
  T uniform(const MaskOf<T>& m) { return to_unit(next(m)); }
  // Uniform in (0, 1): safe under log().
  T uniform_open0(const MaskOf<T>& m) { return open0(uniform(m)); }
  // N uniforms in [0, 1) where m: the same numbers as N calls of uniform(m),
  // the stream's state masked once instead of N times.
  template <int N>
  std::array<T, N> uniforms(const MaskOf<T>& m) {
    Bits s[4] = {s_[0], s_[1], s_[2], s_[3]};
    std::array<T, N> u;
    for (int k = 0; k < N; ++k) u[k] = to_unit(step(s));
    commit(m, s);
    return u;
  }
  // A uniform in [0, 1) moved to (0, 1): k 2^-52 becomes (k + 1/2) 2^-52,
  // exact (2k + 1 < 2^53).
  static T open0(const T& u) { return u + T(0x1.0p-53); }

 private:
  static Bits rotl(const Bits& x, int k) { return (x << k) | (x >> (64 - k)); }
  // The top 52 bits of x as k 2^-52 in [0, 1), exactly: they become the
  // mantissa of a double in [1, 2), and 1 is subtracted (no integer to
  // floating-point conversion, which AVX2 lacks for 64-bit words).
  static T to_unit(const Bits& x) {
    return bits_as_double((x >> 12) | Bits(0x3FF0000000000000ULL)) - T(1.0);
  }
  Bits next(const MaskOf<T>& m) {
    Bits s[4] = {s_[0], s_[1], s_[2], s_[3]};
    const Bits result = step(s);
    commit(m, s);
    return result;
  }
  // xoshiro256+: result = s0 + s3, and the state s steps.
  static Bits step(Bits (&s)[4]) {
    const Bits result = s[0] + s[3];
    const Bits t = s[1] << 17;
    s[2] = s[2] ^ s[0];
    s[3] = s[3] ^ s[1];
    s[1] = s[1] ^ s[2];
    s[0] = s[0] ^ s[3];
    s[2] = s[2] ^ t;
    s[3] = rotl(s[3], 45);
    return result;
  }
  // The stepped state s becomes the stream's where m.
  void commit(const MaskOf<T>& m, const Bits (&s)[4]) {
    const auto um = bits_mask(m);
    for (int k = 0; k < 4; ++k) s_[k] = select(um, s[k], s_[k]);
  }

  Bits s_[4];
};

}  // namespace life

// One photon's stream, with the normal deviates the exit blur draws.
class PhotonRandom {
 public:
  explicit PhotonRandom(const RandomState& st)
      : core_(st.s[0], st.s[1], st.s[2], st.s[3]), spare_(st.spare), has_spare_(st.has_spare) {}
  explicit PhotonRandom(const life::LaneRandom<double>& core) : core_(core) {}
  RandomState state() const {
    return {{core_.word(0), core_.word(1), core_.word(2), core_.word(3)}, spare_, has_spare_};
  }
  const life::LaneRandom<double>& core() const { return core_; }
  life::LaneRandom<double>& core() { return core_; }

  // The stream of photon `photon` of the incident direction (theta_i,
  // phi_i) (radians as configured; phi_i NaN for a randomly rotated fiber).
  PhotonRandom(std::uint64_t seed, double theta_i, double phi_i, std::uint64_t photon)
      : PhotonRandom(stream_key(seed, theta_i, phi_i), photon) {}
  // The same from a precomputed stream_key: the state is SplitMix64 applied
  // to (key ^ photon), then four more times.
  PhotonRandom(std::uint64_t key, std::uint64_t photon)
      : core_(life::LaneRandom<double>::seeded(key, photon)) {}

  // What the streams of one incident direction share: SplitMix64 over the
  // seed and the bit patterns of theta_i and phi_i (-0 counted as +0, every
  // NaN as one value).
  static std::uint64_t stream_key(std::uint64_t seed, double theta_i, double phi_i) {
    const std::uint64_t k = splitmix(splitmix(seed ^ 0x6a09e667f3bcc909ULL) ^ angle_bits(theta_i));
    return splitmix(k ^ angle_bits(phi_i));
  }
  static std::uint64_t angle_bits(double a) {
    if (std::isnan(a)) return 0x7ff8000000000000ULL;
    return std::bit_cast<std::uint64_t>(a + 0.0);  // -0 + 0 = +0
  }
  static std::uint64_t splitmix(std::uint64_t z) { return life::splitmix(z); }

  // Uniform in [0, 1).
  double uniform() { return core_.uniform(true); }
  // Uniform in (0, 1): safe under log().
  double uniform_open0() { return core_.uniform_open0(true); }

  // Standard normal deviate (Box-Muller, both values used).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform_open0()));
    const double a = 6.283185307179586 * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  life::LaneRandom<double> core_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace fiberlab::sim
