#pragma once
// From a physical fiber (what the simulator traces: SPEC sections 2-4) to a
// model's parameters: the rules `predict` and `compare` use unless told
// otherwise with --set.
//
// - eta, sigma_a, lobes (and eccentricity where the model has it) are copied.
// - Tilt: alpha_p, shifts of theta_r, by SPEC s7: R -2a, TT +a, TRT +4a,
//   p >= 3: 0 (rays through the fiber's centre; the comparison measures the
//   real shift).
// - Roughness:
//   * smooth: every beta 0 (d'Eon's exact v -> 0 limits; Marschner's Gaussian
//     M needs beta > 0 and is floored at kMinMarschnerBeta);
//   * exit_blur: beta_long / beta_azim lists used as given (SPEC s3: the exit
//     blur *is* d'Eon's M_p and Gaussian detector);
//   * gaussian (microfacet tilts of standard deviation beta_long, beta_azim at
//     every event): a *calibrated* rule, gaussian_lobe_widths(): the theta_r
//     spread of each lobe measured in simulations over a grid of roughness
//     and theta_i (scripts/calibrate_widths.py regenerates the table below),
//     expressed in each model's width convention;
//   * beckmann / ggx (microfacet alpha per axis): models with their own
//     microfacet roughness (huang2022) take alpha itself; the Gaussian-width
//     models take the gaussian fiber of the same RMS facet slope per axis
//     (microfacet_as_gaussian(), a stated approximation).
// A rule that is an approximation says so in FiberMapping::notes (printed by
// `predict` and `compare`); a fiber a model cannot represent is refused
// (fiberlab::Error naming the field and what the model allows) unless the
// user sets the parameter concerned with --set.
#include <cstdint>
#include <string>
#include <vector>

#include "common/fiber.h"

namespace fiberlab::analytic {

// What a model's rule is given: the simulated fiber (common/fiber.h) and the
// number of lobes its tally separates.
struct PhysicalFiber : Fiber {
  int lobes = 4;
  std::uint64_t photons = 0;  // the simulation's, per incident direction (0: not known)

  // "ggx alpha = [0.3, 0.1]": the roughness as the config gives it, for notes and errors.
  std::string roughness_text() const { return roughness::text(roughness); }
};

// What a model's rule (ModelInfo::from_fiber) knows and says besides the
// parameters: the keys the user sets with --set (a fiber the model cannot
// represent is refused only when the user does not set the key concerned),
// and one line per approximate mapping applied, printed with the model.
struct FiberMapping {
  std::vector<std::string> user_keys;
  std::vector<std::string> notes;
  bool user_sets(const std::string& key) const;
};

// The alpha of a beckmann or ggx fiber; null for the other roughness models.
const roughness::MicrofacetAlpha* microfacet_alpha(const Roughness& g);

// The gaussian fiber of the same RMS facet slope per axis: Beckmann's slopes
// are Normal(0, alpha^2 / 2) per axis, so beta = atan(alpha / sqrt 2). A
// nominal width for the Gaussian-width models (GGX's slopes have no finite
// variance, and the calibrated widths are for gaussian facets).
double microfacet_as_gaussian(double alpha);

// SPEC s7's shifts of theta_r for tilt a: {-2a, a, 4a, 0}.
std::vector<double> tilt_shifts(double scale_tilt);

// How a model's longitudinal width parameter relates to the theta_r spread
// (standard deviation) of its lobe for small widths:
// - ThetaR: a spread in theta_r itself (d'Eon's M_p with v = beta^2:
//   M_p ~ exp(cos(theta_i + theta_r)/v), a Gaussian of sd beta in theta_r;
//   Marschner with longitudinal=two_theta_h);
// - ThetaH: a Gaussian in theta_h = (theta_i + theta_r)/2 (Marschner as
//   published): sd beta in theta_h is sd 2 beta in theta_r, so beta is half
//   the spread.
enum class WidthVariable { ThetaR, ThetaH };

struct LobeWidths {
  std::vector<double> beta_long, beta_azim;  // radians, indexed by p (0..lobes-1)
};

// beta_model_p / beta_gaussian for p = 0 (R), 1 (TT), 2 (TRT), measured by
// scripts/calibrate_widths.py (analytic/calibrated_widths.inc holds the
// numbers, the grid they come from and their held-out error).
struct WidthCalibration {
  double ratio[3];
  WidthVariable variable;  // the model's width variable the ratios are for
};
WidthCalibration deon2011_width_calibration();
// Marschner's Gaussian in theta_h; with two_theta_h the same lobe needs a
// width twice as large (a Gaussian in theta_r + theta_i).
WidthCalibration marschner2003_width_calibration(bool two_theta_h);

// The calibrated rule for a gaussian-rough fiber. beta_long, beta_azim: the
// simulator's gaussian roughness (radians). Longitudinal: ratio[p] *
// beta_long for p <= 2; p >= 3 scales TRT's ratio by the first-order spread
// ratio (not calibrated: faint lobes). Azimuthal: the first-order rule below
// (not calibrated; the target is the theta_r spread).
LobeWidths gaussian_lobe_widths(double beta_long, double beta_azim, double eta, int lobes,
                                const WidthCalibration& calibration);

// The first-order (small-angle, h = 0, normal incidence) theta_r spread of
// lobe p per unit of gaussian microfacet tilt: a reflection deviates a ray
// by 2 delta; a refraction by (eta - 1) delta once the exit refraction has
// magnified it; an internal reflection by 2 eta delta outside; independent
// events add in variance: p = 0: 2, p >= 1: sqrt(2 (eta-1)^2 + 4 eta^2 (p-1)).
// Used for the azimuthal widths (not calibrated) and for lobes p >= 3.
double first_order_spread(double eta, int p);

inline constexpr double kMinMarschnerBeta = 0.1 * 3.14159265358979323846 / 180.0;  // 0.1 deg

// The part of every model's physical defaults that is the same for all:
// eta, sigma_a, lobes copied into the model's struct P (each model's own
// rule adds its tilt: the theta_r shifts tilt_shifts() for a model with
// per-lobe shifts, the scale tilt itself for a model with one).
template <class P>
void apply_fiber_basics(const PhysicalFiber& fiber, P& params) {
  params.eta = fiber.eta;
  params.sigma_a = fiber.sigma_a;
  params.lobes = fiber.lobes;
}
// beta_long / beta_azim from the roughness (see the top of this file), in
// the model's width variable; every beta_long at least min_beta_long.
// A beckmann / ggx fiber goes through microfacet_as_gaussian() per axis, as
// a gaussian fiber, and the mapping is noted in `mapping`.
void apply_fiber_roughness(const PhysicalFiber& fiber, LobeWidths& widths,
                           const WidthCalibration& calibration, FiberMapping& mapping,
                           double min_beta_long = 0.0);

}  // namespace fiberlab::analytic
