#include "compare/model_defaults.h"

#include <algorithm>
#include <cmath>

namespace fiberlab::compare {

double gaussian_lobe_beta(double beta, double eta, int p) {
  if (p == 0) return 2.0 * beta;
  const double var = 2.0 * (eta - 1.0) * (eta - 1.0) + 4.0 * eta * eta * (p - 1);
  return std::sqrt(var) * beta;
}

analytic::ModelParams model_params_from_settings(const sim::Settings& s,
                                                 const std::string& model) {
  analytic::ModelParams m;
  m.eta = s.fiber.eta;
  m.sigma_a = s.fiber.sigma_a;
  m.eccentricity = s.fiber.eccentricity;
  m.lobes = s.tally.lobes;
  const double a = s.fiber.scale_tilt;
  m.alpha = {-2.0 * a, a, 4.0 * a, 0.0};  // SPEC s7, shifts of theta_r
  switch (s.roughness.model) {
    case sim::RoughnessModel::ExitBlur:
      m.beta_long = s.roughness.beta_long;
      m.beta_azim = s.roughness.beta_azim.empty() ? s.roughness.beta_long : s.roughness.beta_azim;
      break;
    case sim::RoughnessModel::Smooth:
      m.beta_long = {0.0};
      m.beta_azim = {0.0};
      break;
    case sim::RoughnessModel::Gaussian: {
      const double bl = sim::RoughnessSettings::for_lobe(s.roughness.beta_long, 0);
      const double ba = s.roughness.beta_azim.empty()
                            ? bl
                            : sim::RoughnessSettings::for_lobe(s.roughness.beta_azim, 0);
      m.beta_long.clear();
      m.beta_azim.clear();
      // One entry per tallied lobe, p up to lobes - 1; the last applies beyond.
      const int n = std::max(1, s.tally.lobes);
      for (int p = 0; p < n; ++p) {
        m.beta_long.push_back(gaussian_lobe_beta(bl, s.fiber.eta, p));
        m.beta_azim.push_back(gaussian_lobe_beta(ba, s.fiber.eta, p));
      }
      break;
    }
  }
  if (model == "marschner2003") {
    for (double& b : m.beta_long) b = std::max(b, kMinMarschnerBeta);
  }
  return m;
}

}  // namespace fiberlab::compare
