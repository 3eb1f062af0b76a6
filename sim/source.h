#pragma once
// The source (SPEC section 5): a collimated beam along -wi. Each photon gets
// its own random stream, its incident azimuth (drawn when the fiber is
// randomly rotated) and its impact parameter h uniform in [-1, 1).
#include <cstdint>

#include "common/fiber_frame.h"
#include "common/units.h"
#include "sim/random.h"

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
  // phi_i is ignored (and may be NaN) when phi_i_uniform.
  Source(std::uint64_t seed, double theta_i, double phi_i, bool phi_i_uniform)
      : key_(PhotonRandom::stream_key(seed, theta_i, phi_i_uniform ? NAN : phi_i)),
        theta_i_(theta_i), phi_i_(phi_i_uniform ? 0.0 : phi_i), uniform_(phi_i_uniform),
        wi_(direction_from_angles(theta_i_, phi_i_)) {}

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
    const double h = 2.0 * rng.uniform() - 1.0;
    return {rng, phi_i, wi, h};
  }

 private:
  std::uint64_t key_;
  double theta_i_, phi_i_;
  bool uniform_;
  Vec3 wi_;
};

inline LaunchedPhoton launch_photon(std::uint64_t seed, std::uint64_t photon, double theta_i,
                                    double phi_i, bool phi_i_uniform) {
  return Source(seed, theta_i, phi_i, phi_i_uniform).launch(photon);
}

}  // namespace fiberlab::sim
