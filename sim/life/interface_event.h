#pragma once
// One interface event (SPEC section 3): given the photon's direction d, its
// side and a microfacet normal m (d.m < 0), choose reflection with the Fresnel
// probability or refraction by Snell's law.
//
// The polarisation state ("light") is a template parameter so that the photon
// life is the same for scalar and Stokes light, and each light is written
// once for its number type T (sim/simd/lanes.h): one photon or a SIMD vector of
// photons. interact() changes only the lanes in `act` (the state of the
// others, their random streams included, is untouched) and returns the new
// direction for those lanes.
#include "common/fresnel.h"
#include "sim/simd/lanes.h"
#include "sim/life/random.h"

namespace fiberlab::sim::life {

// The two sides of the interface at an event: eta_rel = n_t / n_i and its
// inverse ratio = n_i / n_t.
template <class T>
struct InterfaceIndex {
  T eta_rel, ratio;
};

template <class T>
struct EventResult {
  Vec3Of<T> direction;  // the new direction, for the lanes that acted
  MaskOf<T> refracted;  // the photon changed side
  // Expected-value scoring (SPEC section 5), in the lanes of `scored`: the
  // branch that leaves the fiber (its direction and probability) was not
  // chosen; `direction` is the other branch.
  MaskOf<T> scored;
  Vec3Of<T> leave_direction;
  T p_leave;
};

// Which lanes may score their leaving branch by its expected value at this
// event (`eligible`, within the acting lanes), and what decides whether that
// branch leaves: the photon's side and the untilted outward normal n0 (the
// consistency rule of SPEC section 3). interact() without it makes every
// choice analog (the analog estimator; the medulla's interface events,
// sim/life/medulla.h, none of whose branches leaves the fiber).
template <class T>
struct ExitScoring {
  MaskOf<T> eligible, inside;
  Vec3Of<T> n0;
};

// The branch that leaves the fiber at once, if it does: reflection for a
// photon outside, refraction (none under total internal reflection) for one
// inside, kept only where its direction leaves on the outside of n0
// (d'.n0 > 0). Where it does not leave, the choice stays analog (SPEC
// section 5: a branch the consistency rule sends back is not terminal).
template <class T>
MaskOf<T> leaving_branch(const ExitScoring<T>& e, const Vec3Of<T>& d, const Vec3Of<T>& m,
                         const MaskOf<T>& tir, const T& cos_i, const T& cos_t, const T& ratio,
                         Vec3Of<T>& leave) {
  leave = scatter_direction(d, m, !e.inside, cos_i, cos_t, ratio);
  return e.eligible & !(e.inside & tir) & (leave.dot(e.n0) > T(0.0));
}

// The leaving branch's probability: the reflection's, p_reflect, for a
// photon outside; the refraction's, 1 - p_reflect, for one inside.
template <class T>
T leaving_probability(const MaskOf<T>& inside, const T& p_reflect) {
  return select(inside, T(1.0) - p_reflect, p_reflect);
}

// Mirror reflection or vector Snell refraction of d about m (cos_i = -d.m),
// only the chosen one computed: d' = a d + b m with (a, b) = (1, 2 cos_i)
// for reflection and (ratio, ratio cos_i - cos_t) for refraction, normalised.
template <class T>
Vec3Of<T> scatter_direction(const Vec3Of<T>& d, const Vec3Of<T>& m, const MaskOf<T>& reflect,
                            const T& cos_i, const T& cos_t, const T& ratio) {
  const T a = select(reflect, T(1.0), ratio);
  const T b = select(reflect, T(2.0) * cos_i, ratio * cos_i - cos_t);
  return (a * d + b * m).normalized();
}

// Unpolarised light: carries nothing, reflects with F = (Rs + Rp) / 2.
// interact() (both lights) is always inlined: GCC 12 left it out of line,
// passing the vectors through memory (farm-bench, case b, one thread:
// analog 0.95 and Stokes 0.93 of the time, the same numbers).
template <class T>
struct ScalarLight {
  static constexpr bool kPolarized = false;
  template <class U>
  using Rebind = ScalarLight<U>;
  explicit ScalarLight(const Vec3Of<T>& /*d*/ = {}) {}
  [[gnu::always_inline]] EventResult<T> interact(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                 const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                 LaneRandom<T>& rng) {
    return interact_as<false>(d, m, n, act, rng, {});
  }
  [[gnu::always_inline]] EventResult<T> interact(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                 const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                 LaneRandom<T>& rng, const ExitScoring<T>& e) {
    return interact_as<true>(d, m, n, act, rng, e);
  }

 private:
  template <bool kScore>
  [[gnu::always_inline]] EventResult<T> interact_as(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                    const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                    LaneRandom<T>& rng, const ExitScoring<T>& e) {
    // F uses the true 3D angle between d and m (SPEC section 3).
    const T cos_i = min(T(1.0), max(T(0.0), -d.dot(m)));
    const FresnelReflectanceOf<T> f = fresnel_reflectance(cos_i, n.eta_rel, n.ratio);
    EventResult<T> r{{}, {}, MaskOf<T>(false), {}, T(0.0)};
    MaskOf<T> reflect;
    if constexpr (kScore) {
      r.scored = leaving_branch(e, d, m, f.tir, cos_i, f.cos_t, n.ratio, r.leave_direction);
      r.p_leave = leaving_probability(e.inside, f.F);
      // Where the leaving branch is scored, the photon takes the other one:
      // it reflects when inside.
      reflect = f.tir | (r.scored & e.inside) |
                ((!r.scored) & (rng.uniform(act & !f.tir & !r.scored) < f.F));
    } else {
      reflect = f.tir | (rng.uniform(act & !f.tir) < f.F);
    }
    r.direction = scatter_direction(d, m, reflect, cos_i, f.cos_t, n.ratio);
    r.refracted = !reflect;
    return r;
  }
};

// `polarization: stokes` (SPEC section 3): the photon carries one Stokes
// vector (I, Q, U, V), kept at I = 1, referred to an axis e1 perpendicular to
// its direction. At each event the reference axis is first turned to the
// event's s-axis, then the photon reflects with probability (first row of the
// reflection Mueller matrix) . (I, Q, U, V) and the Stokes vector becomes the
// chosen Mueller matrix times itself, renormalised to I = 1.
template <class T>
struct StokesLight {
  static constexpr bool kPolarized = true;
  template <class U>
  using Rebind = StokesLight<U>;
  T q = T(0.0), u = T(0.0), v = T(0.0);
  Vec3Of<T> e1;

  StokesLight() = default;
  // Unpolarised light travelling along d.
  explicit StokesLight(const Vec3Of<T>& d) {
    const MaskOf<T> off_axis = abs(d.x) < T(0.9);
    const Vec3Of<T> helper(select(off_axis, T(1.0), T(0.0)), select(off_axis, T(0.0), T(1.0)),
                           T(0.0));
    e1 = d.cross(helper).normalized();
  }

  [[gnu::always_inline]] EventResult<T> interact(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                 const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                 LaneRandom<T>& rng) {
    return interact_as<false>(d, m, n, act, rng, {});
  }
  [[gnu::always_inline]] EventResult<T> interact(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                 const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                 LaneRandom<T>& rng, const ExitScoring<T>& e) {
    return interact_as<true>(d, m, n, act, rng, e);
  }

 private:
  template <bool kScore>
  [[gnu::always_inline]] EventResult<T> interact_as(const Vec3Of<T>& d, const Vec3Of<T>& m,
                                                    const InterfaceIndex<T>& n, const MaskOf<T>& act,
                                                    LaneRandom<T>& rng, const ExitScoring<T>& e) {
    const T cos_i = min(T(1.0), max(T(0.0), -d.dot(m)));
    // Turn the reference axis about d to the event's s-axis s = d x m / |d x m|;
    // (Q, U) rotate by 2 psi, cos psi = e1.s, sin psi = (d x e1).s. At
    // normal incidence d x m = 0 and e1 is kept.
    const Vec3Of<T> dxm = d.cross(m);
    const T len = dxm.norm();
    const MaskOf<T> turn = act & (len > T(1e-12));
    const Vec3Of<T> s = (T(1.0) / len) * dxm;
    const T c = e1.dot(s), sn = d.cross(e1).dot(s);
    const T c2 = c * c - sn * sn, s2 = T(2.0) * c * sn;  // cos 2 psi, sin 2 psi
    const T q1 = select(turn, c2 * q + s2 * u, q), u1 = select(turn, -s2 * q + c2 * u, u);
    const Vec3Of<T> e1_turned = select(turn, s, e1);
    // Mueller matrices in the s/p frame: [[A, B, 0, 0], [B, A, 0, 0],
    // [0, 0, C, S], [0, 0, -S, C]].
    const FresnelComplexOf<T> r = fresnel_complex_amplitudes(cos_i, n.eta_rel);
    const MaskOf<T> tir = r.tir;
    const T rs2 = r.rs_re * r.rs_re + r.rs_im * r.rs_im;
    const T rp2 = r.rp_re * r.rp_re + r.rp_im * r.rp_im;
    const T a_r = T(0.5) * (rs2 + rp2), b_r = T(0.5) * (rs2 - rp2);
    const T c_r = r.rs_re * r.rp_re + r.rs_im * r.rp_im;  // Re(r_s conj(r_p))
    const T s_r = r.rs_im * r.rp_re - r.rs_re * r.rp_im;  // Im(r_s conj(r_p))
    const T ts = T(1.0) - rs2, tp = T(1.0) - rp2;
    const T a_t = T(0.5) * (ts + tp), b_t = T(0.5) * (ts - tp);
    const T c_t = sqrt(max(T(0.0), ts * tp));
    const T p_reflect = a_r + b_r * q1;
    EventResult<T> res{{}, {}, MaskOf<T>(false), {}, T(0.0)};
    MaskOf<T> reflect;
    if constexpr (kScore) {
      res.scored = leaving_branch(e, d, m, tir, cos_i, r.cos_t, n.ratio, res.leave_direction);
      // The first row of the transmission matrix times the Stokes vector:
      // A_T + B_T Q = 1 - (A_R + B_R Q).
      res.p_leave = leaving_probability(e.inside, p_reflect);
      reflect = tir | (res.scored & e.inside) |
                ((!res.scored) & (rng.uniform(act & !tir & !res.scored) < p_reflect));
    } else {
      reflect = tir | (rng.uniform(act & !tir) < p_reflect);
    }
    const T A = select(reflect, a_r, a_t), B = select(reflect, b_r, b_t);
    const T C = select(reflect, c_r, c_t), S = select(reflect, s_r, T(0.0));
    const T inv_i = T(1.0) / (A + B * q1);
    const T q2 = (B + A * q1) * inv_i, u2 = (C * u1 + S * v) * inv_i;
    const T v2 = (-S * u1 + C * v) * inv_i;
    const Vec3Of<T> out = scatter_direction(d, m, reflect, cos_i, r.cos_t, n.ratio);
    // s stays the reference axis; keep it exactly perpendicular to the new direction.
    const Vec3Of<T> e1_new = (e1_turned - e1_turned.dot(out) * out).normalized();
    q = select(act, q2, q);
    u = select(act, u2, u);
    v = select(act, v2, v);
    e1 = select(act, e1_new, e1);
    res.direction = out;
    res.refracted = !reflect;
    return res;
  }
};

}  // namespace fiberlab::sim::life
