#include "analytic/physical_defaults.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include "common/units.h"

namespace fiberlab::analytic {

const roughness::MicrofacetAlpha* microfacet_alpha(const Roughness& g) {
  if (const auto* b = std::get_if<roughness::Beckmann>(&g)) return b;
  if (const auto* x = std::get_if<roughness::Ggx>(&g)) return x;
  return nullptr;
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

void apply_fiber_roughness(const PhysicalFiber& fiber, LobeWidths& p, const WidthCalibration& cal,
                           FiberMapping& mapping, double min_beta_long) {
  PhysicalFiber f = fiber;
  if (const auto* m = microfacet_alpha(f.roughness)) {
    const roughness::Gaussian g{microfacet_as_gaussian(m->alpha_long), microfacet_as_gaussian(m->alpha_azim)};
    f.roughness = g;
    mapping.notes.push_back(fmt::format(
        "roughness: the {} fiber read as the gaussian fiber of the same RMS facet slope per axis, beta = "
        "atan(alpha / sqrt 2) = [{:g}, {:g}] deg, then the calibrated rule (nominal: fit or --set the widths)",
        fiber.roughness_text(), rad_to_deg(g.beta_long), rad_to_deg(g.beta_azim)));
  }
  // Every roughness type has its rule here: a type without one does not compile.
  std::visit(
      [&](const auto& g) {
        using G = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<G, roughness::ExitBlur>) {
          // SPEC s3: the exit blur's vMF is d'Eon's M_p (a theta_r width); a
          // theta_h Gaussian needs half of it.
          p.beta_long = g.beta_long;
          if (cal.variable == WidthVariable::ThetaH)
            for (double& b : p.beta_long) b *= 0.5;
          p.beta_azim = g.beta_azim;
        } else if constexpr (std::is_same_v<G, roughness::Smooth>) {
          p.beta_long = {0.0};
          p.beta_azim = {0.0};
        } else if constexpr (std::is_same_v<G, roughness::Gaussian>) {
          const LobeWidths w = gaussian_lobe_widths(g.beta_long, g.beta_azim, f.eta, f.lobes, cal);
          p.beta_long = w.beta_long;
          p.beta_azim = w.beta_azim;
        } else {
          static_assert(std::is_base_of_v<roughness::MicrofacetAlpha, G>, "a roughness type without a rule");
        }  // microfacet: read as gaussian above
      },
      f.roughness);
  for (double& b : p.beta_long) b = std::max(b, min_beta_long);
}

}  // namespace fiberlab::analytic
