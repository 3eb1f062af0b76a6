#pragma once
// The fiber's cross-section (SPEC section 2): an ellipse in the normal plane
// with semi-axes r_v = 1/sqrt(e) along v and r_w = sqrt(e) along w, so that its
// area is that of the unit circle. Points are (v, w) pairs; directions are 3D
// fiber-frame vectors (u, v, w) of which only the (v, w) part matters here.
//
// The geometry a photon's life uses at every step (normal, distance to the
// boundary, advance) is written once for a number type T (sim/simd/lanes.h): one
// photon (double) or a SIMD vector of photons.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "common/fiber_frame.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim {

using Point2 = Eigen::Vector2d;

class EllipseCrossSection {
 public:
  explicit EllipseCrossSection(double eccentricity)
      : rv_(1.0 / std::sqrt(eccentricity)), rw_(std::sqrt(eccentricity)),
        inv_rv2_(eccentricity), inv_rw2_(1.0 / eccentricity) {}

  double r_v() const { return rv_; }
  double r_w() const { return rw_; }

  // Outward unit normal n0 at the boundary point (pv, pw), in the normal
  // plane: the gradient of v^2 / r_v^2 + w^2 / r_w^2, normalised.
  template <class T>
  life::Vec3Of<T> normal_at(const T& pv, const T& pw) const {
    using namespace life;
    const T nv = pv * T(inv_rv2_), nw = pw * T(inv_rw2_);
    const T inv = T(1.0) / sqrt(nv * nv + nw * nw);
    return {T(0.0), nv * inv, nw * inv};
  }
  Vec3 normal(const Point2& p) const { return normal_at(p.x(), p.y()).to_vec3(); }

  // From a boundary point (pv, pw), travelling inside along (., dv, dw): the
  // 3D distance to the next boundary point. For a point on the ellipse the
  // quadratic A t^2 + B t + C = 0 has C = 0, so the far root is t = -B / A
  // exactly. `along_axis` is set where A = 0 (d runs along the fiber axis:
  // no boundary ahead); t is 0 there.
  template <class T>
  T distance_to_boundary(const T& pv, const T& pw, const T& dv, const T& dw,
                         life::MaskOf<T>& along_axis) const {
    using namespace life;
    const T a = dv * dv * T(inv_rv2_) + dw * dw * T(inv_rw2_);
    const T b = T(2.0) * (pv * dv * T(inv_rv2_) + pw * dw * T(inv_rw2_));
    along_axis = a <= T(0.0);
    return select(along_axis, T(0.0), max(T(0.0), -b / a));
  }
  // Returns +inf when d runs along the axis.
  double distance_to_boundary(const Point2& p, const Vec3& d) const {
    bool along_axis = false;
    const double t = distance_to_boundary(p.x(), p.y(), d.y(), d.z(), along_axis);
    return along_axis ? INFINITY : t;
  }

  // Moves (pv, pw) along d by t and puts it back on the boundary (removes drift).
  template <class T>
  void advance(T& pv, T& pw, const T& dv, const T& dw, const T& t) const {
    using namespace life;
    const T qv = pv + t * dv, qw = pw + t * dw;
    const T s = T(1.0) / sqrt(qv * qv * T(inv_rv2_) + qw * qw * T(inv_rw2_));
    pv = qv * s;
    pw = qw * s;
  }
  Point2 advance(const Point2& p, const Vec3& d, double t) const {
    double pv = p.x(), pw = p.y();
    advance(pv, pw, d.y(), d.z(), t);
    return Point2(pv, pw);
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
    double pv, pw;
    entry_point_in_beam(g, h, pv, pw);
    return Point2(pv, pw);
  }
  // The same for one photon or a vector of them: q = h g_perp - sqrt(1 - h^2) g
  // on the unit circle, g_perp = (-g_w, g_v), scaled to the ellipse. Written
  // with explicit fused multiply-adds so that both round alike.
  template <class T>
  void entry_point_in_beam(const Eigen::Vector2d& g, const T& h, T& pv, T& pw) const {
    entry_point_in_beam(T(g.x()), T(g.y()), h, pv, pw);
  }
  // The same with the beam direction (gv, gw) per lane (beam_direction_of).
  template <class T>
  void entry_point_in_beam(const T& gv, const T& gw, const T& h, T& pv, T& pw) const {
    using namespace life;
    const T s = sqrt(max(T(0.0), fma(-h, h, T(1.0))));
    pv = T(rv_) * fma(h, -gw, -(s * gv));
    pw = T(rw_) * fma(h, gv, -(s * gw));
  }
  // beam_direction for one photon or a vector of them, each its own d
  // (exit splitting's extra entry points). beam_direction keeps Eigen's
  // normalized(), which rounds differently in the last bit: the source's
  // entry points, and so every run's numbers, stay as they are.
  template <class T>
  void beam_direction_of(const T& dv, const T& dw, T& gv, T& gw) const {
    using namespace life;
    const T a = dv / T(rv_), b = dw / T(rw_);
    const T norm = sqrt(a * a + b * b);
    gv = a / norm;
    gw = b / norm;
  }

 private:
  double rv_, rw_, inv_rv2_, inv_rw2_;
};

}  // namespace fiberlab::sim
