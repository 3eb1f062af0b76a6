#include "sim/roughness/microfacet_distribution.h"

#include <fmt/core.h>

#include <cmath>

#include "common/error.h"
#include "common/ggx.h"
#include "common/units.h"

namespace fiberlab::sim {

namespace {
using V = life::Vec3Of<double>;
}

MicrofacetFrame MicrofacetFrame::about(const Vec3& n) {
  const auto f = life::MicrofacetFrameOf<double>::about(V(n));
  return {f.t.to_vec3(), f.b.to_vec3(), f.n.to_vec3()};
}

MicrofacetDistribution::MicrofacetDistribution(MicrofacetModel model, double alpha_long,
                                               double alpha_azim)
    : model_(model), ax_(alpha_long), ay_(alpha_azim) {
  if (!(alpha_long > 0.0) || !(alpha_azim > 0.0) || !std::isfinite(alpha_long) || !std::isfinite(alpha_azim))
    throw Error(fmt::format("microfacet roughness alpha = [{}, {}]: must be finite and > 0",
                            alpha_long, alpha_azim));
}

double MicrofacetDistribution::D(const Vec3& m) const {
  const double z = m.z();
  if (model_ == MicrofacetModel::GGX) return ggx::D(m, ax_, ay_);
  if (z <= 0.0) return 0.0;
  const double r2 = m.x() * m.x() / (ax_ * ax_) + m.y() * m.y() / (ay_ * ay_);
  const double z2 = z * z;
  return std::exp(-r2 / z2) / (kPi * ax_ * ay_ * z2 * z2);
}

double MicrofacetDistribution::Lambda(const Vec3& w) const {
  return life::microfacet_lambda(model_, V(w), ax_, ay_);
}

double MicrofacetDistribution::G1(const Vec3& w) const {
  return life::microfacet_g1(model_, V(w), ax_, ay_);
}

double MicrofacetDistribution::visible_density(const Vec3& w, const Vec3& m) const {
  if (w.z() <= 0.0) return 0.0;
  return G1(w) * std::max(0.0, w.dot(m)) * D(m) / w.z();
}

Vec3 MicrofacetDistribution::sample_visible(const Vec3& w, double u1, double u2) const {
  return life::microfacet_visible_normal(model_, V(w), ax_, ay_, u1, u2, true).to_vec3();
}

std::optional<Vec3> MicrofacetDistribution::sample_visible(const MicrofacetFrame& frame, const Vec3& d,
                                                           double u1, double u2) const {
  const Vec3 w = frame.to_local(-d);
  if (!(w.z() > 0.0)) return std::nullopt;
  return frame.to_world(sample_visible(w, u1, u2));
}

}  // namespace fiberlab::sim
