#pragma once
// The idealised `exit_blur` roughness (SPEC section 3): interfaces are smooth
// and the exit direction is blurred once, as the photon leaves. The new
// direction has the inclination of a von Mises-Fisher sample (kappa = 1/v)
// centred on the exit direction, and the exit azimuth plus a Normal(0, beta^2)
// offset (wrapped by the caller's relative-azimuth arithmetic).
#include <cmath>

#include <vector>

#include "common/fiber_frame.h"
#include "sim/life/random.h"
#include "sim/roughness/roughness_smooth.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

// Cosine of the angle to the mean of a vMF sample on the sphere (Wood 1994,
// the 3D closed form w = 1 + log(xi + (1 - xi) exp(-2 kappa)) / kappa).
inline double sample_vmf_cosine(double kappa, PhotonRandom& rng) {
  const double xi = rng.uniform_open0();
  if (kappa < 1e-8) return 2.0 * xi - 1.0;  // uniform on the sphere
  return 1.0 + std::log(xi + (1.0 - xi) * std::exp(-2.0 * kappa)) / kappa;
}

inline Vec3 blur_exit_direction(const Vec3& d, double v, double beta_azim, PhotonRandom& rng) {
  double theta = inclination(d);
  if (v > 0.0) {
    const double w = std::min(1.0, sample_vmf_cosine(1.0 / v, rng));
    const double s = std::sqrt(std::max(0.0, 1.0 - w * w));
    const double psi = 6.283185307179586 * rng.uniform();
    // Orthonormal basis around d.
    const Vec3 helper = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 t1 = d.cross(helper).normalized();
    const Vec3 t2 = d.cross(t1);
    const Vec3 sample = w * d + s * (std::cos(psi) * t1 + std::sin(psi) * t2);
    theta = inclination(sample);
  }
  const double phi = azimuth(d) + (beta_azim > 0.0 ? beta_azim * rng.normal() : 0.0);
  return direction_from_angles(theta, phi);
}

// The exit blur of a configuration: v_p = beta_long_p^2 and beta_azim_p,
// indexed by the lobe p (the last entry for every larger p).
class ExitBlur {
 public:
  explicit ExitBlur(const roughness::ExitBlur& r) : beta_azim_(r.beta_azim) {
    for (double b : r.beta_long) v_.push_back(b * b);
  }
  Vec3 apply(const Vec3& d, int p, PhotonRandom& rng) const {
    return blur_exit_direction(d, roughness::ExitBlur::for_lobe(v_, p),
                               roughness::ExitBlur::for_lobe(beta_azim_, p), rng);
  }

 private:
  std::vector<double> v_, beta_azim_;
};

// Roughness model `exit_blur` (sim/roughness/roughness_model.h): smooth interfaces, the
// exit direction blurred once.
struct ExitBlurRoughness : life::SmoothRoughness {
  explicit ExitBlurRoughness(const roughness::ExitBlur& r) : blur(r) {}
  Vec3 exit_direction(const Vec3& d, int segments, PhotonRandom& rng) const {
    return blur.apply(d, segments, rng);
  }
  ExitBlur blur;
};

}  // namespace fiberlab::sim
