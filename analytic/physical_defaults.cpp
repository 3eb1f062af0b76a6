#include "analytic/physical_defaults.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "common/units.h"

namespace fiberlab::analytic {

std::string PhysicalFiber::roughness_text() const {
  switch (roughness) {
    case Roughness::Smooth: return "smooth";
    case Roughness::Gaussian: {
      const double bl = beta_long.empty() ? 0.0 : beta_long.front();
      return fmt::format("gaussian beta = [{:g}, {:g}] deg", rad_to_deg(bl),
                         rad_to_deg(beta_azim.empty() ? bl : beta_azim.front()));
    }
    case Roughness::ExitBlur: return "exit_blur";
    case Roughness::Beckmann: return fmt::format("beckmann alpha = [{:g}, {:g}]", alpha_long, alpha_azim);
    case Roughness::GGX: return fmt::format("ggx alpha = [{:g}, {:g}]", alpha_long, alpha_azim);
  }
  return "";
}

bool FiberMapping::user_sets(const std::string& key) const {
  return std::find(user_keys.begin(), user_keys.end(), key) != user_keys.end();
}

double microfacet_as_gaussian(double alpha) { return std::atan(alpha / std::sqrt(2.0)); }

std::vector<double> tilt_shifts(double a) { return {-2.0 * a, a, 4.0 * a, 0.0}; }

double first_order_spread(double eta, int p) {
  if (p == 0) return 2.0;
  return std::sqrt(2.0 * (eta - 1.0) * (eta - 1.0) + 4.0 * eta * eta * (p - 1));
}

namespace {
#include "analytic/calibrated_widths.inc"
}  // namespace

WidthCalibration deon2011_width_calibration() {
  return {{kDeonWidthRatio[0], kDeonWidthRatio[1], kDeonWidthRatio[2]}, WidthVariable::ThetaR};
}

WidthCalibration marschner2003_width_calibration(bool two_theta_h) {
  const double f = two_theta_h ? 2.0 : 1.0;
  return {{f * kMarschnerWidthRatio[0], f * kMarschnerWidthRatio[1], f * kMarschnerWidthRatio[2]},
          two_theta_h ? WidthVariable::ThetaR : WidthVariable::ThetaH};
}

LobeWidths gaussian_lobe_widths(double beta_long, double beta_azim, double eta, int lobes,
                                const WidthCalibration& cal) {
  LobeWidths w;
  const int n = std::max(1, lobes);
  for (int p = 0; p < n; ++p) {
    const double ratio =
        p <= 2 ? cal.ratio[p] : cal.ratio[2] * first_order_spread(eta, p) / first_order_spread(eta, 2);
    w.beta_long.push_back(ratio * beta_long);
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

void apply_fiber_roughness(const PhysicalFiber& fiber, ModelParams& p, const WidthCalibration& cal,
                           FiberMapping& mapping, double min_beta_long) {
  PhysicalFiber f = fiber;
  if (f.microfacet()) {
    f.roughness = PhysicalFiber::Roughness::Gaussian;
    f.beta_long = {microfacet_as_gaussian(f.alpha_long)};
    f.beta_azim = {microfacet_as_gaussian(f.alpha_azim)};
    mapping.notes.push_back(fmt::format(
        "roughness: the {} fiber read as the gaussian fiber of the same RMS facet slope per axis, beta = "
        "atan(alpha / sqrt 2) = [{:g}, {:g}] deg, then the calibrated rule (nominal: fit or --set the widths)",
        fiber.roughness_text(), rad_to_deg(f.beta_long.front()), rad_to_deg(f.beta_azim.front())));
  }
  const std::vector<double>& azim = f.beta_azim.empty() ? f.beta_long : f.beta_azim;
  switch (f.roughness) {
    case PhysicalFiber::Roughness::ExitBlur:
      // SPEC s3: the exit blur's vMF is d'Eon's M_p (a theta_r width); a
      // theta_h Gaussian needs half of it.
      p.beta_long = f.beta_long;
      if (cal.variable == WidthVariable::ThetaH)
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
      const LobeWidths w = gaussian_lobe_widths(bl, ba, f.eta, f.lobes, cal);
      p.beta_long = w.beta_long;
      p.beta_azim = w.beta_azim;
      break;
    }
    case PhysicalFiber::Roughness::Beckmann:
    case PhysicalFiber::Roughness::GGX: break;  // mapped to Gaussian above
  }
  for (double& b : p.beta_long) b = std::max(b, min_beta_long);
}

}  // namespace fiberlab::analytic
