#include "analytic/huang2022_lanes.h"

#include <cmath>
#include <type_traits>
#include <utility>

#include "analytic/model.h"
#include "common/fiber_frame.h"
#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab::analytic::huang_lanes {

namespace {

template <class B>
V3T<B> operator+(const V3T<B>& a, const V3T<B>& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class B>
V3T<B> operator-(const V3T<B>& a, const V3T<B>& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class B>
V3T<B> operator-(const V3T<B>& a) { return {-a.x, -a.y, -a.z}; }
template <class B>
V3T<B> operator*(const B& s, const V3T<B>& a) { return {s * a.x, s * a.y, s * a.z}; }
template <class B>
B dot(const V3T<B>& a, const V3T<B>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class B>
V3T<B> cross(const V3T<B>& a, const V3T<B>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class B>
V3T<B> normalized(const V3T<B>& a) { return (B(1.0) / xsimd::sqrt(dot(a, a))) * a; }
template <class B>
V3T<B> reflect(const V3T<B>& d, const V3T<B>& m) { return d - (B(2.0) * dot(d, m)) * m; }
template <class B>
B zero_unless(const typename B::batch_bool_type& m, const B& x) { return xsimd::select(m, x, B(0.0)); }

// Snell about m for a travel direction d with d.m = -cos_i < 0, given the
// refraction cosine cos_t (fresnel_reflectance's) and 1 / eta_rel.
template <class B>
V3T<B> refract(const V3T<B>& d, const V3T<B>& m, const B& cos_i, const B& cos_t, double inv_eta_rel) {
  return B(inv_eta_rel) * d + (cos_i * B(inv_eta_rel) - cos_t) * m;
}

// (sin, cos) of 2 pi t for |t| <= 1 (t in turns: a microfacet normal's
// azimuth). Double lanes: xsimd's sincos of 2 pi t, as the scalar paths.
// Float lanes: t is reduced exactly to the nearest quarter turn q / 4
// (t - q / 4 is exact in float for |t| <= 1), a = 2 pi (t - q / 4), |a| <=
// pi / 4, with 2 pi in two parts (float's 2 pi alone is 2.8e-8 high), then
// the Taylor series of sin to a^9 and of cos to a^10 (truncation below
// 2e-9, under float's rounding), rotated by the quarter turns: the exact
// values to float's rounding, without a general range reduction or a call
// (FloatLanesAreTheDoubleLanesToRounding holds the paths to the double
// lanes').
template <class B>
std::pair<B, B> sincos_turns(const B& t) {
  if constexpr (std::is_same_v<typename B::value_type, double>) {
    return xsimd::sincos(B(kTwoPi) * t);
  } else {
    const B q = xsimd::nearbyint(B(4.0) * t);
    constexpr float kHi = static_cast<float>(kTwoPi), kLo = static_cast<float>(kTwoPi - kHi);
    const B r = t - B(0.25) * q, a = xsimd::fma(r, B(kHi), r * B(kLo)), a2 = a * a;
    const B sin_a = a * xsimd::fma(a2, xsimd::fma(a2, xsimd::fma(a2, xsimd::fma(a2, B(1.0 / 362880.0),
                                                                                B(-1.0 / 5040.0)),
                                                               B(1.0 / 120.0)),
                                              B(-1.0 / 6.0)),
                                   B(1.0));
    const B cos_a =
        xsimd::fma(a2, xsimd::fma(a2, xsimd::fma(a2, xsimd::fma(a2, xsimd::fma(a2, B(-1.0 / 3628800.0),
                                                                                B(1.0 / 40320.0)),
                                                               B(-1.0 / 720.0)),
                                              B(1.0 / 24.0)),
                                 B(-0.5)),
                   B(1.0));
    // Quarter turns q mod 4: (sin, cos) -> (cos, -sin) per quarter.
    const B quadrant = q - B(4.0) * xsimd::floor(B(0.25) * q);
    const auto odd = (quadrant == B(1.0)) | (quadrant == B(3.0));
    const auto negate_sin = quadrant >= B(2.0);
    const auto negate_cos = (quadrant == B(1.0)) | (quadrant == B(2.0));
    const B s0 = xsimd::select(odd, cos_a, sin_a), c0 = xsimd::select(odd, sin_a, cos_a);
    return {xsimd::select(negate_sin, -s0, s0), xsimd::select(negate_cos, -c0, c0)};
  }
}

// Adds x to acc where m (per channel).
template <class B>
void add_where(B* acc, const typename B::batch_bool_type& m, const B* x, int C) {
  for (int c = 0; c < C; ++c) acc[c] += zero_unless(m, x[c]);
}

}  // namespace

template <class B>
bool TracerT<B>::supports(const Huang2022Params& p) {
  // Every field of Huang2022Params that changes the transport: the form, the
  // masking, the flux, the residual (each value), tilt, eccentricity, roughness,
  // sigma_a (up to kMaxChannels), lobe_scale (the TRT gate).
  return static_cast<int>(p.sigma_a.size()) <= kMaxChannels;
}

template <class B>
TracerT<B>::TracerT(const Huang2022Params& p, double theta_i, double phi_i)
    : eta_(p.eta), inv_eta_(1.0 / p.eta), alpha_(p.roughness), ct_(std::cos(p.tilt)), st_(std::sin(p.tilt)),
      C_(static_cast<int>(p.sigma_a.size())), masking_(p.masking), mesonormal_flux_(p.mesonormal_flux),
      cycles_residual_(p.residual == HuangResidual::CyclesEval),
      cycles_trt_gate_(for_lobe(p.lobe_scale, 2) > 0.0), cycles_eval_(p.form == HuangForm::CyclesEval) {
  rv_ = 1.0 / std::sqrt(p.eccentricity);
  rw_ = std::sqrt(p.eccentricity);
  irv2_ = 1.0 / (rv_ * rv_);
  irw2_ = 1.0 / (rw_ * rw_);
  for (int c = 0; c < kMaxChannels; ++c) sigma_[c] = c < C_ ? p.sigma_a[c] : 0.0;
  const Vec3 wi = direction_from_angles(theta_i, phi_i);
  wi_[0] = wi.x(), wi_[1] = wi.y(), wi_[2] = wi.z();
  // The beam's direction -wi in the circle space of the ellipse (Fiber::entry).
  const double bv = -wi.y() / rv_, bw = -wi.z() / rw_, n = std::hypot(bv, bw);
  gv_ = bv / n;
  gw_ = bw / n;
  // Cycles' eval() residual: (2 / pi) dgamma / (cos theta_i W) per point,
  // dgamma = pi base, W the projected width with the major axis 1.
  const double width = 2.0 * std::sqrt(rv_ * rv_ * wi.z() * wi.z() + rw_ * rw_ * wi.y() * wi.y()) /
                       std::hypot(wi.y(), wi.z()) * std::sqrt(p.eccentricity);
  cycles_scale_ = 2.0 / (std::cos(theta_i) * width);
}

template <class B>
inline typename TracerT<B>::Hit TracerT<B>::hit(const B& pv, const B& pw) const {
  Hit h{pv, pw, normalized(V3{B(0.0), pv * irv2_, pw * irw2_}), V3{}};
  h.ns = V3{B(-st_), B(ct_) * h.n0.y, B(ct_) * h.n0.z};
  return h;
}

// Smith's Lambda (Surface::lambda) through 1 + 2 Lambda = q / c with
// q = sqrt(c^2 + alpha^2 (1 - c^2)), c = min(1, |cos|), so that each
// masking factor below takes one division.
template <class B>
inline B TracerT<B>::lambda_root(const B& c) const {
  return xsimd::sqrt(c * c + B(alpha_ * alpha_) * (B(1.0) - c * c));
}

// Surface::leaving: separable G1(o) = 1 / (1 + L_o) = 2 c_o / (c_o + q_o);
// correlated (1 + L_i) / (1 + L_i + L_o) = c_o (c_i + q_i) / (q_i c_o + q_o c_i).
template <class B>
inline B TracerT<B>::leaving(const B& cos_in, const B& cos_out) const {
  if (masking_ == HuangMasking::None || alpha_ == 0.0) return B(1.0);
  const B co = xsimd::min(B(1.0), xsimd::abs(cos_out)), qo = lambda_root(co);
  if (masking_ == HuangMasking::Separable) return B(2.0) * co / (co + qo);
  const B ci = xsimd::min(B(1.0), xsimd::abs(cos_in)), qi = lambda_root(ci);
  return co * (ci + qi) / (qi * co + qo * ci);
}

// Surface::normal of huang2022.cpp for the facing normal nf = side * ns at
// h: the frame (the fiber axis u in the facet plane, nf x that, nf) and
// Heitz 2018's VNDF map (common/ggx.cpp's sample_visible) per lane. With
// ns = (-sin tilt, cos tilt n0) and n0 _|_ u, u - (u.nf) nf normalised is
// x = (cos tilt, sin tilt n0) and nf x x = side (0, n0_w, -n0_v): no
// square root.
template <class B>
inline typename TracerT<B>::V3 TracerT<B>::normal(const Hit& h, double side, const V3& w, const B& u1, const B& u2) const {
  const V3 nf = B(side) * h.ns;
  if (alpha_ == 0.0) return nf;
  const B a(alpha_);
  const V3 x{B(ct_), B(st_) * h.n0.y, B(st_) * h.n0.z};
  const V3 y{B(0.0), B(side) * h.n0.z, B(-side) * h.n0.y};
  const V3 vh = normalized(V3{a * dot(w, x), a * dot(w, y), dot(w, nf)});
  const B len2 = vh.x * vh.x + vh.y * vh.y;
  const M flat = len2 > B(0.0);
  const B inv = B(1.0) / xsimd::sqrt(len2);
  const V3 t1{xsimd::select(flat, -vh.y * inv, B(1.0)), xsimd::select(flat, vh.x * inv, B(0.0)), B(0.0)};
  const V3 t2 = cross(vh, t1);
  const B r = xsimd::sqrt(u1);
  const auto sc = sincos_turns(u2);
  const B p1 = r * sc.second;
  const B s = B(0.5) * (B(1.0) + vh.z);
  const B p2 = (B(1.0) - s) * xsimd::sqrt(xsimd::max(B(0.0), B(1.0) - p1 * p1)) + s * (r * sc.first);
  const V3 nh = p1 * t1 + p2 * t2 + xsimd::sqrt(xsimd::max(B(0.0), B(1.0) - p1 * p1 - p2 * p2)) * vh;
  const V3 ml = normalized(V3{a * nh.x, a * nh.y, xsimd::max(B(0.0), nh.z)});
  return ml.x * x + ml.y * y + ml.z * nf;
}

template <class B>
void TracerT<B>::trace(const B* u, const B& base, Exits& out, unsigned orders) const {
  const bool ledger = orders & kLedger;
  for (int c = 0; c < C_; ++c) {
    out.residual[c] = out.masked[c] = out.stopped[c] = B(0.0);
    for (int p = 0; p < 3; ++p) out.w[p][c] = B(0.0);
  }
  for (int p = 0; p < 3; ++p) out.live[p] = M(false);
  // The entry at circle-space angle g (Fiber::entry), its share of the beam
  // cos(g) dg / 2, scaled onto the mesonormal by (wi.ns)/(wi.n0) (paper).
  // (xsimd's sincos, not sincos_turns: in float, g's and pi / 2's roundings
  // are both 2.8e-8 high and cancel in the shares' sum, the light reaching
  // the fiber, which holds to 1e-9.)
  const B g = (u[0] - B(0.5)) * B(kPi);
  const auto sc = xsimd::sincos(g);
  const B sg = sc.first, cg = sc.second;
  const Hit h = hit(B(rv_) * (-sg * gw_ - cg * gv_), B(rw_) * (sg * gv_ - cg * gw_));
  const V3 wi{B(wi_[0]), B(wi_[1]), B(wi_[2])};
  const B macro = dot(wi, h.n0), meso = dot(wi, h.ns);
  // (cos g >= 0: a float g can round past pi / 2.)
  B w0 = base * B(0.5 * kPi) * xsimd::max(B(0.0), cg);
  if (mesonormal_flux_) w0 = w0 * xsimd::max(B(0.0), meso) / macro;
  out.incident = w0;
  M alive = (macro > B(0.0)) & (w0 != B(0.0));
  const M facing = meso > B(0.0);
  if (ledger) for (int c = 0; c < C_; ++c) out.stopped[c] += zero_unless(alive & !facing, w0);
  alive = alive & facing;
  if (cycles_eval_) {
    // Cycles' eval() integrates over |h| <= 0.999 of the projected width only
    // (Paths::trace, kCyclesEvalMaxImpact).
    const M outside = xsimd::abs(sg) > B(0.999);
    if (ledger) for (int c = 0; c < C_; ++c) out.stopped[c] += zero_unless(alive & outside, w0);
    alive = alive & !outside;
  }
  if (!xsimd::any(alive)) return;

  const V3 d0 = -wi;
  const V3 m = normal(h, 1.0, wi, u[1], u[2]);
  const B ci = dot(wi, m);
  const auto fr = fresnel_reflectance(ci, B(eta_), B(inv_eta_));
  const B F = fr.F;
  // R: reflection about m, on the outer side of ns and n0, masked towards o.
  if (orders & 1u) {
    const V3 o = reflect(d0, m);
    const B on = dot(o, h.ns), om = dot(o, h.n0);
    // (form=cycles_eval: Cycles' eval_r tests the macro normal only.)
    const M ok = cycles_eval_ ? om > B(0.0) : (on > B(0.0)) & (om > B(0.0));
    const B gl = leaving(meso, on), wf = w0 * F;
    const M live = alive & ok;
    for (int c = 0; c < C_; ++c) {
      if (ledger) out.stopped[c] += zero_unless(alive & !ok, wf);
      if (ledger) out.masked[c] += zero_unless(live, wf * (B(1.0) - gl));
      out.w[0][c] = zero_unless(live, wf * gl);
    }
    out.live[0] = live & (F > B(0.0));
    out.dir[0] = o;
  }
  if (!(orders & kAllOrders & ~1u)) return;
  // T: into the fiber, on the inner side of ns and n0, masked towards t.
  const M entering = alive & !fr.tir;
  const V3 t = refract(d0, m, ci, fr.cos_t, inv_eta_);
  const B on = -dot(t, h.ns), om = -dot(t, h.n0);
  const M ok = (on > B(0.0)) & (om > B(0.0));
  const B gl = leaving(meso, on), prob = B(1.0) - F;
  const M live = entering & ok;
  B w[kMaxChannels];
  for (int c = 0; c < C_; ++c) {
    if (ledger) out.stopped[c] += zero_unless(entering & !ok, w0 * prob);
    if (ledger) out.masked[c] += zero_unless(live, w0 * prob * (B(1.0) - gl));
    w[c] = zero_unless(live, w0 * prob * gl);
  }
  const M inside_live = live & (prob > B(0.0));
  if (xsimd::any(inside_live)) inside(u, h, t, inside_live, w, prob, base * cycles_scale_, orders, out);
}

// Huang2022's Paths::inside for k = 1 then k = 2: a chord, absorption, the
// interface (stopped where its scale faces away from the arriving light),
// the exit of order k and the internal reflection; after interface 3 the
// residual (Cycles' sampler's geometric series, or with residual=cycles_eval
// Cycles' eval()'s at interface 2 and nothing from interface 3).
template <class B>
void TracerT<B>::inside(const B* u, const Hit& from, const V3& d_in, const M& alive_in, const B* w_in,
                    const B& t1, const B& cycles_weight, unsigned orders, Exits& out) const {
  const bool ledger = orders & kLedger;
  const int C = C_;
  M alive = alive_in;
  Hit at = from;
  V3 d = d_in;
  B w[kMaxChannels], a1[kMaxChannels];
  for (int c = 0; c < C; ++c) w[c] = w_in[c];
  B t2(1.0);  // interface 2's Fresnel transmittance (the sampler's residual)
  for (int k = 1; k <= 2; ++k) {
    // The chord: the far root of the ellipse's quadratic from `at` along d.
    const B qa = d.y * d.y * irv2_ + d.z * d.z * irw2_;
    const B qb = B(2.0) * (at.pv * d.y * irv2_ + at.pw * d.z * irw2_);
    const M runs = qa > B(0.0);
    if (ledger) add_where(out.stopped, alive & !runs, w, C);
    alive = alive & runs;
    const B len = xsimd::max(B(0.0), -qb / qa);
    // (The scalar Fiber::next also rescales the point onto the ellipse: a
    // change in the last bits only.)
    const Hit before = at;
    at = hit(at.pv + len * d.y, at.pw + len * d.z);
    B a[kMaxChannels];
    for (int c = 0; c < C; ++c) {
      a[c] = sigma_[c] == 0.0 ? B(1.0) : xsimd::exp(B(-sigma_[c]) * len);  // SPEC s4
      w[c] = w[c] * a[c];
    }
    if (cycles_eval_) {
      // Paths::cycles_eval_chord_ratio: (d.n0 / d.ns) where the chord leaves,
      // (d.ns / d.n0) where it arrives, 0 where either is not positive.
      const B leave = dot(d, before.n0) / dot(d, before.ns), arrive = dot(d, at.ns) / dot(d, at.n0);
      const B ratio = zero_unless((leave > B(0.0)) & (arrive > B(0.0)), leave * arrive);
      for (int c = 0; c < C; ++c) w[c] = w[c] * ratio;
    }
    const V3 nf = -at.ns, wv = -d;
    const B wn = dot(wv, nf);
    const M facing = wn > B(0.0);
    if (ledger) add_where(out.stopped, alive & !facing, w, C);
    alive = alive & facing;
    if (!xsimd::any(alive)) return;
    const V3 m = normal(at, -1.0, wv, u[2 * k + 1], u[2 * k + 2]);
    const B ci = dot(wv, m);
    const auto fr = fresnel_reflectance(ci, B(inv_eta_), B(eta_));
    const B F = fr.F;
    // Out: order p = k (crossing: on the outer side of ns and n0).
    if (orders >> k & 1u) {
      const M leaving_side = alive & !fr.tir;
      const V3 o = refract(d, m, ci, fr.cos_t, eta_);
      const B on = dot(o, at.ns), om = dot(o, at.n0);
      // (form=cycles_eval: Cycles' eval() does not test TT's exit side.)
      const M ok = cycles_eval_ && k == 1 ? M(true) : (on > B(0.0)) & (om > B(0.0));
      const B gl = leaving(wn, on), prob = B(1.0) - F;
      const M live = leaving_side & ok;
      for (int c = 0; c < C; ++c) {
        if (ledger) out.stopped[c] += zero_unless(leaving_side & !ok, w[c] * prob);
        if (ledger) out.masked[c] += zero_unless(live, w[c] * prob * (B(1.0) - gl));
        out.w[k][c] = zero_unless(live, w[c] * prob * gl);
      }
      out.live[k] = live & (prob > B(0.0));
      out.dir[k] = o;
    }
    // Internal reflection (staying: on the inner side of ns and n0), where
    // an order beyond k is followed.
    if (!((orders & kAllOrders) >> (k + 1))) return;
    if (cycles_residual_ && k == 2) {
      if (ledger) for (int c = 0; c < C; ++c) out.stopped[c] += zero_unless(alive, w[c] * F);
      return;
    }
    if (cycles_residual_ && cycles_trt_gate_ && (orders & 8u)) {
      // Cycles' eval() residual at interface 2: T1 R2^2 T_avg A^3 / (1 - A (1 - T_avg)).
      const B t_avg = xsimd::max(B(1.0) - F, B(1e-5));
      for (int c = 0; c < C; ++c)
        out.residual[c] += zero_unless(
            alive, cycles_weight * t1 * F * F * t_avg * a[c] * a[c] * a[c] / ((B(1.0) - a[c]) + a[c] * t_avg));
    }
    const V3 r = reflect(d, m);
    const B on = -dot(r, at.ns), om = -dot(r, at.n0);
    const M ok = (on > B(0.0)) & (om > B(0.0));
    const B gl = leaving(wn, on);
    const M live = alive & ok;
    for (int c = 0; c < C; ++c) {
      if (ledger) out.stopped[c] += zero_unless(alive & !ok, w[c] * F);
      if (ledger) out.masked[c] += zero_unless(live, w[c] * F * (B(1.0) - gl));
      w[c] = zero_unless(live, w[c] * F * gl);
    }
    alive = live & (F > B(0.0));
    if (k == 2) {
      // Cycles' sampler's residual for every p >= 3:
      // A_avg T_avg / (1 - A_avg (1 - T_avg)), A_avg = sqrt(A_1 A_2).
      const B t_avg = xsimd::max(B(1e-5), B(0.5) * (t2 + (B(1.0) - F)));
      for (int c = 0; c < C; ++c) {
        const B a_avg = sigma_[c] == 0.0 ? B(1.0) : xsimd::sqrt(a1[c] * a[c]);
        // 1 - A (1 - T) as (1 - A) + A T (Paths::inside): exact for white
        // fibers as T -> 1e-5, where float's 1 - (1 - T) loses ~1e-3.
        out.residual[c] += zero_unless(alive, w[c] * a_avg * t_avg / ((B(1.0) - a_avg) + a_avg * t_avg));
      }
      return;
    }
    for (int c = 0; c < C; ++c) a1[c] = a[c];
    t2 = B(1.0) - F;
    d = r;
    if (!xsimd::any(alive)) return;
  }
}

template class TracerT<xsimd::batch<float>>;
template class TracerT<xsimd::batch<double>>;

}  // namespace fiberlab::analytic::huang_lanes
