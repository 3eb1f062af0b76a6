#include "sim/roughness/microfacet_distribution.h"

#include <fmt/core.h>

#include <algorithm>
#include <boost/math/special_functions/erf.hpp>
#include <cmath>

#include "common/error.h"
#include "common/ggx.h"
#include "common/units.h"

namespace fiberlab::sim {

namespace {
constexpr double kSqrtPi = 1.7724538509055160273;
}

MicrofacetFrame MicrofacetFrame::about(const Vec3& n, const Vec3& axis) {
  MicrofacetFrame f;
  f.n = n;
  Vec3 t = axis - axis.dot(n) * n;
  if (t.squaredNorm() < 1e-24) {
    // axis parallel to n: any tangent will do.
    t = std::abs(n.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    t -= t.dot(n) * n;
  }
  f.t = t.normalized();
  f.b = n.cross(f.t);
  return f;
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
  if (model_ == MicrofacetModel::GGX) return ggx::Lambda(w, ax_, ay_);
  const double z = w.z();
  const double s = std::sqrt(ax_ * ax_ * w.x() * w.x() + ay_ * ay_ * w.y() * w.y());
  if (s == 0.0) return 0.0;  // w along the normal: nothing masks it
  const double a = z / s;    // 1 / (alpha tan theta) in the stretched configuration
  return 0.5 * (std::erf(a) - 1.0) + std::exp(-a * a) / (2.0 * a * kSqrtPi);
}

double MicrofacetDistribution::G1(const Vec3& w) const {
  if (w.z() <= 0.0) return 0.0;
  return 1.0 / (1.0 + Lambda(w));
}

double MicrofacetDistribution::visible_density(const Vec3& w, const Vec3& m) const {
  if (w.z() <= 0.0) return 0.0;
  return G1(w) * std::max(0.0, w.dot(m)) * D(m) / w.z();
}

Vec3 MicrofacetDistribution::sample_ggx_stretched(const Vec3& w, double u1, double u2) const {
  return ggx::sample_visible(w, ax_, ay_, u1, u2);  // Heitz 2018 (common/ggx.h)
}

void MicrofacetDistribution::sample_beckmann_slopes(double cos_theta, double u1, double u2,
                                                    double& x, double& y) const {
  // Heitz and d'Eon 2014, section 4: x from the marginal CDF of visible slopes
  //   C(x) = cos(theta) (1 + erf x) / 2 + sin(theta) exp(-x^2) / (2 sqrt pi), x <= cot(theta),
  // whose derivative is the density (cos theta - x sin theta) exp(-x^2) / sqrt(pi).
  const double c = std::clamp(cos_theta, 0.0, 1.0);
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  auto C = [&](double t) { return 0.5 * c * std::erfc(-t) + s * std::exp(-t * t) / (2.0 * kSqrtPi); };
  auto dC = [&](double t) { return (c - t * s) * std::exp(-t * t) / kSqrtPi; };
  // Bracket: [-9, min(cot theta, 9)]; erfc(9) ~ 4e-37 and exp(-81) ~ 7e-36 lie
  // below any target u1 C(hi) >= 2^-53 * 0.28 except u1 = 0 (then x = -9).
  double lo = -9.0, hi = s > 0.0 ? std::min(c / s, 9.0) : 9.0;
  const double target = u1 * C(hi);
  double t = 0.0;
  if (t <= lo || t >= hi) t = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const double g = C(t) - target;
    if (g > 0.0) hi = t; else lo = t;
    const double d = dC(t);
    double tn = d > 0.0 ? t - g / d : 0.5 * (lo + hi);
    if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    if (std::abs(tn - t) <= 1e-15 * (1.0 + std::abs(t)) || hi - lo <= 1e-15) {
      t = tn;
      break;
    }
    t = tn;
  }
  x = t;
  // y | x ~ Normal(0, 1/2): the projected area depends on x only.
  const double v = std::clamp(2.0 * u2 - 1.0, -1.0 + 1e-16, 1.0 - 1e-16);
  y = boost::math::erf_inv(v);
}

Vec3 MicrofacetDistribution::sample_visible(const Vec3& w, double u1, double u2) const {
  if (model_ == MicrofacetModel::GGX) return sample_ggx_stretched(w, u1, u2);
  // Stretch to alpha = 1, rotate w into the x-z plane, sample, rotate back, unstretch.
  const Vec3 ws = Vec3(ax_ * w.x(), ay_ * w.y(), w.z()).normalized();
  const double rxy = std::hypot(ws.x(), ws.y());
  const double cphi = rxy > 0.0 ? ws.x() / rxy : 1.0, sphi = rxy > 0.0 ? ws.y() / rxy : 0.0;
  double sx, sy;
  sample_beckmann_slopes(ws.z(), u1, u2, sx, sy);
  const double x = (cphi * sx - sphi * sy) * ax_;
  const double y = (sphi * sx + cphi * sy) * ay_;
  // A facet with slopes (x, y) has normal (-x, -y, 1) normalised.
  return Vec3(-x, -y, 1.0).normalized();
}

std::optional<Vec3> MicrofacetDistribution::sample_visible(const MicrofacetFrame& frame, const Vec3& d,
                                                           double u1, double u2) const {
  const Vec3 w = frame.to_local(-d);
  if (!(w.z() > 0.0)) return std::nullopt;
  return frame.to_world(sample_visible(w, u1, u2));
}

}  // namespace fiberlab::sim
