#include "sim/roughness/microfacet_roughness.h"

#include "common/error.h"

namespace fiberlab::sim {

namespace {

MicrofacetModel distribution_model(RoughnessModel m) {
  if (m == RoughnessModel::Beckmann) return MicrofacetModel::Beckmann;
  if (m == RoughnessModel::GGX) return MicrofacetModel::GGX;
  throw Error("internal error: microfacet roughness for a model that is not beckmann or ggx");
}

}  // namespace

MicrofacetRoughness::MicrofacetRoughness(const RoughnessSettings& r)
    : distribution_(distribution_model(r.model), r.alpha_long, r.alpha_azim), masking_(r.masking) {}

std::optional<Vec3> MicrofacetRoughness::sample_normal(const Vec3& d, const Vec3& mean,
                                                       PhotonRandom& rng) const {
  const double u1 = rng.uniform(), u2 = rng.uniform();
  const std::optional<Vec3> m = distribution_.sample_visible(frame(mean), d, u1, u2);
  // The VNDF has d.m <= 0; d.m = 0 (a facet seen exactly edge-on, probability
  // zero up to rounding) has no event.
  if (!m || !(d.dot(*m) < 0.0)) return std::nullopt;
  return m;
}

double MicrofacetRoughness::masking_factor(const Vec3& mean, const Vec3& d_out,
                                           bool refracted) const {
  // A refracted direction is judged from the other side of the mean surface,
  // as -d_out (Lambda depends on w_x, w_y only through their squares).
  const Vec3 w = frame(mean).to_local(refracted ? Vec3(-d_out) : d_out);
  return distribution_.G1(w);  // 0 for w_z <= 0: the wrong side
}

}  // namespace fiberlab::sim
