#pragma once
// Roughness model `gaussian` (SPEC section 3): n_f rotated by dl ~ N(0,
// beta_long^2) towards +u in the plane of n_f and u, then by da ~ N(0,
// beta_azim^2) about u, the candidate kept with probability max(0, -d.m)
// (visible normals). beta_long = beta_azim = 0 is the `smooth` model, which
// the tracers use instead (make_roughness in sim/roughness_models.h).
//
// The sampler: one exact rejection sampler for every incidence, with the same
// work for every candidate (a fixed block of five uniforms, one log, one
// square root, three sine-cosine pairs, sim/life_trig.h), so that a SIMD vector of photons never waits
// on a branch only some of its lanes take.
//
// The target density of the offsets is G(x) max(0, -d.m) with x = (dl /
// beta_long, da / beta_azim) standard normal in the plane (density phi(x)).
// A bound on -d.m: m is n_f moved by an angle delta along the sphere, and
// the straight path in (inclination, azimuth about u) has length
// integral sqrt(dl^2 + cos^2(t) da^2) <= sqrt(dl^2 + da^2) <= b rho, with
// rho = |x| and b = max(beta_long, beta_azim). With c0 = -d.n_f = cos(gamma),
// gamma the angle between -d and n_f, -d.m <= cos(max(0, gamma - delta)), so
//   -d.m <= c + delta <= c + b rho,
// where c = c0 when c0 >= 0 (the cosine is 1-Lipschitz) and c = -eps =
// asin(c0) when n_f faces away by eps (gamma = pi/2 + eps: -d.m <=
// sin(delta - eps) <= delta - eps; the tighter bound matters in the tail).
// With w = rho^2 / 2 (d^2x = dw dpsi, psi the direction of x, uniform) and
// sqrt(2w) <= k/2 + w/k (any k > 0; equality at rho = k):
//   -d.m <= A + B w,   A = c + b k / 2,   B = b / k.
// So propose x with density ~ phi(x) (A + B w)+ and accept with probability
// max(0, -d.m) / (A + B w): exact, the tail included. In w the proposal is
// e^-w (A + B w) on w >= w0 = max(0, -A / B): w = w0 + E, where E has
// density ~ e^-E (A0 + B E), A0 = A + B w0 >= 0, a mixture of Exp(1)
// (weight A0) and Gamma(2, 1) (weight B): E = -log(u1) or -log(u1 u2).
// k: the envelope's mass is e^-w0 (A0 + B); k = sqrt 2 minimises it when
// w0 = 0, k = (rho0 + sqrt(rho0^2 + 4)) / 2 when n_f faces away from the
// photon by rho0 = -c / b > 1/sqrt 2 (then every visible normal is in the
// tail). When the envelope's mass is >= 1 the plain proposal (A, B) = (1, 0)
// (x from phi, accept with probability -d.m) is used instead.
#include <optional>

#include "sim/life_trig.h"
#include "sim/roughness_model.h"
#include "sim/settings.h"

namespace fiberlab::sim::life {

class GaussianRoughness {
 public:
  GaussianRoughness(double beta_long, double beta_azim)
      : beta_long_(beta_long), beta_azim_(beta_azim), b_(std::max(beta_long, beta_azim)) {}
  explicit GaussianRoughness(const Settings& s)
      : GaussianRoughness(s.roughness.beta_long.front(), s.roughness.beta_azim.front()) {}

  template <class T>
  FacetDraw<T> draw_normal(const Vec3Of<T>& d, const BoundaryFrame<T>& frame,
                           const MaskOf<T>& live, LaneRandom<T>& rng, T& tries,
                           LifeCounts<T>& counts, int rounds) const {
    // n_f = sin(theta_n) u + cos(theta_n) (0, pv, pw).
    const T sin_n = frame.sin_n, cos_n = frame.cos_n;
    const T pv = frame.untilted_facing.y, pw = frame.untilted_facing.z;
    const Envelope<T> env = envelope(-d.dot(frame.facing));
    FacetDraw<T> out{Vec3Of<T>(T(0.0), T(0.0), T(0.0)), MaskOf<T>(false), MaskOf<T>(false)};
    MaskOf<T> pending = live;
    for (int k = 0; k < rounds && any(pending); ++k) {
      counts.normal_draws = counts.normal_draws + ones<T>(pending);
      tries = tries + ones<T>(pending);
      const auto [u_pick, u1_closed, u2_closed, u_psi, u_accept] = rng.template uniforms<5>(pending);
      const T u1 = LaneRandom<T>::open0(u1_closed), u2 = LaneRandom<T>::open0(u2_closed);
      const MaskOf<T> gamma2 = u_pick * (env.a0 + env.b) < env.b;
      const T e = -log(u1 * select(gamma2, u2, T(1.0)));
      const T rho = sqrt(T(2.0) * (env.w0 + e));
      const auto [sp, cp] = sincos_turn(u_psi);
      const Vec3Of<T> m =
          rotated_normal(sin_n, cos_n, pv, pw, T(beta_long_) * rho * cp, T(beta_azim_) * rho * sp);
      const T visible = -d.dot(m);
      const MaskOf<T> accepted =
          pending & (visible > T(0.0)) & (u_accept * (env.a0 + env.b * e) < visible);
      out.m = select(accepted, m, out.m);
      out.ready = out.ready | accepted;
      pending = pending & !accepted;
      out.failed = out.failed | (pending & (tries >= T(kMaxNormalTries)));
      pending = pending & !out.failed;
    }
    counts.sampler_caps = counts.sampler_caps + ones<T>(out.failed);
    tries = select(out.ready | out.failed, T(0.0), tries);
    return out;
  }

 private:
  // The proposal e^-E (a0 + b E) on w = w0 + E of the comment above.
  template <class T>
  struct Envelope {
    T a0, b, w0;
  };
  template <class T>
  Envelope<T> envelope(const T& c0) const {
    constexpr double kSqrt2 = 1.4142135623730951;
    const MaskOf<T> away = c0 < T(0.0);
    const T c = any(away) ? select(away, asin(max(T(-1.0), c0)), c0) : c0;
    const T rho0 = max(T(0.0), -c) * T(1.0 / b_);
    const MaskOf<T> tail = rho0 > T(1.0 / kSqrt2);
    const T k = select(tail, T(0.5) * (rho0 + sqrt(rho0 * rho0 + T(4.0))), T(kSqrt2));
    const T inv_k = select(tail, k - rho0, T(1.0 / kSqrt2));  // k^2 - rho0 k - 1 = 0
    const T a = c + T(0.5 * b_) * k, b = T(b_) * inv_k;
    const T w0 = max(T(0.0), -a * k * T(1.0 / b_));
    const T a0 = max(T(0.0), a);
    const MaskOf<T> plain = (w0 == T(0.0)) & (a0 + b >= T(1.0));
    return {select(plain, T(1.0), a0), select(plain, T(0.0), b), w0};
  }

  // m for a longitudinal offset dl and an azimuthal offset da (SPEC section
  // 3): n_f tilted to inclination theta_n + dl in its plane with u (sin and
  // cos by the angle-sum rule), then turned by da about u.
  template <class T>
  static Vec3Of<T> rotated_normal(const T& sin_n, const T& cos_n, const T& pv, const T& pw,
                                  const T& dl, const T& da) {
    const auto [sl, cl] = sincos_small(dl);
    const auto [sa, ca] = sincos_small(da);
    const T st = sin_n * cl + cos_n * sl, ct = cos_n * cl - sin_n * sl;
    return {st, ct * (pv * ca - pw * sa), ct * (pv * sa + pw * ca)};
  }

  double beta_long_, beta_azim_, b_;
};

}  // namespace fiberlab::sim::life

namespace fiberlab::sim {

// One gaussian normal for a photon along d at a point with tilted facing
// normal n_facing, at most max_tries candidates (counted in `tries`);
// nothing when all were rejected. The scalar form of
// GaussianRoughness::draw_normal, for tests.
inline std::optional<Vec3> gaussian_normal(const Vec3& d, const Vec3& n_facing, double beta_long,
                                           double beta_azim, PhotonRandom& rng, int max_tries,
                                           long& tries) {
  const life::GaussianRoughness model(beta_long, beta_azim);
  life::LifeCounts<double> counts;
  double pending_tries = 0.0;
  const life::FacetDraw<double> f = model.draw_normal(
      life::Vec3Of<double>(d), life::BoundaryFrame<double>::from_facing(life::Vec3Of<double>(n_facing)),
      true, rng.core(), pending_tries, counts, max_tries);
  tries += static_cast<long>(counts.normal_draws);
  if (!f.ready) return std::nullopt;
  return f.m.to_vec3();
}

}  // namespace fiberlab::sim
