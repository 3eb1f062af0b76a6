#pragma once
// The source (SPEC section 5): a collimated beam along -wi. Each photon gets
// its own random stream, its incident azimuth (drawn when the fiber is
// randomly rotated) and its impact parameter h uniform in [-1, 1).
//
// Stratified h (`source.h_sampling: stratified`, opt-in; SPEC section 5
// allows it: it changes the variance, never the expectation; measured, it
// removed no measurable variance: README "Stratified impact parameters"). Photons are taken in blocks of kStrata
// consecutive indices from photon 0; in a block that lies wholly within the
// run's photons, photon i draws its h in the i mod kStrata-th of kStrata
// equal strata of [-1, 1). Every h is still uniform in [-1, 1) in law, each
// full block samples h once per stratum, and the photons of a last partial
// block (photons not a multiple of kStrata) draw h independently, as without
// stratification. The stratum depends only on the photon index, so threads,
// ranks, chunks and checkpoints change nothing.
//
// Standard errors stay honest: the tally's estimator sqrt((S2/N - P^2)/(N-1))
// assumes independent photons. With one photon per stratum its expectation
// is (sigma^2 - V)/(N - 1) where sigma^2 is a photon's variance without
// strata and V the stratified estimator's variance; since V <= sigma^2/N
// (proportional allocation removes the between-strata part), the reported
// error is at least the true one: conservative, never optimistic.
#include <cstdint>

#include "common/fiber_frame.h"
#include "common/units.h"
#include "sim/life/random.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

struct LaunchedPhoton {
  PhotonRandom rng;
  double phi_i;  // this photon's incident azimuth
  Vec3 wi;       // towards the light
  double h;      // impact parameter across the projected width
};

// The photons of one incident configuration. The incident direction is
// computed once unless the fiber is randomly rotated (phi_i uniform), when
// each photon draws its own azimuth first.
class Source {
 public:
  static constexpr std::uint64_t kStrata = 4096;  // 2^12

  // phi_i is ignored (and may be NaN) when phi_i_uniform. `photons`: the
  // run's photons of this direction, for stratified h (0: h independent).
  Source(std::uint64_t seed, double theta_i, double phi_i, bool phi_i_uniform,
         std::uint64_t stratified_photons = 0)
      : key_(PhotonRandom::stream_key(seed, theta_i, phi_i_uniform ? NAN : phi_i)),
        theta_i_(theta_i), phi_i_(phi_i_uniform ? 0.0 : phi_i), uniform_(phi_i_uniform),
        wi_(direction_from_angles(theta_i_, phi_i_)),
        stratified_end_(stratified_photons / kStrata * kStrata) {}
  // The run's source for one incident direction, as its settings say.
  Source(const Settings& s, double theta_i, double phi_i)
      : Source(s.seed, theta_i, phi_i, s.source.phi_i_uniform,
               s.source.h_stratified ? s.photons : 0) {}

  bool fixed_direction() const { return !uniform_; }
  std::uint64_t stream_key() const { return key_; }

  LaunchedPhoton launch(std::uint64_t photon) const {
    PhotonRandom rng(key_, photon);
    double phi_i = phi_i_;
    Vec3 wi = wi_;
    if (uniform_) {
      phi_i = kTwoPi * rng.uniform() - kPi;
      wi = direction_from_angles(theta_i_, phi_i);
    }
    const double h = impact_parameter(photon, rng.uniform());
    return {rng, phi_i, wi, h};
  }

  // h of `photon` from its uniform draw u (a multiple of 2^-52 in [0, 1), as
  // PhotonRandom::uniform gives): 2u - 1 exactly when independent; when
  // stratified, the stratum's 12 bits followed by u's first 41 bits, so h is
  // exact, uniform in its stratum and never 1.
  double impact_parameter(std::uint64_t photon, double u) const {
    return impact_parameter_of<double>(photon, u);
  }

  // The streams and impact parameters of photons `photon` (one per lane: T a
  // vector) when the direction is fixed: launch(), W photons at a time.
  template <class T>
  struct Lanes {
    life::LaneRandom<T> rng;
    T h;
  };
  template <class T>
  Lanes<T> launch_lanes(const life::BitsOf<T>& photon) const {
    auto rng = life::LaneRandom<T>::seeded(key_, photon);
    const T u = rng.uniform(life::MaskOf<T>(true));
    return {rng, impact_parameter_of<T>(photon, u)};
  }

 private:
  template <class T>
  T impact_parameter_of(const life::BitsOf<T>& photon, const T& u) const {
    using Bits = life::BitsOf<T>;
    using life::select;  // and xsimd's, by argument-dependent lookup
    static_assert(kStrata == 1 << 12, "a stratum is 12 bits");
    const Bits x = life::to_bits(u * T(0x1.0p52)) << 1;  // u's 52 random bits, then a 0
    const Bits strata = ((photon & Bits(kStrata - 1)) << 41) | (x >> 12);
    return life::to_double(select(photon < Bits(stratified_end_), strata, x)) * T(0x1.0p-52) - T(1.0);
  }

  std::uint64_t key_;
  double theta_i_, phi_i_;
  bool uniform_;
  Vec3 wi_;
  std::uint64_t stratified_end_;  // photons [0, stratified_end_) are in full blocks
};

inline LaunchedPhoton launch_photon(std::uint64_t seed, std::uint64_t photon, double theta_i,
                                    double phi_i, bool phi_i_uniform) {
  return Source(seed, theta_i, phi_i, phi_i_uniform).launch(photon);
}

}  // namespace fiberlab::sim
