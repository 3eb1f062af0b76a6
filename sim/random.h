#pragma once
// Random numbers for one photon. Each photon's stream is derived only from
// (seed, the incident direction's value (theta_i, phi_i), photon index), so a
// photon's path depends neither on which thread traces it, in which order,
// nor on where its direction sits in a sweep: a sweep split into jobs and
// merged equals one run (OpenMC's scheme; SPEC section 6, reproducibility).
// Generator: xoshiro256** (Blackman & Vigna 2018) seeded through SplitMix64.
#include <bit>
#include <cmath>
#include <cstdint>

namespace fiberlab::sim {

// The whole state of a photon's stream, so that a batched tracer can keep it
// in structure-of-arrays form and hand it back.
struct RandomState {
  std::uint64_t s[4];
  double spare;
  bool has_spare;
};

class PhotonRandom {
 public:
  explicit PhotonRandom(const RandomState& st) : spare_(st.spare), has_spare_(st.has_spare) {
    for (int i = 0; i < 4; ++i) s_[i] = st.s[i];
  }
  RandomState state() const { return {{s_[0], s_[1], s_[2], s_[3]}, spare_, has_spare_}; }

  // The stream of photon `photon` of the incident direction (theta_i,
  // phi_i) (radians as configured; phi_i NaN for a randomly rotated fiber).
  PhotonRandom(std::uint64_t seed, double theta_i, double phi_i, std::uint64_t photon)
      : PhotonRandom(stream_key(seed, theta_i, phi_i), photon) {}
  // The same from a precomputed stream_key.
  PhotonRandom(std::uint64_t key, std::uint64_t photon) {
    std::uint64_t x = splitmix(key ^ photon);
    for (auto& s : s_) s = x = splitmix(x);
  }

  // What the streams of one incident direction share: SplitMix64 over the
  // seed and the bit patterns of theta_i and phi_i (-0 counted as +0, every
  // NaN as one value). A photon's state is SplitMix64 applied to
  // (key ^ photon), then four more times.
  static std::uint64_t stream_key(std::uint64_t seed, double theta_i, double phi_i) {
    const std::uint64_t k = splitmix(splitmix(seed ^ 0x6a09e667f3bcc909ULL) ^ angle_bits(theta_i));
    return splitmix(k ^ angle_bits(phi_i));
  }
  static std::uint64_t angle_bits(double a) {
    if (std::isnan(a)) return 0x7ff8000000000000ULL;
    return std::bit_cast<std::uint64_t>(a + 0.0);  // -0 + 0 = +0
  }
  static std::uint64_t splitmix(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Uniform in (0, 1]: safe under log().
  double uniform_open0() { return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53; }

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
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace fiberlab::sim
