#pragma once
// The registry of roughness models (sim/roughness/roughness_model.h says what a model
// is and how to add one): every model the tracers can run, which one a
// configuration selects, and whether the batched tracer runs it.
#include <variant>

#include "sim/life/exit_blur.h"
#include "sim/roughness/roughness_gaussian.h"
#include "sim/roughness/roughness_microfacet.h"
#include "sim/roughness/roughness_smooth.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

using AnyRoughness = std::variant<life::SmoothRoughness, life::GaussianRoughness, ExitBlurRoughness,
                                  MicrofacetLifeModel>;

// The sampler of each roughness of the fiber (common/roughness/roughness.h).
inline AnyRoughness life_model(const roughness::Smooth&) { return life::SmoothRoughness(); }
// Gaussian with beta_long = beta_azim = 0 is the smooth model, fallback
// included (SPEC section 3).
inline AnyRoughness life_model(const roughness::Gaussian& g) {
  if (g.beta_long == 0.0 && g.beta_azim == 0.0) return life::SmoothRoughness();
  return life::GaussianRoughness(g.beta_long, g.beta_azim);
}
inline AnyRoughness life_model(const roughness::ExitBlur& e) { return ExitBlurRoughness(e); }
inline AnyRoughness life_model(const roughness::Beckmann& b) {
  return MicrofacetLifeModel(MicrofacetModel::Beckmann, b);
}
inline AnyRoughness life_model(const roughness::Ggx& g) { return MicrofacetLifeModel(MicrofacetModel::GGX, g); }

// The roughness model the tracers apply to the fiber of `s`.
inline AnyRoughness make_roughness(const Settings& s) {
  return std::visit([](const auto& r) { return life_model(r); }, s.fiber.roughness);
}

// Whether the batched tracer runs the model of `r`: its type says
// (life::RunsBatched, sim/roughness/roughness_model.h); otherwise the
// reference tracer runs it.
inline bool runs_batched(const AnyRoughness& r) {
  return std::visit([](const auto& m) { return life::RunsBatched<std::decay_t<decltype(m)>>; }, r);
}

}  // namespace fiberlab::sim
