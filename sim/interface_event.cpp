#include "sim/interface_event.h"

#include <algorithm>
#include <cmath>

#include "common/fresnel.h"

namespace fiberlab::sim {

EventResult ScalarLight::interact(const Vec3& d, const Vec3& m, double eta_rel,
                                  PhotonRandom& rng) {
  // F uses the true 3D angle between d and m (SPEC section 3).
  const double cos_i = std::clamp(-d.dot(m), 0.0, 1.0);
  const double eta_ratio = 1.0 / eta_rel;
  const double sin2_t = eta_ratio * eta_ratio * (1.0 - cos_i * cos_i);
  if (sin2_t >= 1.0) return {reflect(d, m, cos_i), false};  // total internal reflection
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double F = fresnel_dielectric(cos_i, eta_rel);
  if (rng.uniform() < F) return {reflect(d, m, cos_i), false};
  return {refract(d, m, cos_i, eta_ratio, cos_t), true};
}

}  // namespace fiberlab::sim
