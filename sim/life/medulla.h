#pragma once
// The medulla (docs/FUR.md): a scattering core inside the fiber, the
// cross-section scaled by k about the axis (semi-axes k r_v, k r_w), filled
// with a medium of scattering coefficient sigma_s (1/R), a Henyey-Greenstein
// phase function of anisotropy g, and index eta_m. Its absorption is not
// here: the life adds up the 3D length travelled inside the medulla, and the
// scorer turns it into exp(-sigma_a_medulla[c] l) per channel, as it does
// the cortex's length with the fiber's sigma_a (SPEC section 4).
//
// A cortex segment (outer boundary to outer boundary, SPEC section 5) whose
// chord meets the medulla is replaced by a walk: to the medulla, a smooth
// Fresnel event on its boundary if eta_m != eta (the medulla has no tilt
// and no roughness), free paths and scatterings inside, a Fresnel event at
// each arrival on the boundary from inside, then the rest of the way to the
// outer boundary. The walk stays within the segment: the lobe index p counts
// outer-boundary segments whatever happened in the medulla.
//
// Polarisation: the phase function is the scalar Henyey-Greenstein one,
// with an unpolarising scatter (Stokes light is reset to (1, 0, 0, 0) at
// every scattering event; refraction and reflection at the medulla's
// boundary use the full Fresnel Mueller matrices of SPEC section 3).
//
// Written once for the number type T (sim/simd/lanes.h): lanes that do not
// take part draw no random numbers, and every branch is a mask.
#include <cmath>

#include "sim/life/interface_event.h"
#include "sim/simd/life_log.h"
#include "sim/simd/life_trig.h"
#include "sim/simd/lanes.h"

namespace fiberlab::sim::life {

// An ellipse centred on the axis, v^2 inv_v2 + w^2 inv_w2 = 1.
struct AxisEllipse {
  double inv_v2 = 1.0, inv_w2 = 1.0;

  // The ray (pv, pw) + t (dv, dw): the terms of A t^2 + 2 b t + C = 0.
  template <class T>
  void quadratic(const T& pv, const T& pw, const T& dv, const T& dw, T& a, T& b, T& c) const {
    a = dv * dv * T(inv_v2) + dw * dw * T(inv_w2);
    b = pv * dv * T(inv_v2) + pw * dw * T(inv_w2);
    c = pv * pv * T(inv_v2) + pw * pw * T(inv_w2) - T(1.0);
  }
  // From a point inside or on the ellipse (C <= 0), the distance to the
  // boundary ahead: the non-negative root, in the form that does not cancel
  // (q = -(b + sign(b) sqrt(disc)); roots q / A and C / q). `along_axis`
  // where A = 0 (no boundary ahead; t is 0 there).
  template <class T>
  T exit_distance(const T& pv, const T& pw, const T& dv, const T& dw,
                  MaskOf<T>& along_axis) const {
    T a, b, c;
    quadratic(pv, pw, dv, dw, a, b, c);
    c = min(c, T(0.0));
    along_axis = a <= T(0.0);
    const T root = sqrt(max(T(0.0), b * b - a * c));
    const MaskOf<T> forward = b < T(0.0);
    const T safe_a = select(along_axis, T(1.0), a);
    const T q = select(forward, root - b, -(b + root));
    const T safe_q = select(q == T(0.0), T(1.0), q);
    const T t = select(forward, q / safe_a, c / safe_q);
    return select(along_axis, T(0.0), max(T(0.0), t));
  }
  // Outward unit normal at a boundary point, in the normal plane.
  template <class T>
  Vec3Of<T> normal_at(const T& pv, const T& pw) const {
    const T nv = pv * T(inv_v2), nw = pw * T(inv_w2);
    const T inv = T(1.0) / sqrt(nv * nv + nw * nw);
    return {T(0.0), nv * inv, nw * inv};
  }
  // Puts a point back on the boundary along its ray from the centre.
  template <class T>
  void snap(T& pv, T& pw) const {
    const T s = T(1.0) / sqrt(pv * pv * T(inv_v2) + pw * pw * T(inv_w2));
    pv = pv * s;
    pw = pw * s;
  }
};

struct MedullaConfig {
  bool present = false;
  AxisEllipse inner;  // the medulla's boundary
  AxisEllipse outer;  // the fiber's
  double sigma_s = 0.0, g = 0.0;
  bool interface = false;    // eta_m != eta: Fresnel events on the medulla's boundary
  double eta_in = 1.0;       // eta_m / eta: the relative index entering the medulla
  int max_events = 1000;     // scatterings and reflections inside per visit (max_segments)

  MedullaConfig() = default;
  // r_v, r_w: the fiber's semi-axes (SPEC section 2).
  MedullaConfig(double r_v, double r_w, double k, double sigma_s_, double g_, double eta_fiber,
                double eta_medulla, int max_segments)
      : present(true), inner{1.0 / (k * r_v * k * r_v), 1.0 / (k * r_w * k * r_w)},
        outer{1.0 / (r_v * r_v), 1.0 / (r_w * r_w)}, sigma_s(sigma_s_), g(g_),
        interface(eta_medulla != eta_fiber), eta_in(eta_medulla / eta_fiber),
        max_events(max_segments) {}
};

// cos of the scattering angle from a uniform u in [0, 1) (Henyey and
// Greenstein 1941; the inversion of their CDF as in pbrt-v3 section 15.2.3):
// cos = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g), and 1 - 2u for g = 0.
template <class T>
T henyey_greenstein_cos(double g, const T& u) {
  if (std::abs(g) < 1e-5) return T(1.0) - T(2.0) * u;
  const T f = T(1.0 - g * g) / (T(1.0 - g) + T(2.0 * g) * u);
  return max(T(-1.0), min(T(1.0), (T(1.0 + g * g) - f * f) * T(1.0 / (2.0 * g))));
}

// The direction at angle acos(cos_t) from d, turned by the azimuth whose
// sine and cosine are (sp, cp) about d, in the orthonormal frame of Duff et
// al. 2017 ("Building an orthonormal basis, revisited", listing 3).
template <class T>
Vec3Of<T> turn_direction(const Vec3Of<T>& d, const T& cos_t, const T& sp, const T& cp) {
  const T sign = select(d.z >= T(0.0), T(1.0), T(-1.0));
  const T a = T(-1.0) / (sign + d.z);
  const T b = d.x * d.y * a;
  const Vec3Of<T> t1(T(1.0) + sign * d.x * d.x * a, sign * b, -sign * d.x);
  const Vec3Of<T> t2(b, sign + d.y * d.y * a, -d.y);
  const T sin_t = sqrt(max(T(0.0), T(1.0) - cos_t * cos_t));
  return ((sin_t * cp) * t1 + (sin_t * sp) * t2 + cos_t * d).normalized();
}

// A scattering event unpolarises the light (see the top of this file).
template <class T>
void unpolarize(ScalarLight<T>&, const Vec3Of<T>&, const MaskOf<T>&) {}
template <class T>
void unpolarize(StokesLight<T>& l, const Vec3Of<T>& d, const MaskOf<T>& m) {
  const StokesLight<T> fresh(d);
  l.q = select(m, T(0.0), l.q);
  l.u = select(m, T(0.0), l.u);
  l.v = select(m, T(0.0), l.v);
  l.e1 = select(m, fresh.e1, l.e1);
}

// What a segment's walk through the medulla changed, per lane.
template <class T>
struct MedullaWalk {
  T cortex;         // 3D length travelled in the cortex
  T medulla;        // 3D length travelled in the medulla
  T scatters;       // scattering events
  T pv, pw;         // the end point on the outer boundary
  MaskOf<T> met;    // the chord met the medulla (the other lanes are unchanged)
  MaskOf<T> stuck;  // still inside after max_events events, or running along the axis: truncated
};

// For the lanes in `go`, at outer boundary points (pv, pw) travelling inside
// along d: if the chord meets the medulla, the walk through it (d, the light
// and the random stream change for those lanes).
template <class T, class Light>
MedullaWalk<T> walk_medulla(const MedullaConfig& m, const T& pv0, const T& pw0, Vec3Of<T>& d,
                            Light& light, LaneRandom<T>& rng, const MaskOf<T>& go) {
  MedullaWalk<T> w{T(0.0), T(0.0), T(0.0), pv0, pw0, MaskOf<T>(false), MaskOf<T>(false)};
  T a, b, c;
  m.inner.quadratic(pv0, pw0, d.y, d.z, a, b, c);
  const T disc = b * b - a * c;
  w.met = go & (a > T(0.0)) & (b < T(0.0)) & (disc > T(0.0));
  if (!any(w.met)) return w;
  // The near root C / (sqrt(disc) - b) (no cancellation: b < 0).
  const T t_in = select(w.met, c / (sqrt(max(T(0.0), disc)) - b), T(0.0));
  T qv = pv0 + t_in * d.y, qw = pw0 + t_in * d.z;
  m.inner.snap(qv, qw);
  w.cortex = t_in;
  MaskOf<T> inside = w.met;
  if (m.interface) {
    const Vec3Of<T> n = m.inner.normal_at(qv, qw);  // faces the photon arriving from the cortex
    const EventResult<T> r =
        light.interact(d, n, InterfaceIndex<T>{T(m.eta_in), T(1.0 / m.eta_in)}, w.met, rng);
    d = select(w.met, r.direction, d);
    inside = w.met & r.refracted;
  }
  T events(0.0);
  while (any(inside)) {
    MaskOf<T> along_axis(false);
    const T t_b = m.inner.exit_distance(qv, qw, d.y, d.z, along_axis);
    MaskOf<T> scatter(false);
    T t = t_b;
    if (m.sigma_s > 0.0) {
      // Free path -ln(u) / sigma_s, u in (0, 1].
      const T t_s = -log_normal(rng.uniform_open0(inside)) * T(1.0 / m.sigma_s);
      scatter = inside & ((t_s < t_b) | along_axis);
      t = select(scatter, t_s, t_b);
    }
    const MaskOf<T> axis_stuck = inside & along_axis & !scatter;
    const MaskOf<T> reach = inside & !scatter & !along_axis;
    w.medulla = w.medulla + select(inside & !axis_stuck, t, T(0.0));
    qv = select(inside, qv + t * d.y, qv);
    qw = select(inside, qw + t * d.z, qw);
    T sv = qv, sw = qw;
    m.inner.snap(sv, sw);
    qv = select(reach, sv, qv);
    qw = select(reach, sw, qw);
    if (any(scatter)) {
      const T cos_t = henyey_greenstein_cos(m.g, rng.uniform(scatter));
      const auto [sp, cp] = sincos_turn(rng.uniform(scatter));
      d = select(scatter, turn_direction(d, cos_t, sp, cp), d);
      unpolarize(light, d, scatter);
      w.scatters = w.scatters + ones<T>(scatter);
    }
    MaskOf<T> leave = reach;
    if (m.interface && any(reach)) {
      const Vec3Of<T> n = -m.inner.normal_at(qv, qw);  // faces the photon inside
      const EventResult<T> r =
          light.interact(d, n, InterfaceIndex<T>{T(1.0 / m.eta_in), T(m.eta_in)}, reach, rng);
      d = select(reach, r.direction, d);
      leave = reach & r.refracted;
    }
    inside = inside & !leave & !axis_stuck;
    events = events + ones<T>(inside);
    const MaskOf<T> over = inside & (events >= T(double(m.max_events)));
    w.stuck = w.stuck | axis_stuck | over;
    inside = inside & !over;
  }
  // From the medulla's boundary (or a reflection off it) to the outer boundary.
  const MaskOf<T> out = w.met & !w.stuck;
  MaskOf<T> along_axis(false);
  const T t_out = m.outer.exit_distance(qv, qw, d.y, d.z, along_axis);
  T ov = qv + t_out * d.y, ow = qw + t_out * d.z;
  m.outer.snap(ov, ow);
  w.cortex = w.cortex + select(out, t_out, T(0.0));
  w.pv = select(out, ov, pv0);
  w.pw = select(out, ow, pw0);
  w.stuck = w.stuck | (out & along_axis);
  return w;
}

// The medulla's part of one cortex segment of the photon state s (sim/life/
// photon_life.h), for the lanes in `moved` that left the outer boundary
// point (s.px, s.py) along s.d: t (the segment's cortex length) and (pv, pw)
// (its end) are replaced where the chord met the medulla. Returns the lanes
// to truncate.
template <class T, class State>
MaskOf<T> cross_medulla(const MedullaConfig& m, State& s, const MaskOf<T>& moved, T& t, T& pv,
                        T& pw) {
  const MedullaWalk<T> w = walk_medulla(m, s.px, s.py, s.d, s.light, s.rng, moved);
  t = select(w.met, w.cortex, t);
  pv = select(w.met, w.pv, pv);
  pw = select(w.met, w.pw, pw);
  s.medulla_path = s.medulla_path + w.medulla;
  s.scatters = s.scatters + w.scatters;
  return w.stuck;
}

}  // namespace fiberlab::sim::life
