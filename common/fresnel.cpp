#include "common/fresnel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fiberlab {

FresnelAmplitudes fresnel_amplitudes(double cos_i, double eta_rel) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double sin2_i = std::max(0.0, 1.0 - cos_i * cos_i);
  const double sin2_t = sin2_i / (eta_rel * eta_rel);
  if (sin2_t >= 1.0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, 1.0, 1.0};  // magnitudes under TIR are 1
  }
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double r_s = (cos_i - eta_rel * cos_t) / (cos_i + eta_rel * cos_t);
  const double r_p = (eta_rel * cos_i - cos_t) / (eta_rel * cos_i + cos_t);
  return {cos_t, r_s, r_p};
}

double fresnel_dielectric(double cos_i, double eta_rel) {
  const FresnelAmplitudes a = fresnel_amplitudes(cos_i, eta_rel);
  if (std::isnan(a.cos_t)) return 1.0;
  return 0.5 * (a.r_s * a.r_s + a.r_p * a.r_p);
}

}  // namespace fiberlab
