#include "sim/roughness/microfacet_roughness.h"

#include "common/error.h"

namespace fiberlab::sim {

namespace {

using V = life::Vec3Of<double>;

}  // namespace

MicrofacetRoughness::MicrofacetRoughness(MicrofacetModel model, const roughness::MicrofacetAlpha& r)
    : distribution_(model, r.alpha_long, r.alpha_azim), masking_(r.masking) {}

Vec3 MicrofacetRoughness::mean_normal(const Vec3& d, const BoundaryNormals& n) {
  return mean_normal(V(d), V(n.facing), V(n.untilted_facing)).to_vec3();
}

std::optional<Vec3> MicrofacetRoughness::sample_normal(const Vec3& d, const Vec3& mean,
                                                       PhotonRandom& rng) const {
  const double u1 = rng.uniform(), u2 = rng.uniform();
  bool ok = false;
  const V m = sample_normal(V(d), V(mean), u1, u2, true, ok);
  if (!ok) return std::nullopt;
  return m.to_vec3();
}

double MicrofacetRoughness::masking_factor(const Vec3& mean, const Vec3& d_out,
                                           bool refracted) const {
  return masking_factor(V(mean), V(d_out), refracted);
}

}  // namespace fiberlab::sim
