#pragma once
// The fiber's cross-section (SPEC section 2): an ellipse in the normal plane
// with semi-axes r_v = 1/sqrt(e) along v and r_w = sqrt(e) along w, so that its
// area is that of the unit circle. Points are (v, w) pairs; directions are 3D
// fiber-frame vectors (u, v, w) of which only the (v, w) part matters here.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "common/fiber_frame.h"

namespace fiberlab::sim {

using Point2 = Eigen::Vector2d;

class EllipseCrossSection {
 public:
  explicit EllipseCrossSection(double eccentricity)
      : rv_(1.0 / std::sqrt(eccentricity)), rw_(std::sqrt(eccentricity)),
        inv_rv2_(eccentricity), inv_rw2_(1.0 / eccentricity) {}

  double r_v() const { return rv_; }
  double r_w() const { return rw_; }

  // Outward unit normal n0 at a boundary point, in the normal plane.
  Vec3 normal(const Point2& p) const {
    const double nv = p.x() * inv_rv2_, nw = p.y() * inv_rw2_;
    const double inv = 1.0 / std::sqrt(nv * nv + nw * nw);
    return Vec3(0.0, nv * inv, nw * inv);
  }

  // Where a photon travelling along d (3D, unit) enters, given the impact
  // parameter h in (-1, 1) across the projected width. The ellipse is the
  // unit circle scaled by (r_v, r_w); that affine map keeps parallel lines
  // parallel and ratios across the beam, so uniform h on the ellipse is
  // uniform impact parameter on the circle, where the entry point is exact.
  Point2 entry_point(const Vec3& d, double h) const {
    return entry_point_in_beam(beam_direction(d), h);
  }
  // The two halves of entry_point, for a source that launches many photons
  // along one direction: the unit beam direction in circle space, then the
  // entry point of impact parameter h.
  Eigen::Vector2d beam_direction(const Vec3& d) const {
    return Eigen::Vector2d(d.y() / rv_, d.z() / rw_).normalized();
  }
  Point2 entry_point_in_beam(const Eigen::Vector2d& g, double h) const {
    const Eigen::Vector2d g_perp(-g.y(), g.x());
    const Eigen::Vector2d q = h * g_perp - std::sqrt(std::max(0.0, 1.0 - h * h)) * g;
    return Point2(rv_ * q.x(), rw_ * q.y());
  }

  // From a boundary point p, travelling inside along d: the 3D distance to
  // the next boundary point. For p on the ellipse the quadratic
  // A t^2 + B t + C = 0 has C = 0, so the far root is t = -B / A exactly.
  // Returns +inf when d runs along the axis (no boundary ahead).
  double distance_to_boundary(const Point2& p, const Vec3& d) const {
    const double a = d.y() * d.y() * inv_rv2_ + d.z() * d.z() * inv_rw2_;
    const double b = 2.0 * (p.x() * d.y() * inv_rv2_ + p.y() * d.z() * inv_rw2_);
    if (a <= 0.0) return INFINITY;
    return std::max(0.0, -b / a);
  }

  // Moves p along d by t and puts it back on the boundary (removes drift).
  Point2 advance(const Point2& p, const Vec3& d, double t) const {
    Point2 q(p.x() + t * d.y(), p.y() + t * d.z());
    const double s = std::sqrt(q.x() * q.x() * inv_rv2_ + q.y() * q.y() * inv_rw2_);
    return q / s;
  }

 private:
  double rv_, rw_, inv_rv2_, inv_rw2_;
};

}  // namespace fiberlab::sim
