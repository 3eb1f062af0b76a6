#pragma once
// Roughness models `beckmann` and `ggx` (sim/roughness/microfacet_roughness.h) as a
// roughness model of the photon life (sim/roughness/roughness_model.h), for
// one photon or a vector of photons. The VNDF samplers do not reject: one
// pair of uniforms per event, never a failure but for rounding.
#include "sim/roughness/microfacet_roughness.h"
#include "sim/roughness/roughness_model.h"

namespace fiberlab::sim {

struct MicrofacetLifeModel {
  MicrofacetLifeModel(MicrofacetModel model, const roughness::MicrofacetAlpha& r) : roughness(model, r) {}

  template <class T>
  life::FacetDraw<T> draw_normal(const life::Vec3Of<T>& d, const life::BoundaryFrame<T>& frame,
                                 const life::MaskOf<T>& live, life::LaneRandom<T>& rng,
                                 T& /*tries*/, life::LifeCounts<T>& counts, int /*rounds*/) const {
    counts.normal_draws = counts.normal_draws + life::ones<T>(live);
    const auto [u1, u2] = rng.template uniforms<2>(live);
    const life::Vec3Of<T> mean =
        MicrofacetRoughness::mean_normal(d, frame.facing, frame.untilted_facing);
    life::MaskOf<T> ok;
    const life::Vec3Of<T> m = roughness.sample_normal(d, mean, u1, u2, live, ok);
    const life::MaskOf<T> failed = live & !ok;
    counts.sampler_caps = counts.sampler_caps + life::ones<T>(failed);
    return {select(ok, m, d), ok, failed};
  }

  // Smith G1 masking of the outgoing direction: the throughput factor; a
  // factor 0 ends the path (Lost).
  template <class T>
  life::EventWeight<T> event_weight(const life::EventGeometry<T>& e,
                                    const life::MaskOf<T>& /*act*/,
                                    life::LaneRandom<T>& /*rng*/) const {
    if (!roughness.masks()) return {T(1.0), life::MaskOf<T>(false)};
    const life::Vec3Of<T> mean =
        MicrofacetRoughness::mean_normal(e.d_in, e.frame.facing, e.frame.untilted_facing);
    const T g1 = roughness.masking_factor(mean, e.d_out, e.refracted);
    return {g1, !(g1 > T(0.0))};  // photon_life keeps the lanes that acted
  }

  MicrofacetRoughness roughness;
};

}  // namespace fiberlab::sim
