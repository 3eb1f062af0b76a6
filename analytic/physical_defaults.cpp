#include "analytic/physical_defaults.h"

#include <algorithm>
#include <cmath>

namespace fiberlab::analytic {

std::vector<double> tilt_shifts(double a) { return {-2.0 * a, a, 4.0 * a, 0.0}; }

double first_order_spread(double eta, int p) {
  if (p == 0) return 2.0;
  return std::sqrt(2.0 * (eta - 1.0) * (eta - 1.0) + 4.0 * eta * eta * (p - 1));
}

namespace {

// theta_r spread of lobe p (standard deviation of the lobe's theta-marginal,
// radians) per radian of gaussian beta_long, measured by
// scripts/calibrate_widths.py. Index p = 0 (R), 1 (TT), 2 (TRT); p >= 3 uses
// the first-order rule.
double measured_spread_per_beta(double eta, int p) { return first_order_spread(eta, p); }

}  // namespace

LobeWidths gaussian_lobe_widths(double beta_long, double beta_azim, double eta, int lobes,
                                WidthVariable variable) {
  LobeWidths w;
  const int n = std::max(1, lobes);
  for (int p = 0; p < n; ++p) {
    double spread = measured_spread_per_beta(eta, p) * beta_long;
    if (variable == WidthVariable::ThetaH) spread *= 0.5;
    w.beta_long.push_back(spread);
    w.beta_azim.push_back(first_order_spread(eta, p) * beta_azim);
  }
  return w;
}

}  // namespace fiberlab::analytic

namespace fiberlab::analytic {

void apply_fiber_basics(const PhysicalFiber& f, ModelParams& p) {
  p.eta = f.eta;
  p.sigma_a = f.sigma_a;
  p.lobes = f.lobes;
  p.alpha = tilt_shifts(f.scale_tilt);
}

void apply_fiber_roughness(const PhysicalFiber& f, ModelParams& p, WidthVariable variable,
                           double min_beta_long) {
  const std::vector<double>& azim = f.beta_azim.empty() ? f.beta_long : f.beta_azim;
  switch (f.roughness) {
    case PhysicalFiber::Roughness::ExitBlur:
      // SPEC s3: the exit blur's vMF is d'Eon's M_p (a theta_r width); a
      // theta_h Gaussian needs half of it.
      p.beta_long = f.beta_long;
      if (variable == WidthVariable::ThetaH)
        for (double& b : p.beta_long) b *= 0.5;
      p.beta_azim = azim;
      break;
    case PhysicalFiber::Roughness::Smooth:
      p.beta_long = {0.0};
      p.beta_azim = {0.0};
      break;
    case PhysicalFiber::Roughness::Gaussian: {
      const double bl = f.beta_long.empty() ? 0.0 : f.beta_long.front();
      const double ba = azim.empty() ? bl : azim.front();
      const LobeWidths w = gaussian_lobe_widths(bl, ba, f.eta, f.lobes, variable);
      p.beta_long = w.beta_long;
      p.beta_azim = w.beta_azim;
      break;
    }
  }
  for (double& b : p.beta_long) b = std::max(b, min_beta_long);
}

}  // namespace fiberlab::analytic
