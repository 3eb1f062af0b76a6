#pragma once
// Roughness model `gaussian` (SPEC section 3): n_f rotated by dl ~ N(0,
// beta_long^2) towards +u in the plane of n_f and u, then by da ~ N(0,
// beta_azim^2) about u, the candidate kept with probability max(0, -d.m)
// (visible normals). beta_long = beta_azim = 0 is the `smooth` model, which
// the tracers use instead (make_roughness in sim/roughness/roughness_models.h).
//
// The sampler: one exact rejection sampler for every incidence, with the same
// work for every candidate (a fixed block of five uniforms, one log
// (sim/simd/life_log.h), two square roots, three sine-cosine pairs
// (sim/simd/life_trig.h)), so that a SIMD vector of photons never waits on a
// branch only some of its lanes take. Its
// proposal, and the proof that it bounds the target, is in
// sim/roughness/gaussian_envelope.h.
#include <optional>

#include "sim/roughness/gaussian_envelope.h"
#include "sim/simd/life_log.h"
#include "sim/simd/life_trig.h"
#include "sim/roughness/roughness_model.h"
#include "sim/run/settings.h"

namespace fiberlab::sim::life {

class GaussianRoughness {
 public:
  GaussianRoughness(double beta_long, double beta_azim)
      : widths_(beta_long, beta_azim) {}

  // Always inline: GCC 12 leaves it out of line, passing the photon state,
  // the frame and the stream through memory.
  template <class T>
  [[gnu::always_inline]] FacetDraw<T> draw_normal(const Vec3Of<T>& d,
                                                  const BoundaryFrame<T>& frame,
                                                  const MaskOf<T>& live, LaneRandom<T>& rng,
                                                  T& tries, LifeCounts<T>& counts,
                                                  int rounds) const {
    // n_f = sin(theta_n) u + cos(theta_n) (0, pv, pw).
    const T sin_n = frame.sin_n, cos_n = frame.cos_n;
    const T pv = frame.untilted_facing.y, pw = frame.untilted_facing.z;
    const GaussianEnvelope<T> env = gaussian_envelope(-d, frame, widths_);
    const T a_end = env.a_end(), lobe_end = env.lobe_end(), mass = env.mass();
    FacetDraw<T> out{Vec3Of<T>(T(0.0), T(0.0), T(0.0)), MaskOf<T>(false), MaskOf<T>(false)};
    MaskOf<T> pending = live;
    // Slow: the tail's envelope (n_f facing away), about 0.1 of candidates accepted.
    const MaskOf<T> slow = env.w0 > T(0.0);
    for (int k = 0; k < rounds && any(pending) && (k == 0 || another_round(pending, slow)); ++k) {
      counts.normal_draws = counts.normal_draws + ones<T>(pending);
      tries = tries + ones<T>(pending);
      const auto [u_pick, u1_closed, u2_closed, u_psi, u_accept] = rng.template uniforms<5>(pending);
      const T u1 = LaneRandom<T>::open0(u1_closed), u2 = LaneRandom<T>::open0(u2_closed);
      // The part: a flat, a lobe, b lobe, b flat (sim/roughness/gaussian_envelope.h).
      const T pick = u_pick * mass;
      const MaskOf<T> gamma2 = pick >= a_end;
      const MaskOf<T> lobe = (pick >= env.a_flat) & (pick < lobe_end);
      const T e = -log_normal(u1 * select(gamma2, u2, T(1.0)));
      const T rho = sqrt(T(2.0) * (env.w0 + e));
      const Direction<T> dir = direction(env, lobe, u_psi);
      const Vec3Of<T> m = rotated_normal(sin_n, cos_n, pv, pw, T(widths_.beta_long) * rho * dir.cos,
                                         T(widths_.beta_azim) * rho * dir.sin);
      const T visible = -d.dot(m);
      const MaskOf<T> accepted =
          pending & (visible > T(0.0)) & (u_accept * env.at(e, dir.c_plus) < visible);
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
  // The offsets' direction psi, and c+ = max(0, cos(psi - psi_h)).
  template <class T>
  struct Direction {
    T cos, sin, c_plus;
  };
  // Uniform from u (the flat parts), or with density cos(psi - psi_h) / 2
  // on the half plane around psi_h (the lobe parts): sin(psi - psi_h) = 2 u - 1.
  template <class T>
  [[gnu::always_inline]]
  static Direction<T> direction(const GaussianEnvelope<T>& env, const MaskOf<T>& lobe,
                                const T& u) {
    const auto [s_flat, c_flat] = sincos_turn(u);
    const T s_rel = T(2.0) * u - T(1.0);
    const T c_rel = sqrt((T(1.0) - s_rel) * (T(1.0) + s_rel));
    const T c_lobe = env.h_cos * c_rel - env.h_sin * s_rel;
    const T s_lobe = env.h_sin * c_rel + env.h_cos * s_rel;
    const T c_plus_flat = max(T(0.0), env.h_cos * c_flat + env.h_sin * s_flat);
    return {select(lobe, c_lobe, c_flat), select(lobe, s_lobe, s_flat),
            select(lobe, c_rel, c_plus_flat)};
  }

  // m for a longitudinal offset dl and an azimuthal offset da (SPEC section
  // 3): n_f tilted to inclination theta_n + dl in its plane with u (sin and
  // cos by the angle-sum rule), then turned by da about u.
  template <class T>
  [[gnu::always_inline]]
  static Vec3Of<T> rotated_normal(const T& sin_n, const T& cos_n, const T& pv, const T& pw,
                                  const T& dl, const T& da) {
    const auto [sl, cl] = sincos_small(dl);
    const auto [sa, ca] = sincos_small(da);
    const T st = sin_n * cl + cos_n * sl, ct = cos_n * cl - sin_n * sl;
    return {st, ct * (pv * ca - pw * sa), ct * (pv * sa + pw * ca)};
  }

  EnvelopeWidths widths_;
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
