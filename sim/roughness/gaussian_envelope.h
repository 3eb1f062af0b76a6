#pragma once
// The proposal of the gaussian roughness sampler (sim/roughness/roughness_gaussian.h).
//
// The sampler draws the standard normal offsets x = (dl / beta_long,
// da / beta_azim) of SPEC section 3 from the target phi(x) max(0, v.m),
// v = -d the reversed photon direction and m(x) the rotated normal. It
// proposes x from phi(x) env(x), with env >= max(0, v.m) for every x, and
// accepts with probability max(0, v.m) / env: exact, the tails included.
// In polar form x = rho (cos psi, sin psi), w = rho^2 / 2 = w0 + E
// (d^2x = dw dpsi, phi = e^-w / 2 pi), every envelope here is
//
//   env = a_flat + a_lobe c+ + (b_lobe c+ + b_flat) E,  c+ = max(0, cos(psi - psi_h)),
//
// so phi env is a mixture of four parts, each drawn directly: E from Exp(1)
// (the a terms) or Gamma(2, 1) (the b terms), psi uniform (the flat terms)
// or with density cos(psi - psi_h) / 2 on the half plane around psi_h (the
// lobe terms, whose mass is 1/pi of a flat term's).
//
// Notation: u the fiber axis, p the untilted facing normal, q = u x p;
// n_f = sin(t_n) u + cos(t_n) p and m = sin(t) u + cos(t) (cos(da) p +
// sin(da) q) with t = t_n + dl (SPEC section 3); c0 = v.n_f; b the larger
// beta. Two bounds of v.m give two envelopes; each lane takes the one with
// the smaller mass (the lobe envelope only where the radial one starts at
// w0 = 0), and the plain proposal (env = 1: x from phi) when that mass is at
// least 1.
//
// The lobe envelope. In the orthonormal frame (n_f, e_l = cos(t_n) u -
// sin(t_n) p, q) write v = c0 n_f + g_l e_l + g_a q, s0 = sqrt(g_l^2 +
// g_a^2). By the angle-sum identities, exactly,
//   v.m = c0 n_f.m + g_l (dl + R_l) + g_a (cos(t_n) da + R_a),
//   R_l = sin(dl) - dl + sin(t_n) cos(t) (1 - cos(da)),
//   R_a = cos(t) sin(da) - cos(t_n) da.
// With r^2 = dl^2 + da^2: n_f.m = cos(delta) for the angle delta <= r (the
// path below) between n_f and m, so c0 n_f.m <= c0+ + c0- r^2 / 2 (c0+ =
// max(0, c0), c0- = max(0, -c0); n_f.m <= 1, 1 - cos(delta) <= r^2 / 2).
// And v.m <= c0+ + c0- r^2 / 2 + h.x + s0 (|R_l| + |R_a|) with h = (g_l
// beta_long, g_a cos(t_n) beta_azim). By |sin z - z| <= |z|^3 / 6, 1 - cos z
// <= z^2 / 2 and |cos t - cos t_n| <= (1 - cos dl) + |sin t_n| |dl|:
//   |R_l| + |R_a| <= |dl|^3/6 + |da|^3/6 + |da| dl^2/2 + |sin t_n| (da^2/2 + |da dl|)
//                 <= 0.36 r^3 + 0.81 |sin t_n| r^2
// (the cubic's angular factor is at most 1/6 + 1/(3 sqrt 3) < 0.36, the
// quadratic's (1 + sqrt 5) / 4 < 0.81). For r <= r1 = 1/sqrt(0.51) that is
// at most K r^2, K = 0.51 + 0.81 |sin t_n| (0.36 r1 < 0.51); for r > r1,
// K r^2 > 1 >= the unit vector (g_l e_l + g_a q) / s0 dotted with m, so
//   v.m <= c0+ + (h.x)+ + (s0 K + c0- / 2) r^2
//       <= c0+ + |h| rho c+ + (s0 K + c0- / 2) b^2 rho^2
// for every x, psi_h the direction of h. With rho <= k/2 + w/k (k = sqrt 2,
// the k that minimises the mass):
//   a_flat = c0+, a_lobe = |h| k/2, b_lobe = |h| / k,
//   b_flat = (2 s K + c0-) b^2, w0 = 0,
// with s = 1 - c0^2 / 2 >= s0 = sqrt(1 - c0^2) (|v| = 1; saves a root).
// It follows the first-order change of v.m, which only h's direction
// raises: at grazing incidence (c0 -> 0) with beta 5 deg about 0.7 of its
// candidates are accepted, against 0.3 for the radial envelope.
//
// The radial envelope (the one for n_f facing away by more than about b /
// sqrt 2, where every visible normal is in the tail).
// m is n_f moved by an angle delta along the sphere, and the straight path
// in (inclination, azimuth about u) has length integral sqrt(dl^2 + cos^2(t)
// da^2) <= r <= b rho. With c0 = cos(gamma), gamma the angle between v and
// n_f, v.m <= cos(max(0, gamma - delta)), so
//   v.m <= c + delta <= c + b rho,
// where c = c0 when c0 >= 0 (the cosine is 1-Lipschitz) and c = -eps =
// asin(c0) when n_f faces away by eps (gamma = pi/2 + eps: v.m <=
// sin(delta - eps) <= delta - eps). asin(c0) <= c0 there, so c = c0 is a
// valid, looser choice: it is taken while eps <= b / sqrt 2 (asin's cost
// buys nothing there: the envelope starts at w0 = 0 either way, and the
// lobe envelope is usually chosen), asin(c0) beyond, in the tail.
// With sqrt(2w) <= k/2 + w/k (any k > 0; equality at rho = k):
//   v.m <= A + B w,   A = c + b k / 2,   B = b / k,
// positive from w0 = max(0, -A / B) on: a_flat = A0 = A + B w0, b_flat = B,
// no lobe terms. k: the mass is e^-w0 (A0 + B); k = sqrt 2 minimises it when
// w0 = 0, k = (rho0 + sqrt(rho0^2 + 4)) / 2 when n_f faces away from the
// photon by rho0 = -c / b > 1/sqrt 2 (then every visible normal is in the
// tail).
//
// tests/sim/test_gaussian_envelope.cpp checks env >= v.m over random
// frames, betas and offsets; tests/sim/test_gaussian_normal.cpp checks the
// sampled normals against the definition. Any choice between valid
// envelopes is exact; the choices only change the candidates' count.
#include <algorithm>
#include <cmath>

#include "sim/simd/lanes.h"
#include "sim/roughness/roughness_model.h"

namespace fiberlab::sim::life {

inline constexpr double kSqrt2 = 1.4142135623730951;

template <class T>
struct GaussianEnvelope {
  T a_flat, a_lobe, b_lobe, b_flat;  // env = a_flat + a_lobe c+ + (b_lobe c+ + b_flat) E
  T w0;                              // w = rho^2 / 2 = w0 + E
  T h_cos, h_sin;                    // (cos psi_h, sin psi_h)

  static constexpr double kInvPi = 0.3183098861837907;
  // The four parts' masses in the order the sampler picks them (a flat, a
  // lobe, b lobe, b flat), and their sum: the proposal's mass is e^-w0 times it.
  T a_end() const { return a_flat + a_lobe * T(kInvPi); }
  T lobe_end() const { return a_end() + b_lobe * T(kInvPi); }
  T mass() const { return lobe_end() + b_flat; }
  // env at w = w0 + e, c_plus = max(0, cos(psi - psi_h)).
  T at(const T& e, const T& c_plus) const {
    return a_flat + a_lobe * c_plus + (b_lobe * c_plus + b_flat) * e;
  }
};

// The roughness widths (radians) and what the envelopes derive from them,
// computed once per model.
struct EnvelopeWidths {
  EnvelopeWidths(double beta_long_, double beta_azim_)
      : beta_long(beta_long_),
        beta_azim(beta_azim_),
        b(std::max(beta_long_, beta_azim_)),
        // No c0 >= -1 faces away by more than pi/2: no tail for b / sqrt 2 >= pi/2.
        tail_c0(b / kSqrt2 >= 1.5707963267948966 ? -1.0 : -std::sin(b / kSqrt2)) {}
  double beta_long, beta_azim;
  double b;        // the larger beta
  double tail_c0;  // c0 below which n_f faces away by more than b / sqrt 2
};

template <class T>
struct RadialEnvelope {
  T a, slope, w0;  // env = a + slope E on w = w0 + E
};

// The radial envelope (the comment above).
template <class T>
[[gnu::always_inline]] inline RadialEnvelope<T> radial_envelope(const T& c0,
                                                                const EnvelopeWidths& widths) {
  const double b = widths.b;
  const T zero(0.0);
  // In the tail: eps > b / sqrt 2, where rho0 below exceeds 1 / sqrt 2.
  const MaskOf<T> deep = c0 < T(widths.tail_c0);
  // No lane in the tail: k = sqrt 2 and w0 = 0 (the same operations as below).
  if (!any(deep)) return {c0 + T(0.5 * b) * T(kSqrt2), T(b) * T(1.0 / kSqrt2), zero};
  const T c = select(deep, asin(max(T(-1.0), c0)), c0);
  const T rho0 = max(zero, -c) * T(1.0 / b);
  const MaskOf<T> tail = rho0 > T(1.0 / kSqrt2);
  const T k = select(tail, T(0.5) * (rho0 + sqrt(rho0 * rho0 + T(4.0))), T(kSqrt2));
  const T inv_k = select(tail, k - rho0, T(1.0 / kSqrt2));  // k^2 - rho0 k - 1 = 0
  const T a = c + T(0.5 * b) * k;
  const T w0 = max(zero, -a * k * T(1.0 / b));
  return {max(zero, a), T(b) * inv_k, w0};
}

// The lobe envelope (the comment above).
template <class T>
[[gnu::always_inline]] inline GaussianEnvelope<T> lobe_envelope(const Vec3Of<T>& v,
                                                                const BoundaryFrame<T>& frame,
                                                                const T& c0,
                                                                const EnvelopeWidths& widths) {
  const double beta_long = widths.beta_long, beta_azim = widths.beta_azim, b = widths.b;
  const T zero(0.0), one(1.0);
  // v's parts along e_l and q, and h.
  const Vec3Of<T>& p = frame.untilted_facing;  // (0, p.y, p.z)
  const T v_p = v.y * p.y + v.z * p.z;
  const T g_l = frame.cos_n * v.x - frame.sin_n * v_p;
  const T g_a = v.z * p.y - v.y * p.z;  // v.q, q = u x p = (0, -p.z, p.y)
  const T h1 = g_l * T(beta_long), h2 = g_a * frame.cos_n * T(beta_azim);
  const T h = sqrt(h1 * h1 + h2 * h2);
  const T s = one - T(0.5) * c0 * c0;
  const T quad = T(0.51) + T(0.81) * abs(frame.sin_n);  // K
  const MaskOf<T> has_h = h > zero;
  const T inv_h = one / select(has_h, h, one);
  return {max(zero, c0),
          h * T(0.5 * kSqrt2),
          h * T(1.0 / kSqrt2),
          T(b * b) * (T(2.0) * s * quad + max(zero, -c0)),
          zero,
          select(has_h, h1 * inv_h, one),
          select(has_h, h2 * inv_h, zero)};
}

// The envelope for a photon with reversed direction v at a boundary point
// with frame `frame` (the comment above), for the roughness widths `widths`.
template <class T>
[[gnu::always_inline]] inline GaussianEnvelope<T> gaussian_envelope(const Vec3Of<T>& v,
                                                                    const BoundaryFrame<T>& frame,
                                                                    const EnvelopeWidths& widths) {
  const T zero(0.0), one(1.0);
  const T c0 = v.dot(frame.facing);
  const RadialEnvelope<T> radial = radial_envelope(c0, widths);
  GaussianEnvelope<T> env = lobe_envelope(v, frame, c0, widths);
  // Where the radial envelope starts at w0 = 0 the masses compare directly.
  const MaskOf<T> use_radial = (radial.w0 > zero) | (radial.a + radial.slope <= env.mass());
  env.a_flat = select(use_radial, radial.a, env.a_flat);
  env.a_lobe = select(use_radial, zero, env.a_lobe);
  env.b_lobe = select(use_radial, zero, env.b_lobe);
  env.b_flat = select(use_radial, radial.slope, env.b_flat);
  env.w0 = select(use_radial, radial.w0, zero);
  // The plain proposal when the envelope's mass is 1 or more.
  const MaskOf<T> plain = (env.w0 == zero) & (env.mass() >= one);
  env.a_flat = select(plain, one, env.a_flat);
  env.a_lobe = select(plain, zero, env.a_lobe);
  env.b_lobe = select(plain, zero, env.b_lobe);
  env.b_flat = select(plain, zero, env.b_flat);
  return env;
}

}  // namespace fiberlab::sim::life
