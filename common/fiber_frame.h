#pragma once
// The fiber frame {u, v, w} of SPEC section 1, stored as Eigen vectors with
// components (u, v, w): u is the tangent (root -> tip), v the major axis of the
// cross-section, w the minor axis.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace fiberlab {

using Vec3 = Eigen::Vector3d;

// Unit direction from inclination theta (asin(d.u)) and azimuth phi
// (atan2(d.w, d.v)), SPEC section 1.
inline Vec3 direction_from_angles(double theta, double phi) {
  const double c = std::cos(theta);
  return Vec3(std::sin(theta), c * std::cos(phi), c * std::sin(phi));
}

inline double inclination(const Vec3& d) { return std::asin(std::clamp(d.x(), -1.0, 1.0)); }
inline double azimuth(const Vec3& d) { return std::atan2(d.z(), d.y()); }

}  // namespace fiberlab
