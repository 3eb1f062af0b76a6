#pragma once
// Dielectric Fresnel reflectance, shared by the simulator and the analytic
// models. Written once, generic over its number type: a scalar double, or a
// SIMD vector of doubles (xsimd::batch<double>) in the batched photon life.
// A number type T needs sqrt, select(mask, a, b) and comparisons, found for
// double here and for xsimd batches by argument-dependent lookup.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace fiberlab {

namespace fresnel_detail {
inline double select(bool m, double a, double b) { return m ? a : b; }
}  // namespace fresnel_detail

// Snell's law, the step every function below starts from: cos_i clamped to
// [0, 1], sin^2 t = sin^2 i / eta_rel^2 (given 1 / eta_rel^2, so callers
// that hold 1 / eta_rel need no division), total internal reflection where
// sin^2 t >= 1, and the real refraction cosine (0 under TIR).
template <class T>
struct SnellOf {
  T cos_i, sin2_t, cos_t;
  decltype(std::declval<T>() >= std::declval<T>()) tir;
};
template <class T>
SnellOf<T> snell_refraction(T cos_i, T inv_eta_rel2) {
  using std::max;
  using std::min;
  using std::sqrt;
  cos_i = min(T(1.0), max(T(0.0), cos_i));
  const T sin2_t = max(T(0.0), T(1.0) - cos_i * cos_i) * inv_eta_rel2;
  return {cos_i, sin2_t, sqrt(max(T(0.0), T(1.0) - sin2_t)), sin2_t >= T(1.0)};
}

// Fresnel s and p amplitude reflectances r_s and r_p (real, no TIR) with the
// sign convention of SPEC section 3: r_p = -r_s at normal incidence.
template <class T>
struct FresnelAmplitudesOf {
  T cos_t;  // cosine of the refraction angle; NaN under TIR
  T r_s, r_p;
  decltype(std::declval<T>() >= std::declval<T>()) tir;  // total internal reflection
};
using FresnelAmplitudes = FresnelAmplitudesOf<double>;

// cos_i = cosine of the angle between the ray and the normal (>= 0),
// eta_rel = n_t / n_i (the index on the far side over the index on the near
// side). Under total internal reflection r_s = r_p = 1 and cos_t is NaN.
// Textbook form, e.g. Born & Wolf section 1.5.2.
template <class T>
FresnelAmplitudesOf<T> fresnel_amplitudes(T cos_i, T eta_rel) {
  using fresnel_detail::select;
  const SnellOf<T> snell = snell_refraction(cos_i, T(1.0) / (eta_rel * eta_rel));
  const T cos_t = snell.cos_t;
  const auto tir = snell.tir;
  cos_i = snell.cos_i;
  const T r_s = (cos_i - eta_rel * cos_t) / (cos_i + eta_rel * cos_t);
  const T r_p = (eta_rel * cos_i - cos_t) / (eta_rel * cos_i + cos_t);
  return {select(tir, T(std::numeric_limits<double>::quiet_NaN()), cos_t),
          select(tir, T(1.0), r_s), select(tir, T(1.0), r_p), tir};
}

// Unpolarised reflectance F = (Rs + Rp) / 2 (1 under total internal
// reflection) and the refraction cosine, given also 1 / eta_rel: the form the
// photon life uses at every event, with one division. Rs + Rp = (N_s^2 D_p^2
// + N_p^2 D_s^2) / (D_s D_p)^2 with r = N / D as in fresnel_amplitudes.
template <class T>
struct FresnelReflectanceOf {
  T F;
  T cos_t;  // NaN under TIR
  decltype(std::declval<T>() >= std::declval<T>()) tir;
};
template <class T>
FresnelReflectanceOf<T> fresnel_reflectance(T cos_i, T eta_rel, T inv_eta_rel) {
  using fresnel_detail::select;
  const SnellOf<T> snell = snell_refraction(cos_i, inv_eta_rel * inv_eta_rel);
  const T cos_t = snell.cos_t;
  const auto tir = snell.tir;
  cos_i = snell.cos_i;
  const T ns = cos_i - eta_rel * cos_t, ds = cos_i + eta_rel * cos_t;
  const T np = eta_rel * cos_i - cos_t, dp = eta_rel * cos_i + cos_t;
  const T dsp = ds * dp;
  const T F = T(0.5) * (ns * ns * (dp * dp) + np * np * (ds * ds)) / (dsp * dsp);
  return {select(tir, T(1.0), F), select(tir, T(std::numeric_limits<double>::quiet_NaN()), cos_t),
          tir};
}

// Unpolarised reflectance F = (Rs + Rp) / 2; total internal reflection gives 1.
template <class T>
T fresnel_dielectric(T cos_i, T eta_rel) {
  const FresnelAmplitudesOf<T> a = fresnel_amplitudes(cos_i, eta_rel);
  return T(0.5) * (a.r_s * a.r_s + a.r_p * a.r_p);
}
inline double fresnel_dielectric(double cos_i, double eta_rel) {
  return fresnel_dielectric<double>(cos_i, eta_rel);
}
inline FresnelAmplitudes fresnel_amplitudes(double cos_i, double eta_rel) {
  return fresnel_amplitudes<double>(cos_i, eta_rel);
}

// The complex amplitudes, for polarised light (SPEC section 3): under total
// internal reflection cos t = +i sqrt(sin^2 i / eta_r^2 - 1) and
// r = N / D becomes a unit complex number. r = N conj(D) / |D|^2 with
// r_s: N = cos i - eta_r cos t, D = cos i + eta_r cos t;
// r_p: N = eta_r cos i - cos t, D = eta_r cos i + cos t.
template <class T>
struct FresnelComplexOf {
  T rs_re, rs_im, rp_re, rp_im;
  T cos_t;  // real refraction cosine; 0 under TIR
  decltype(std::declval<T>() >= std::declval<T>()) tir;  // total internal reflection
};

template <class T>
FresnelComplexOf<T> fresnel_complex_amplitudes(T cos_i, T eta_rel) {
  using fresnel_detail::select;
  using std::abs;
  using std::sqrt;
  const SnellOf<T> snell = snell_refraction(cos_i, T(1.0) / (eta_rel * eta_rel));
  const auto tir = snell.tir;
  cos_i = snell.cos_i;
  const T ct_re = select(tir, T(0.0), snell.cos_t);
  const T ct_im = select(tir, sqrt(abs(snell.sin2_t - T(1.0))), T(0.0));
  auto divide = [](T n_re, T n_im, T d_re, T d_im, T& re, T& im) {
    const T inv = T(1.0) / (d_re * d_re + d_im * d_im);
    re = (n_re * d_re + n_im * d_im) * inv;
    im = (n_im * d_re - n_re * d_im) * inv;
  };
  FresnelComplexOf<T> r;
  divide(cos_i - eta_rel * ct_re, -eta_rel * ct_im, cos_i + eta_rel * ct_re, eta_rel * ct_im,
         r.rs_re, r.rs_im);
  divide(eta_rel * cos_i - ct_re, -ct_im, eta_rel * cos_i + ct_re, ct_im, r.rp_re, r.rp_im);
  r.cos_t = ct_re;
  r.tir = tir;
  return r;
}

}  // namespace fiberlab
