#include "sim/microfacet_normal.h"

#include <cmath>

namespace fiberlab::sim {

Vec3 smooth_normal(const Vec3& d, const BoundaryNormals& n) {
  return d.dot(n.facing) < 0.0 ? n.facing : n.untilted_facing;
}

std::optional<Vec3> gaussian_normal(const Vec3& d, const Vec3& n_facing, double beta_long,
                                    double beta_azim, PhotonRandom& rng, int max_tries,
                                    long& tries) {
  // n_f = sin(theta_n) u + cos(theta_n) n_perp with n_perp a unit vector in
  // the normal plane (n_f is never parallel to u: |tilt| < 45 deg).
  const double theta_n = std::asin(n_facing.x());
  const double inv = 1.0 / std::hypot(n_facing.y(), n_facing.z());
  const double pv = n_facing.y() * inv, pw = n_facing.z() * inv;
  for (int k = 0; k < max_tries; ++k) {
    ++tries;
    const double t = theta_n + beta_long * rng.normal();
    const double a = beta_azim * rng.normal();
    const double ct = std::cos(t), ca = std::cos(a), sa = std::sin(a);
    // Rotate n_perp by a about u, then tilt to inclination t.
    const Vec3 m(std::sin(t), ct * (pv * ca - pw * sa), ct * (pv * sa + pw * ca));
    const double visible = -d.dot(m);
    if (visible > 0.0 && rng.uniform() < visible) return m;
  }
  return std::nullopt;
}

}  // namespace fiberlab::sim
