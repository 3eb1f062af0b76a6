#pragma once
// Roughness models `beckmann` and `ggx` (sim/roughness/microfacet_roughness.h) as a
// roughness model of the photon life (sim/roughness/roughness_model.h). Scalar only:
// its visible-normal sampler is written for one photon, so
// Simulation traces these models with the reference Tracer (kScalarOnly);
// making MicrofacetRoughness generic over T would run it batched unchanged.
#include "sim/roughness/microfacet_normal.h"
#include "sim/roughness/microfacet_roughness.h"
#include "sim/roughness/roughness_model.h"

namespace fiberlab::sim {

struct MicrofacetLifeModel {
  static constexpr bool kScalarOnly = true;
  explicit MicrofacetLifeModel(const Settings& s) : roughness(s.roughness) {}

  life::FacetDraw<double> draw_normal(const life::Vec3Of<double>& d,
                                      const life::BoundaryFrame<double>& frame, bool live,
                                      life::LaneRandom<double>& rng, double& /*tries*/,
                                      life::LifeCounts<double>& counts, int /*rounds*/) const {
    if (!live) return {d, false, false};
    counts.normal_draws += 1.0;
    const Vec3 dir = d.to_vec3();
    const Vec3 mean = MicrofacetRoughness::mean_normal(
        dir, BoundaryNormals{frame.facing.to_vec3(), frame.untilted_facing.to_vec3()});
    PhotonRandom stream(rng);
    const std::optional<Vec3> m = roughness.sample_normal(dir, mean, stream);
    rng = stream.core();
    if (!m) {
      counts.sampler_caps += 1.0;
      return {d, false, true};
    }
    return {life::Vec3Of<double>(*m), true, false};
  }

  // Smith G1 masking of the outgoing direction: the throughput factor; a
  // factor 0 ends the path (Lost).
  life::EventWeight<double> event_weight(const life::EventGeometry<double>& e, bool act,
                                         life::LaneRandom<double>& /*rng*/) const {
    if (!act || !roughness.masks()) return {1.0, false};
    const Vec3 mean = MicrofacetRoughness::mean_normal(
        e.d_in.to_vec3(),
        BoundaryNormals{e.frame.facing.to_vec3(), e.frame.untilted_facing.to_vec3()});
    const double g1 = roughness.masking_factor(mean, e.d_out.to_vec3(), e.refracted);
    return {g1, !(g1 > 0.0)};
  }

  MicrofacetRoughness roughness;
};

}  // namespace fiberlab::sim
