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

// The roughness model the tracers apply: gaussian with beta_long = beta_azim
// = 0 is the smooth model, fallback included (SPEC section 3).
inline AnyRoughness make_roughness(const Settings& s) {
  const RoughnessSettings& r = s.roughness;
  switch (r.model) {
    case RoughnessModel::Beckmann:
    case RoughnessModel::GGX:
      return MicrofacetLifeModel(s);
    case RoughnessModel::Smooth:
      return life::SmoothRoughness(s);
    case RoughnessModel::Gaussian:
      if (r.beta_long.front() == 0.0 && r.beta_azim.front() == 0.0) return life::SmoothRoughness(s);
      return life::GaussianRoughness(s);
    case RoughnessModel::ExitBlur:
      return ExitBlurRoughness(s);
  }
  return life::SmoothRoughness(s);
}

// Whether the batched tracer runs the model of `r`: its type says
// (life::RunsBatched, sim/roughness/roughness_model.h); otherwise the
// reference tracer runs it.
inline bool runs_batched(const AnyRoughness& r) {
  return std::visit([](const auto& m) { return life::RunsBatched<std::decay_t<decltype(m)>>; }, r);
}

}  // namespace fiberlab::sim
