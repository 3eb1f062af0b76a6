#pragma once
// The microfacet distributions of `roughness: {model: beckmann | ggx}`
// (sim/roughness/microfacet_distribution.h states them and their sources)
// written once for the number types of the photon life (sim/simd/lanes.h: one
// photon as a double, or a vector of photons): the frame about a mean normal,
// Smith's Lambda, and exact sampling of the distribution of visible normals.
// Branches that depend on the photon are masks; neither sampler rejects.
//
// - GGX: Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
//   (JCGT 7(4)), section 4. Its angle 2 pi u2 goes through sincos_turn
//   (sim/simd/life_trig.h), one operation sequence for one photon and for a
//   vector, so both compute the same numbers (up to the compiler fusing a
//   product into a sum in one form and not the other).
// - Beckmann: Heitz and d'Eon 2014 (EGSR), section 4: the marginal CDF of the
//   stretched visible slope x inverted by safeguarded Newton iteration to
//   rounding (exact, not a fit), y | x ~ Normal(0, 1/2) by the inverse error
//   function. Each lane iterates until its own step is below rounding; the
//   vector form uses xsimd's erfc and exp (the scalar form the C library's),
//   which may differ in the last bit: a photon's Beckmann normal from the
//   batched tracer may differ from the scalar one's there. The inverse error
//   function (Boost's; xsimd has none) runs lane by lane, the same bits.
#include <boost/math/special_functions/erf.hpp>

#include <algorithm>
#include <cmath>

#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"
#include "sim/simd/life_trig.h"

namespace fiberlab::sim {

enum class MicrofacetModel { Beckmann, GGX };

}  // namespace fiberlab::sim

namespace fiberlab::sim::life {

namespace microfacet_detail {

inline constexpr double kSqrtPi = 1.7724538509055160273;

inline double exp_of(double x) { return std::exp(x); }
// f applied to each lane (a function with no vector form).
template <class F>
double per_lane(double x, F f) {
  return f(x);
}
template <class F>
Batch per_lane(const Batch& x, F f) {
  alignas(64) double v[kBatchWidth];
  x.store_aligned(v);
  for (double& e : v) e = f(e);
  return Batch::load_aligned(v);
}
// xsimd's exp (and its erf, erfc, which call it) converts a reduced argument
// to integers; without a vector conversion (AVX-512 DQ) it does so lane by
// lane in C++, undefined behaviour for the infinite or NaN arguments that
// masked-out lanes and grazing directions give. There the lanes are
// computed one by one with the C library instead (the same functions the
// scalar tracer uses).
template <class F, class G>
Batch lane_function(const Batch& x, F&& vector_form, G&& scalar_form) {
#if defined(__AVX512DQ__)
  (void)scalar_form;
  return vector_form(x);
#else
  (void)vector_form;
  return per_lane(x, scalar_form);
#endif
}
inline Batch exp_of(const Batch& x) {
  return lane_function(x, [](const Batch& y) { return xsimd::exp(y); }, [](double y) { return std::exp(y); });
}
template <class V>
Pair<V> exp_of(const Pair<V>& x) {
  return {exp_of(x.a), exp_of(x.b)};
}
inline double erf_of(double x) { return std::erf(x); }
inline Batch erf_of(const Batch& x) {
  return lane_function(x, [](const Batch& y) { return xsimd::erf(y); }, [](double y) { return std::erf(y); });
}
template <class V>
Pair<V> erf_of(const Pair<V>& x) {
  return {erf_of(x.a), erf_of(x.b)};
}
inline double erfc_of(double x) { return std::erfc(x); }
inline Batch erfc_of(const Batch& x) {
  return lane_function(x, [](const Batch& y) { return xsimd::erfc(y); }, [](double y) { return std::erfc(y); });
}
template <class V>
Pair<V> erfc_of(const Pair<V>& x) {
  return {erfc_of(x.a), erfc_of(x.b)};
}

template <class V, class F>
Pair<V> per_lane(const Pair<V>& x, F f) {
  return {per_lane(x.a, f), per_lane(x.b, f)};
}

}  // namespace microfacet_detail

// Orthonormal frame about a mean normal n: t along the fiber axis u = x
// projected onto n's tangent plane (longitudinal), b = n x t (azimuthal).
template <class T>
struct MicrofacetFrameOf {
  Vec3Of<T> t, b, n;

  // n unit.
  static MicrofacetFrameOf about(const Vec3Of<T>& n) {
    // u - (u.n) n; with n along u (|n.x| = 1, not a fiber's normal for any
    // tilt the settings allow) any tangent will do: y - (y.n) n.
    const Vec3Of<T> along_u(T(1.0) - n.x * n.x, -(n.x * n.y), -(n.x * n.z));
    const Vec3Of<T> along_y(-(n.y * n.x), T(1.0) - n.y * n.y, -(n.y * n.z));
    const MaskOf<T> degenerate = along_u.dot(along_u) < T(1e-24);
    const Vec3Of<T> t = select(degenerate, along_y, along_u).normalized();
    return {t, n.cross(t), n};
  }
  Vec3Of<T> to_local(const Vec3Of<T>& v) const { return {v.dot(t), v.dot(b), v.dot(n)}; }
  Vec3Of<T> to_world(const Vec3Of<T>& v) const { return v.x * t + v.y * b + v.z * n; }
};

// Smith's Lambda(w) in the local frame (Heitz 2014, "Understanding the
// Masking-Shadowing Function", sections 5.1-5.3), with a = w_z / sqrt(ax^2
// w_x^2 + ay^2 w_y^2); 0 for w along the normal (nothing masks it).
template <class T>
T microfacet_lambda(MicrofacetModel model, const Vec3Of<T>& w, double ax, double ay) {
  using namespace microfacet_detail;
  const T s = sqrt(T(ax * ax) * w.x * w.x + T(ay * ay) * w.y * w.y);
  const T a = w.z / s;  // 1 / (alpha tan theta) in the stretched configuration
  T lambda;
  if (model == MicrofacetModel::GGX) {
    lambda = T(0.5) * (T(-1.0) + sqrt(T(1.0) + T(1.0) / (a * a)));
  } else {
    lambda = T(0.5) * (erf_of(a) - T(1.0)) + exp_of(-a * a) / (T(2.0) * a * T(kSqrtPi));
  }
  return select(s == T(0.0), T(0.0), lambda);
}

// G1(w) = 1 / (1 + Lambda(w)) for w_z > 0, 0 otherwise (the wrong side).
template <class T>
T microfacet_g1(MicrofacetModel model, const Vec3Of<T>& w, double ax, double ay) {
  return select(w.z > T(0.0), T(1.0) / (T(1.0) + microfacet_lambda(model, w, ax, ay)), T(0.0));
}

// GGX: the normal m (local frame) that (u1, u2) in [0, 1)^2 maps to, w_z > 0
// (Heitz 2018, section 4): w stretched to the alpha = 1 hemisphere, a uniform
// point of the unit disk with its second coordinate squeezed onto the part
// of the projected hemisphere visible from w, lifted and unstretched.
template <class T>
Vec3Of<T> ggx_visible_normal(const Vec3Of<T>& w, double ax, double ay, const T& u1, const T& u2) {
  const Vec3Of<T> vh = Vec3Of<T>(T(ax) * w.x, T(ay) * w.y, w.z).normalized();
  const T len2 = vh.x * vh.x + vh.y * vh.y;
  const T inv_len = T(1.0) / sqrt(len2);
  const Vec3Of<T> t1 = select(len2 > T(0.0), Vec3Of<T>(-vh.y * inv_len, vh.x * inv_len, T(0.0)),
                              Vec3Of<T>(T(1.0), T(0.0), T(0.0)));
  const Vec3Of<T> t2 = vh.cross(t1);
  const T r = sqrt(u1);
  const auto [sin_phi, cos_phi] = sincos_turn(u2);
  const T p1 = r * cos_phi;
  const T s = T(0.5) * (T(1.0) + vh.z);
  const T p2 = (T(1.0) - s) * sqrt(max(T(0.0), T(1.0) - p1 * p1)) + s * (r * sin_phi);
  const Vec3Of<T> nh =
      p1 * t1 + p2 * t2 + sqrt(max(T(0.0), T(1.0) - p1 * p1 - p2 * p2)) * vh;
  // Normals transform with the inverse transpose of the stretch.
  return Vec3Of<T>(T(ax) * nh.x, T(ay) * nh.y, max(T(0.0), nh.z)).normalized();
}

// Beckmann, alpha = 1, incidence theta in the x-z plane (cos_theta in [0,
// 1]): the visible slopes (x, y) from (u1, u2), in the lanes of `live`
// (Heitz and d'Eon 2014, section 4). x inverts the marginal CDF
//   C(x) = cos(theta) (1 + erf x) / 2 + sin(theta) exp(-x^2) / (2 sqrt pi), x <= cot(theta),
// whose derivative is the density (cos theta - x sin theta) exp(-x^2) / sqrt(pi).
template <class T>
void beckmann_visible_slopes(const T& cos_theta, const T& u1, const T& u2, const MaskOf<T>& live,
                             T& x, T& y) {
  using namespace microfacet_detail;
  const T c = min(T(1.0), max(T(0.0), cos_theta));
  const T s = sqrt(max(T(0.0), T(1.0) - c * c));
  auto cdf = [&](const T& t, const T& e) { return T(0.5) * c * erfc_of(-t) + s * e / T(2.0 * kSqrtPi); };
  // Bracket: [-9, min(cot theta, 9)]; erfc(9) ~ 4e-37 and exp(-81) ~ 7e-36 lie
  // below any target u1 C(hi) >= 2^-53 * 0.28 except u1 = 0 (then x = -9).
  T lo(-9.0);
  T hi = select(s > T(0.0), min(c / s, T(9.0)), T(9.0));
  const T target = u1 * cdf(hi, exp_of(-hi * hi));
  T t(0.0);
  t = select((t <= lo) | (t >= hi), T(0.5) * (lo + hi), t);
  MaskOf<T> pending = live;
  for (int it = 0; it < 200 && any(pending); ++it) {
    const T e = exp_of(-t * t);
    const T g = cdf(t, e) - target;
    const MaskOf<T> above = g > T(0.0);
    hi = select(pending & above, t, hi);
    lo = select(pending & !above, t, lo);
    const T d = (c - t * s) * e / T(kSqrtPi);
    const T mid = T(0.5) * (lo + hi);
    T tn = select(d > T(0.0), t - g / d, mid);
    tn = select((tn > lo) & (tn < hi), tn, mid);
    const MaskOf<T> done =
        (abs(tn - t) <= T(1e-15) * (T(1.0) + abs(t))) | (hi - lo <= T(1e-15));
    t = select(pending, tn, t);
    pending = pending & !done;
  }
  x = t;
  // y | x ~ Normal(0, 1/2): the projected area depends on x only.
  const T v = min(T(1.0 - 1e-16), max(T(-1.0 + 1e-16), T(2.0) * u2 - T(1.0)));
  y = per_lane(v, [](double z) { return boost::math::erf_inv(z); });
}

// Beckmann: the normal m (local frame) that (u1, u2) maps to, w_z > 0, in
// the lanes of `live`: w stretched to alpha = 1 and turned into the x-z
// plane, slopes sampled, turned back and unstretched; a facet with slopes
// (x, y) has normal (-x, -y, 1) normalised.
template <class T>
Vec3Of<T> beckmann_visible_normal(const Vec3Of<T>& w, double ax, double ay, const T& u1,
                                  const T& u2, const MaskOf<T>& live) {
  const Vec3Of<T> ws = Vec3Of<T>(T(ax) * w.x, T(ay) * w.y, w.z).normalized();
  const T rxy = sqrt(ws.x * ws.x + ws.y * ws.y);
  const MaskOf<T> slanted = rxy > T(0.0);
  const T cphi = select(slanted, ws.x / rxy, T(1.0)), sphi = select(slanted, ws.y / rxy, T(0.0));
  T sx, sy;
  beckmann_visible_slopes(ws.z, u1, u2, live, sx, sy);
  const T x = (cphi * sx - sphi * sy) * T(ax);
  const T y = (sphi * sx + cphi * sy) * T(ay);
  return Vec3Of<T>(-x, -y, T(1.0)).normalized();
}

// The visible normal of either model (local frame), w_z > 0 in `live`.
template <class T>
Vec3Of<T> microfacet_visible_normal(MicrofacetModel model, const Vec3Of<T>& w, double ax,
                                    double ay, const T& u1, const T& u2, const MaskOf<T>& live) {
  if (model == MicrofacetModel::GGX) return ggx_visible_normal(w, ax, ay, u1, u2);
  return beckmann_visible_normal(w, ax, ay, u1, u2, live);
}

}  // namespace fiberlab::sim::life
