#include "analytic/huang2022.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <deque>
#include <type_traits>
#include <variant>

#include <omp.h>

#include "analytic/huang2022_lanes.h"
#include "analytic/longitudinal_lobes.h"
#include "analytic/model_params.h"
#include "analytic/model_registry.h"
#include "analytic/physical_defaults.h"
#include "analytic/quadrature.h"
#include "common/error.h"
#include "common/fresnel.h"
#include "common/ggx.h"
#include "common/units.h"

namespace fiberlab::analytic {

namespace {

constexpr int kResidualP = 3;              // every order p >= 3 in one lobe (Cycles' TRRT+)
constexpr double kMinDensityRoughness = 1e-3;  // density(): Cycles' clamp of the roughness
constexpr int kArcNodes = 4096;            // density(): midpoint nodes over the arc (R)
constexpr double kDeltaV = 1e-10;          // residual: v below this is a delta in theta_r
constexpr double kCyclesEvalMaxImpact = 0.999;  // form=cycles_eval: Cycles' eval() clamps |h| / r to this
constexpr long kMaxQuadraturePoints = 1L << 30;

// ---- The point set ---------------------------------------------------------------
// Halton's point set: coordinate k of point i is the radical inverse of i in
// the k-th prime base. Deterministic; its one-dimensional projections are
// stratified, the first (base 2) exactly for N a power of 2.
constexpr int kDims = 9;
constexpr unsigned kBases[kDims] = {2, 3, 5, 7, 11, 13, 17, 19, 23};

// The points i = first, first + 1, ... in order. The radical inverse of i in
// base b is sum_k T(c_k) / B^k over i's digits c_k in base B = b^e (a block
// of e base-b digits; T the radical inverse of a block, tabulated): the
// blocks are carried as i advances, so no point needs a division.
class Halton {
 public:
  Halton(std::uint64_t first, long n, std::uint64_t end) : half_cell_(0.5 / static_cast<double>(n)) {
    for (int k = 0; k < kDims; ++k) {
      Digits& d = digits_[k];
      const std::vector<double>& table = block_tables()[k];
      d.block = static_cast<unsigned>(table.size());
      d.table = table.data();
      d.inv_block = 1.0 / d.block;
      std::uint64_t x = first;
      for (int q = 0; q < kMaxBlocks; ++q, x /= d.block) d.c[q] = static_cast<unsigned>(x % d.block);
      d.used = 1;  // blocks that any index below `end` has
      for (std::uint64_t top = end / d.block; top > 0 && d.used < kMaxBlocks; top /= d.block) ++d.used;
    }
  }
  // The current point; then advance().
  void get(double* u) const {
    for (int k = 0; k < kDims; ++k) {
      const Digits& d = digits_[k];
      double r = 0.0;
      for (int q = d.used - 1; q >= 0; --q) r = (r + d.table[d.c[q]]) * (q > 0 ? d.inv_block : 1.0);
      u[k] = r;
    }
    u[0] += half_cell_;  // midpoints in dimension 0
    if (u[0] >= 1.0) u[0] -= 1.0;
  }
  // The W points from the current one (coordinate k < dims of point l in
  // u[k][l]; the others not written), then advanced past them. The same
  // values as W calls of get() and advance(): within a block the lowest
  // digits of W consecutive indices are consecutive table entries over the
  // same higher blocks.
  template <int W>
  void get_lanes(double (*u)[W], int dims = kDims) {
    for (int k = dims; k < kDims; ++k) skip<W>(digits_[k]);
    for (int k = 0; k < dims; ++k) {
      Digits& d = digits_[k];
      if (d.c[0] + W > d.block) {  // a carry inside the group: point by point
        for (int l = 0; l < W; ++l) {
          u[k][l] = value(d);
          step(d);
        }
        continue;
      }
      double hi = 0.0;
      for (int q = d.used - 1; q > 0; --q) hi = (hi + d.table[d.c[q]]) * d.inv_block;
      const double* t = &d.table[d.c[0]];
      for (int l = 0; l < W; ++l) u[k][l] = hi + t[l];
      d.c[0] += W;
      if (d.c[0] == d.block) {
        d.c[0] = 0;
        for (int q = 1; q < kMaxBlocks; ++q) {
          if (++d.c[q] < d.block) break;
          d.c[q] = 0;
        }
      }
    }
    for (int l = 0; l < W; ++l) {
      u[0][l] += half_cell_;
      if (u[0][l] >= 1.0) u[0][l] -= 1.0;
    }
  }
  void advance() {
    for (Digits& d : digits_)
      for (int q = 0; q < kMaxBlocks; ++q) {
        if (++d.c[q] < d.block) break;
        d.c[q] = 0;
      }
  }

 private:
  static constexpr unsigned kBlockMax = 4096;  // tables of at most 4096 entries (32 KiB)
  static constexpr int kMaxBlocks = 8;          // 23^2 = 529 per block: 8 blocks hold i < 2^64
  // Per base b, the radical inverse of every block of e base-b digits (the
  // digits of j reversed), b^e the largest power within kBlockMax: made once
  // (a quadrature makes a Halton per block of points).
  static const std::array<std::vector<double>, kDims>& block_tables() {
    static const std::array<std::vector<double>, kDims> tables = [] {
      std::array<std::vector<double>, kDims> t;
      for (int k = 0; k < kDims; ++k) {
        const unsigned b = kBases[k];
        unsigned block = 1;
        int e = 0;
        while (block * b <= kBlockMax) block *= b, ++e;
        t[k].resize(block);
        for (unsigned j = 0; j < block; ++j) {
          double f = 1.0 / b, r = 0.0;
          for (unsigned x = j, q = 0; q < static_cast<unsigned>(e); ++q, x /= b, f /= b) r += (x % b) * f;
          t[k][j] = r;
        }
      }
      return t;
    }();
    return tables;
  }
  struct Digits {
    unsigned block = 1;
    int used = kMaxBlocks;
    double inv_block = 1.0;
    const double* table = nullptr;
    unsigned c[kMaxBlocks] = {};
  };
  static double value(const Digits& d) {
    double r = 0.0;
    for (int q = d.used - 1; q >= 0; --q) r = (r + d.table[d.c[q]]) * (q > 0 ? d.inv_block : 1.0);
    return r;
  }
  static void step(Digits& d) {
    for (int q = 0; q < kMaxBlocks; ++q) {
      if (++d.c[q] < d.block) break;
      d.c[q] = 0;
    }
  }
  // W steps at once (W is below every block: one carry at most).
  template <int W>
  static void skip(Digits& d) {
    d.c[0] += W;
    if (d.c[0] < d.block) return;
    d.c[0] -= d.block;
    for (int q = 1; q < kMaxBlocks; ++q) {
      if (++d.c[q] < d.block) break;
      d.c[q] = 0;
    }
  }
  Digits digits_[kDims];
  double half_cell_;
};

// Coordinates: 0 the entry angle, 1-2 / 3-4 / 5-6 the microfacet normals of
// interfaces 1 / 2 / 3, 7-8 the residual's spread.
struct Point {
  double u[kDims];
};

// Per-channel weights without allocation (at most 8 channels: the
// constructor's limit).
constexpr int kMaxChannels = 8;
struct Weights {
  double c[kMaxChannels];
};

// ---- Geometry (SPEC s2) ----------------------------------------------------------
// A boundary point of the ellipse (semi-axes rv, rw) with its outward macro
// normal n0 and the tilted mesonormal ns = cos(tilt) n0 - sin(tilt) u.
struct Hit {
  double pv, pw;
  Vec3 n0, ns;
};

class Fiber {
 public:
  Fiber(double eccentricity, double tilt)
      : rv_(1.0 / std::sqrt(eccentricity)), rw_(std::sqrt(eccentricity)),
        ct_(std::cos(tilt)), st_(std::sin(tilt)) {}

  Hit hit(double pv, double pw) const {
    Hit h{pv, pw, Vec3(0.0, pv / (rv_ * rv_), pw / (rw_ * rw_)).normalized(), Vec3()};
    h.ns = ct_ * h.n0 - st_ * Vec3(1.0, 0.0, 0.0);
    return h;
  }
  // The point a photon travelling along d meets at circle-space angle g in
  // (-pi/2, pi/2) (impact h = sin g across the projected width): the ellipse
  // is the unit circle scaled by (rv, rw), which keeps impact fractions.
  Hit entry(const Vec3& d, double g) const {
    const double bv = d.y() / rv_, bw = d.z() / rw_, n = std::hypot(bv, bw);
    const double gv = bv / n, gw = bw / n;  // beam direction in circle space
    const double qv = std::sin(g) * -gw - std::cos(g) * gv, qw = std::sin(g) * gv - std::cos(g) * gw;
    return hit(rv_ * qv, rw_ * qw);
  }
  // From boundary point `from` along d inside: the next boundary point and
  // the 3D length travelled (the far root of the ellipse's quadratic, whose
  // constant term is 0 on the boundary). Returns false if d runs along u.
  bool next(const Hit& from, const Vec3& d, Hit& to, double& length) const {
    const double a = d.y() * d.y() / (rv_ * rv_) + d.z() * d.z() / (rw_ * rw_);
    const double b = 2.0 * (from.pv * d.y() / (rv_ * rv_) + from.pw * d.z() / (rw_ * rw_));
    if (!(a > 0.0)) return false;
    length = std::max(0.0, -b / a);
    double pv = from.pv + length * d.y(), pw = from.pw + length * d.z();
    const double s = std::sqrt(pv * pv / (rv_ * rv_) + pw * pw / (rw_ * rw_));
    to = hit(pv / s, pw / s);
    return true;
  }
  // Width of the cross-section's projection across the beam direction (v, w).
  double projected_width(double bv, double bw) const {
    const double n = std::hypot(bv, bw);
    return 2.0 * std::sqrt(rv_ * rv_ * bw * bw + rw_ * rw_ * bv * bv) / n;
  }
  // Point of the boundary at parameter t (v = rv cos t, w = rw sin t) and
  // the arc length per dt there.
  Hit at(double t) const { return hit(rv_ * std::cos(t), rw_ * std::sin(t)); }
  double arc_per_dt(double t) const {
    return std::hypot(rv_ * std::sin(t), rw_ * std::cos(t));
  }

 private:
  double rv_, rw_, ct_, st_;
};

Vec3 reflect(const Vec3& d, const Vec3& m) { return d - 2.0 * d.dot(m) * m; }

// Snell about m (d.m < 0) with eta_rel = n_t / n_i; false under total
// internal reflection.
bool refract(const Vec3& d, const Vec3& m, double eta_rel, Vec3& t) {
  const double ci = -d.dot(m);
  const double s2 = (1.0 - ci * ci) / (eta_rel * eta_rel);
  if (s2 >= 1.0) return false;
  t = d / eta_rel + (ci / eta_rel - std::sqrt(1.0 - s2)) * m;
  return true;
}

// ---- The microfacet interface ----------------------------------------------------
class Surface {
 public:
  Surface(double alpha, HuangMasking masking) : a_(alpha), masking_(masking) {}
  double alpha() const { return a_; }
  // Smith's Lambda of a direction at |cos| c to the mesonormal (isotropic GGX).
  // ggx::Lambda's formula for an isotropic alpha written in c alone:
  // 1/a^2 = alpha^2 tan^2 = alpha^2 (1 - c^2) / c^2 (inf at c = 0, as there).
  double lambda(double c) const {
    if (a_ == 0.0) return 0.0;
    c = std::min(1.0, std::abs(c));
    return 0.5 * (-1.0 + std::sqrt(1.0 + a_ * a_ * (1.0 - c * c) / (c * c)));
  }
  // Weight of the leaving direction given the normals were drawn from the
  // arriving direction's VNDF (which holds G1 of the arrival): separable
  // G1(o); correlated G2 / G1(i) = (1 + L_i) / (1 + L_i + L_o); none 1.
  double leaving(double cos_in, double cos_out) const {
    if (masking_ == HuangMasking::None || a_ == 0.0) return 1.0;
    const double lo = lambda(cos_out);
    if (masking_ == HuangMasking::Separable) return 1.0 / (1.0 + lo);
    const double li = lambda(cos_in);
    return (1.0 + li) / (1.0 + li + lo);
  }
  // A microfacet normal seen from w (w.nf > 0) for the point (u1, u2).
  Vec3 normal(const Vec3& nf, const Vec3& w, double u1, double u2) const {
    if (a_ == 0.0) return nf;
    const Vec3 x = tangent(nf), y = nf.cross(x);
    const Vec3 wl(w.dot(x), w.dot(y), w.dot(nf));
    const Vec3 m = ggx::sample_visible(wl, a_, a_, u1, u2);
    return m.x() * x + m.y() * y + m.z() * nf;
  }
  // The VNDF D_w(m) = G1(w) max(0, w.m) D(m) / (w.nf) per steradian of m.
  double visible_density(const Vec3& nf, const Vec3& w, const Vec3& m) const {
    const double wn = w.dot(nf), wm = w.dot(m), c = m.dot(nf);
    if (!(wn > 0.0) || !(wm > 0.0) || !(c > 0.0)) return 0.0;
    const double D = ggx::D(Vec3(std::sqrt(std::max(0.0, 1.0 - c * c)), 0.0, c), a_, a_);
    return D * wm / wn / (1.0 + lambda(wn));
  }

 private:
  static Vec3 tangent(const Vec3& n) {
    Vec3 t = Vec3(1.0, 0.0, 0.0) - n.x() * n;  // the fiber axis in n's tangent plane
    if (t.squaredNorm() < 1e-20) t = Vec3(0.0, 1.0, 0.0) - n.y() * n;
    return t.normalized();
  }
  double a_;
  HuangMasking masking_;
};

// ---- Paths -----------------------------------------------------------------------
// What a traced point reports. Weights are per channel (w[0..C)).
struct Sink {
  virtual ~Sink() = default;
  virtual void exit(int p, const Vec3& o, const double* w) = 0;
  virtual void residual(const double* w, double u1, double u2) = 0;
  virtual void lost(bool masked, const double* w) = 0;
  virtual void incident(double w) = 0;
  // Arrival inside at interface `p + 1` (after p + 1 segments) with travel
  // direction d; return false to stop there (density() takes over).
  virtual bool arrive(int, const Hit&, const Vec3&, const double*) { return true; }
};

// Which sides of an interface's normals a leaving direction must take:
// both the mesonormal's and the macro normal's (the paper), the macro
// normal's only, or none (form=cycles_eval, see Paths::branch).
enum class Sides { Both, Macro, None };

class Paths {
 public:
  Paths(const Huang2022Params& p, double theta_i, double phi_i)
      : p_(p), fiber_(p.eccentricity, p.tilt), surface_(p.roughness, p.masking),
        wi_(direction_from_angles(theta_i, phi_i)), cycles_residual_(p.residual == HuangResidual::CyclesEval),
        cycles_eval_(p.form == HuangForm::CyclesEval),
        cos_i_(std::cos(theta_i)),
        cycles_width_(fiber_.projected_width(wi_.y(), wi_.z()) * std::sqrt(p.eccentricity)),
        C_(static_cast<int>(p.sigma_a.size())) {}

  const Fiber& fiber() const { return fiber_; }
  const Surface& surface() const { return surface_; }
  const Vec3& wi() const { return wi_; }
  int channels() const { return C_; }
  double scale(int p) const { return p < kResidualP ? for_lobe(p_.lobe_scale, p) : 1.0; }
  const Huang2022Params& params() const { return p_; }

  // One point of the set, weight `base` (its share of the incident beam).
  void trace(const Point& pt, double base, Sink& sink) const {
    const double g = (pt.u[0] - 0.5) * kPi;
    const Vec3 d0 = -wi_;
    const Hit h = fiber_.entry(d0, g);
    const double macro = wi_.dot(h.n0), meso = wi_.dot(h.ns);
    // Share of the beam at this point: cos(g) dg / 2 of the projected width;
    // the paper's flux over the mesonormal scales it by (wi.ns)/(wi.n0).
    double w0 = base * 0.5 * kPi * std::cos(g);
    if (p_.mesonormal_flux) w0 *= std::max(0.0, meso) / macro;
    Weights w;
    for (int c = 0; c < C_; ++c) w.c[c] = w0;
    sink.incident(w0);
    if (!(macro > 0.0) || w0 == 0.0) return;
    if (!(meso > 0.0)) return sink.lost(false, w.c);  // macro flux only: no visible scale
    // Cycles' eval() (bsdf_hair_huang_eval) integrates over |h| <= 0.999 of
    // the projected width only, normalised by the whole width.
    if (cycles_eval_ && std::abs(std::sin(g)) > kCyclesEvalMaxImpact) return sink.lost(false, w.c);
    const Vec3 m = surface_.normal(h.ns, wi_, pt.u[1], pt.u[2]);
    const double ci = wi_.dot(m);
    const double F = fresnel_dielectric(ci, p_.eta);
    // R: reflection about m (Cycles' eval() tests its side of the macro
    // normal only).
    branch(0, d0, reflect(d0, m), h, +1, F, w, sink, [&](const Vec3& o, const double* wr) {
      sink.exit(0, o, wr);
    }, cycles_eval_ ? Sides::Macro : Sides::Both);
    // T: into the fiber.
    Vec3 t;
    if (!refract(d0, m, p_.eta, t)) return;
    // Cycles' eval() residual: this point's share of its arc integral,
    // (2 / pi) dgamma / (cos theta_i W), W the projected width with the
    // major axis 1 (Cycles' 2r), dgamma = pi base.
    const Entry entry{1.0 - F, 2.0 * base / (cos_i_ * cycles_width_)};
    branch(0, d0, t, h, -1, 1.0 - F, w, sink, [&](const Vec3& dt, const double* wt) {
      inside(pt, 1, h, dt, wt, sink, nullptr, 1.0, entry);
    });
  }

 private:
  // An event's outcome o (+1: stays on the arriving side, -1: crosses) with
  // probability `prob`: checks it leaves on its side of the mesonormal and
  // the macro normal (else stopped), applies the leaving masking, continues.
  // `side` of the arrival: the facing normals are side * ns, side * n0 with
  // side = +1 outside (arriving along d0 from outside) and -1 inside.
  // `sides` relaxes the check for Cycles' eval() (form=cycles_eval).
  template <class Next>
  void branch(int inside_events, const Vec3& d, const Vec3& o, const Hit& h, int cross,
              double prob, const Weights& w, Sink& sink, Next next, Sides sides = Sides::Both) const {
    const double side = inside_events == 0 ? 1.0 : -1.0;
    const Vec3 nf = side * h.ns, nm = side * h.n0;
    Weights wo, lost;
    const double on = o.dot(nf) * cross, om = o.dot(nm) * cross;
    const bool meso_ok = on > 0.0 || sides != Sides::Both, macro_ok = om > 0.0 || sides == Sides::None;
    if (!meso_ok || !macro_ok) {
      for (int c = 0; c < C_; ++c) lost.c[c] = w.c[c] * prob;
      if (prob > 0.0) sink.lost(false, lost.c);
      return;
    }
    const double g = surface_.leaving(-d.dot(nf), on);
    for (int c = 0; c < C_; ++c) {
      wo.c[c] = w.c[c] * prob * g;
      lost.c[c] = w.c[c] * prob * (1.0 - g);
    }
    if (g < 1.0) sink.lost(true, lost.c);
    if (prob > 0.0) next(o, wo.c);
  }

  // What Cycles' eval() residual takes from the entry: the Fresnel
  // transmittance T1 and the point's weight in its arc integral.
  struct Entry {
    double t1, weight;
  };

  // Segment k (1 or 2) from `from` along d with weight w, then the event at
  // its end. For k = 2: a1 the first segment's transmittance, t2 the Fresnel
  // transmittance of interface 2 (both for the residual).
  void inside(const Point& pt, int k, const Hit& from, const Vec3& d, const double* w, Sink& sink,
              const Weights* a1, double t2, const Entry& entry) const {
    Hit h;
    double len;
    Weights wa, a;
    for (int c = 0; c < C_; ++c) wa.c[c] = w[c];
    if (!fiber_.next(from, d, h, len)) return sink.lost(false, wa.c);
    const double ratio = cycles_eval_ ? cycles_eval_chord_ratio(from, h, d) : 1.0;
    for (int c = 0; c < C_; ++c) {
      a.c[c] = std::exp(-p_.sigma_a[c] * len);  // the chord's 3D length (SPEC s4)
      wa.c[c] *= a.c[c] * ratio;
    }
    if (!sink.arrive(k - 1, h, d, wa.c)) return;
    const Vec3 nf = -h.ns;
    const Vec3 wv = -d;
    if (!(wv.dot(nf) > 0.0)) return sink.lost(false, wa.c);  // the scale faces away
    const Vec3 m = surface_.normal(nf, wv, pt.u[2 * k + 1], pt.u[2 * k + 2]);
    const double F = fresnel_dielectric(wv.dot(m), 1.0 / p_.eta);
    // Out: order p = k.
    Vec3 t;
    if (refract(d, m, 1.0 / p_.eta, t)) {
      // Cycles' eval() lets TT light leave on either side of the exit's normals.
      const Sides sides = cycles_eval_ && k == 1 ? Sides::None : Sides::Both;
      branch(1, d, t, h, -1, 1.0 - F, wa, sink, [&](const Vec3& o, const double* wo) {
        sink.exit(k, o, wo);
      }, sides);
    }
    // Internal reflection: order k + 1 and beyond.
    const Vec3 r = reflect(d, m);
    if (k == 1) {
      if (cycles_residual_) cycles_eval_residual(pt, entry, F, a, sink);
      branch(1, d, r, h, +1, F, wa, sink, [&](const Vec3& dr, const double* wr) {
        inside(pt, 2, h, dr, wr, sink, &a, 1.0 - F, entry);
      });
      return;
    }
    if (cycles_residual_) {
      // The TRT path's reflection here carries no residual in this form.
      Weights gone;
      for (int c = 0; c < C_; ++c) gone.c[c] = wa.c[c] * F;
      return sink.lost(false, gone.c);
    }
    // k == 2: Cycles' residual for every p >= 3 from the weight reflected
    // here: the geometric series A_avg T_avg / (1 - A_avg (1 - T_avg)).
    branch(1, d, r, h, +1, F, wa, sink, [&](const Vec3&, const double* wr) {
      const double t_avg = std::max(1e-5, 0.5 * (t2 + (1.0 - F)));
      Weights e;
      for (int c = 0; c < C_; ++c) {
        const double a_avg = std::sqrt(a1->c[c] * a.c[c]);
        // 1 - A (1 - T) written (1 - A) + A T: no cancellation as T -> 1e-5 (white, trapped by TIR).
        e.c[c] = wr[c] * a_avg * t_avg / ((1.0 - a_avg) + a_avg * t_avg);
      }
      sink.residual(e.c, pt.u[7], pt.u[8]);
    });
  }

  // Cycles' eval() residual (bsdf_hair_huang_eval_trrt): at the second
  // interface, with R2 its Fresnel reflectance at the sampled normal and A
  // the first chord's transmittance, T1 R2^2 T_avg A^3 / (1 - A (1 - T_avg)),
  // T_avg = max(1 - R2, 1e-5), weighted by the point's share of the arc
  // integral (Entry), without masking or the light's flux onto the arc.
  // Cycles drops it where the reflection at this interface leaves on the
  // wrong side (and the exit direction lies inside that reflected
  // direction's refraction cone); here it is kept for every exit direction.
  // None when the TRT factor is 0 (Cycles evaluates it in the TRT branch).
  void cycles_eval_residual(const Point& pt, const Entry& entry, double r2, const Weights& a, Sink& sink) const {
    if (!(for_lobe(p_.lobe_scale, 2) > 0.0)) return;
    const double t_avg = std::max(1.0 - r2, 1e-5);
    Weights e;
    for (int c = 0; c < C_; ++c) {
      const double A = a.c[c];
      e.c[c] = entry.weight * entry.t1 * r2 * r2 * t_avg * A * A * A / ((1.0 - A) + A * t_avg);
    }
    sink.residual(e.c, pt.u[7], pt.u[8]);
  }

  // form=cycles_eval: the factor by which Cycles' eval() rescales the light
  // of a chord along d from interface `from` to interface `to`. Cycles
  // (bsdf_principled_hair_huang.h, bsdf_hair_huang_eval_residual) weights a
  // TT path by cos_mi1 / cos_mo1 times the exit's arc length per entry arc
  // angle, a TRT path also by cos_mi2 / cos_mo2 (cos_mo: the leaving
  // direction's cosine to the mesonormal of the interface it leaves, cos_mi:
  // the arriving one's at the next); the paper's transport carries the flux
  // onto the entry arc, and its last interface's VNDF holds 1 / cos_mi.
  // Parallel chords keep their flux through the cross-section, so the exit
  // arc per entry arc is (d.n0_from) / (d.n0_to), and per chord Cycles'
  // eval() is the paper's transport times (d.n0 / d.ns) at `from` and
  // (d.ns / d.n0) at `to` (SPEC s2's n0 and n_s; 1 without tilt). 0 where
  // the chord meets the mesonormal of `to` from behind (the path ends).
  static double cycles_eval_chord_ratio(const Hit& from, const Hit& to, const Vec3& d) {
    const double leave = d.dot(from.n0) / d.dot(from.ns), arrive = d.dot(to.ns) / d.dot(to.n0);
    return arrive > 0.0 && leave > 0.0 ? leave * arrive : 0.0;
  }

  const Huang2022Params& p_;
  Fiber fiber_;
  Surface surface_;
  Vec3 wi_;
  bool cycles_residual_, cycles_eval_;
  double cos_i_, cycles_width_;
  int C_;
};

// Runs every point of an n-point set through the paths.
void integrate(const Paths& paths, long n, Sink& sink) {
  const double base = 1.0 / static_cast<double>(n);
  Halton set(0, n, static_cast<std::uint64_t>(n));
  Point pt;
  for (long i = 0; i < n; ++i, set.advance()) {
    set.get(pt.u);
    paths.trace(pt, base, sink);
  }
}

// The coordinates (Point) the paths of `orders` read: R's the entry and
// interface 1's normal, TT's also interface 2's, TRT's interface 3's, the
// residual's its spread.
int coordinates_of(unsigned orders) {
  if (orders & 8u) return kDims;
  if (orders & 4u) return 7;
  if (orders & 2u) return 5;
  return 3;
}

// Points [first, end) of the set whose coordinate 0 is offset by half a
// cell of `cells` points (the midpoints of a `cells`-point set: a fixed
// quadrature_points = n is [0, n) with cells n); `orders`, what their paths
// follow (TracerT::trace).
struct PointRange {
  long first, end, cells;
  unsigned orders = huang_lanes::kAllOrders | huang_lanes::kLedger;
};

// The same points W at a time through the lanes' paths (huang2022_lanes.h),
// lane groups [first, end) of the range (point i0 = W g starts group g;
// r.first a multiple of W): deposit(exits, u) takes each group's exits (per
// unit share, the lanes' number type) and coordinates (double). The last
// group's lanes past point r.end - 1 carry weight 0 (their paths end at the entry).
template <class Tracer, class Deposit>
void integrate_lanes(const Tracer& tracer, const PointRange& r, long first, long end, Deposit&& deposit) {
  using B = typename Tracer::Batch;
  using T = typename B::value_type;
  constexpr int W = Tracer::kWidth;
  Halton set(static_cast<std::uint64_t>(first) * W, r.cells, static_cast<std::uint64_t>(r.end) + W);
  alignas(64) double u[kDims][W] = {};
  alignas(64) T ut[kDims][W], share[W];
  B ub[kDims];
  for (B& x : ub) x = B(0.0);
  typename Tracer::Exits exits;
  const int dims = coordinates_of(r.orders);  // (the others are not read)
  for (long i0 = first * W; i0 < end * W; i0 += W) {
    set.get_lanes<W>(u, dims);
    for (int l = 0; l < W; ++l) share[l] = i0 + l < r.end ? T(1) : T(0);
    for (int k = 0; k < dims; ++k) {
      for (int l = 0; l < W; ++l) ut[k][l] = static_cast<T>(u[k][l]);
      ub[k] = B::load_aligned(ut[k]);
    }
    tracer.trace(ub, B::load_aligned(share), exits, r.orders);
    deposit(exits, u);
  }
}

// The range in kPointBlocks contiguous blocks of lane groups, block b's
// exits handed to deposit(b, exits, u) for an accumulator of its own, which
// the caller sums in block order afterwards: the same numbers for any number of threads, which the
// atlas's bit-identity across threads, ranks and resumes needs. The blocks
// run on OpenMP threads unless the caller is already in a parallel region
// (compare's fits and predict_result run configurations in parallel; no
// nested team then).
constexpr int kPointBlocks = 16;
template <class Tracer, class Deposit>
void integrate_blocks(const Tracer& tracer, const PointRange& r, Deposit&& deposit) {
  constexpr long W = Tracer::kWidth;
  const long g0 = r.first / W, groups = (r.end + W - 1) / W - g0;
#pragma omp parallel for schedule(dynamic) if (!omp_in_parallel())
  for (int b = 0; b < kPointBlocks; ++b)
    integrate_lanes(tracer, r, g0 + groups * b / kPointBlocks, g0 + groups * (b + 1) / kPointBlocks,
                    [&](const auto& e, const auto* u) { deposit(b, e, u); });
}

// Bit l set where lane l of m is.
template <class M>
unsigned lane_bits(const M& m) {
#if defined(__AVX512F__)
  // AVX-512's masks are the bits themselves (8 doubles, 16 floats).
  if constexpr (M::size == 8 || M::size == 16) return static_cast<unsigned>(m.data);
#endif
  using B = typename M::batch_type;
  using T = typename B::value_type;
  alignas(64) T f[M::size];
  xsimd::select(m, B(1.0), B(0.0)).store_aligned(f);
  unsigned bits = 0;
  for (std::size_t l = 0; l < M::size; ++l) bits |= (f[l] != 0 ? 1u : 0u) << l;
  return bits;
}

// The sum of a vector's lanes in double (float lanes' weights are summed in
// double).
template <class B>
double sum_lanes(const B& x) {
  alignas(64) typename B::value_type a[B::size];
  x.store_aligned(a);
  double s = 0.0;
  for (std::size_t l = 0; l < B::size; ++l) s += static_cast<double>(a[l]);
  return s;
}

// The residual's inclination for the point (u1, u2): a von Mises-Fisher
// spread (kappa = 1/v) of the specular direction at inclination -theta_i,
// whose theta-marginal is d'Eon's M_p(v) (SPEC s3).
double residual_theta(double theta_i, double v, double u1, double u2) {
  if (v < kDeltaV) return -theta_i;
  const double c = std::clamp(1.0 + v * std::log(u1 + (1.0 - u1) * std::exp(-2.0 / v)), -1.0, 1.0);
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c)), b = kTwoPi * u2;
  // About the centre (sin(-theta_i), cos(theta_i), 0): the u component.
  const double ui = -std::sin(theta_i), ci = std::cos(theta_i);
  return std::asin(std::clamp(c * ui + s * std::cos(b) * ci, -1.0, 1.0));
}

int lobe_index(int p, int lobes) { return lobe_of(std::min(p, kResidualP), lobes); }

// The orders (huang_lanes::kAllOrders's bits) whose exits land in `lobe`.
unsigned orders_of_lobe(int lobe, int lobes) {
  unsigned orders = 0;
  for (int p = 0; p <= kResidualP; ++p)
    if (lobe_index(p, lobes) == lobe) orders |= 1u << p;
  return orders;
}

// Whether the model is symmetric under the mirror through the fiber axis u
// and the light's direction (relative azimuth phi -> -phi): that plane must
// be a symmetry plane of the cross-section, i.e. any plane on a circle and
// the planes of the ellipse's axes v (phi_i = 0, 180 deg) and w (+-90 deg)
// on an ellipse. The mirror keeps u, so the tilted mesonormal
// cos(tilt) n0 - sin(tilt) u maps to the mirrored point's, and isotropic
// GGX facets, Fresnel, masking and absorption are mirror-invariant.
bool mirror_symmetric(const Huang2022Params& p, double phi_i) {
  return p.eccentricity == 1.0 || std::abs(std::sin(2.0 * phi_i)) < 1e-12;
}

}  // namespace

Huang2022::Huang2022(Huang2022Params params) : params_(std::move(params)) {
  auto bad = [](const std::string& what) { throw Error("huang2022: " + what); };
  const Huang2022Params& p = params_;
  if (!(p.eta > 1.0) || !std::isfinite(p.eta)) bad(fmt::format("eta = {} must be > 1", p.eta));
  if (!(p.roughness >= 0.0 && p.roughness <= 1.0))
    bad(fmt::format("roughness = {} must be in [0, 1]", p.roughness));
  if (!(std::abs(p.tilt) < kPi / 4)) bad(fmt::format("tilt = {:g} deg must be in (-45, 45)", rad_to_deg(p.tilt)));
  if (!(p.eccentricity > 0.0 && p.eccentricity <= 1.0))
    bad(fmt::format("eccentricity = {} must be in (0, 1]", p.eccentricity));
  if (p.lobes < 1 || p.lobes > 4)
    bad(fmt::format("lobes = {} must be 1..4 (every order p >= 3 is one residual lobe)", p.lobes));
  if (p.sigma_a.empty() || p.sigma_a.size() > kMaxChannels) bad("sigma_a needs 1 to 8 channels");
  for (double s : p.sigma_a)
    if (!(s >= 0.0) || !std::isfinite(s)) bad(fmt::format("sigma_a = {} must be finite and >= 0", s));
  if (p.lobe_scale.empty()) bad("lobe_scale needs at least one value");
  for (double s : p.lobe_scale)
    if (!(s >= 0.0) || !std::isfinite(s)) bad(fmt::format("lobe_scale = {} must be finite and >= 0", s));
  if (p.quadrature_points != kAutoQuadraturePoints &&
      (p.quadrature_points < 1024 || p.quadrature_points > kMaxQuadraturePoints))
    bad(fmt::format("quadrature_points = {} must be auto or in [1024, 2^30]", p.quadrature_points));
  if (!(p.quadrature_photons >= 1.0) || !std::isfinite(p.quadrature_photons))
    bad(fmt::format("quadrature_photons = {} must be finite and >= 1", p.quadrature_photons));
}

namespace {

// The residual's share of each theta bin: the integral over the bin of its
// theta-marginal M_p(v, theta_i, theta_r) cos(theta_r) (d'Eon 2011 Eq. 7, the
// von Mises-Fisher spread's marginal: SPEC s3), by Gauss-Legendre on panels
// narrower than a third of the spread sqrt(v). Exact up to the rule's
// error (far below 1e-12 of the lobe), where sampling the spread by two
// more coordinates of the point set added their quadrature noise.
constexpr double kMinExactResidualV = 1e-6;  // below: the spread is sampled by the points
std::vector<double> residual_theta_masses(const BinGrid& grid, double theta_i, double v) {
  const GaussLegendre& gl = gauss_legendre(8);
  std::vector<double> mass(grid.n_theta(), 0.0);
  for (int i = 0; i < grid.n_theta(); ++i) {
    const double a = grid.theta_edges[i], b = grid.theta_edges[i + 1];
    const int panels = std::clamp(static_cast<int>(std::ceil((b - a) / (std::sqrt(v) / 3.0))), 1, 4096);
    const double h = (b - a) / panels;
    for (int k = 0; k < panels; ++k)
      for (std::size_t q = 0; q < gl.x.size(); ++q) {
        const double t = a + h * (k + 0.5 * (1.0 + gl.x[q]));
        mass[i] += 0.5 * h * gl.w[q] * std::exp(longitudinal::vmf_log_M_p(v, theta_i, t)) * std::cos(t);
      }
  }
  return mass;
}

// Bin probabilities: each exit lands in one bin; the residual's weight is
// spread over the theta bins by its M_p (or, for v below
// kMinExactResidualV, lands in the theta bin of its sampled inclination),
// evenly over phi (finish()).
//
// Where the model is mirror-symmetric (mirror_symmetric()), each exit lands
// half in its bin and half in the bin of its mirror image (relative azimuth
// -phi; done once after the points, finish(), as the average of every phi
// bin with its mirror bin): the mirrored path has the same weight and the same density, so
// this averages the push-forward of the point set and of its mirror image,
// an estimate of the same integral from twice the paths (its quadrature
// error about 1/sqrt(2) of the unmirrored one's at the same cost: measured
// in analytic/huang2022.h).
class BinSink : public Sink {
 public:
  BinSink(const Paths& paths, const BinGrid& grid, double theta_i, double phi_i, std::vector<double>& out)
      : paths_(paths), grid_(grid), theta_i_(theta_i), phi_i_(phi_i), out_(out),
        C_(paths.channels()), L_(paths.params().lobes), v_(4.0 * paths.params().roughness),
        mirror_(mirror_symmetric(paths.params(), phi_i)),
        residual_(static_cast<std::size_t>(grid.n_theta()) * C_, 0.0) {
    for (int p = 0; p < kResidualP; ++p) scale_[p] = paths.scale(p);
  }
  void exit(int p, const Vec3& o, const double* w) override { deposit(p, inclination(o), azimuth(o) - phi_i_, w); }
  // W points' exits and residuals (integrate_lanes), each point's weight
  // `share` times its Exits weight (summed in double). Each exit's bin as
  // BinGrid::theta_bin / phi_bin gives it for the lane's angles: the
  // closed-form index per lane (xsimd's asin and atan2, in the lanes'
  // arithmetic), and where a lane lies within near_edge() of an edge,
  // BinGrid's own rule on that lane's angles; each live lane deposited as
  // exit() does.
  template <class B>
  void lanes(const huang_lanes::ExitsT<B>& e, const double (*u)[B::size], double share) {
    using T = typename B::value_type;
    using M = typename B::batch_bool_type;
    constexpr int W = static_cast<int>(B::size);
    const int nt = grid_.n_theta(), np = grid_.n_phi();
    const bool uniform = grid_.theta_binning == ThetaBinning::Uniform;
    alignas(64) T at[W], ai[W], aj[W], w[kMaxChannels][W];
    // floor(g) clamped to [0, n - 1] into out (0 for a dead lane's NaN: its
    // offset below is computed, not used); the lanes near an integer.
    auto index = [](const B& g, int n, T* out) {
      const B f = xsimd::floor(g), r = g - f;
      xsimd::select(f >= B(0.0), xsimd::min(B(n - 1.0), f), B(0.0)).store_aligned(out);
      const B tol(near_edge<T>(n));
      return (r < tol) | (r > B(1.0) - tol);
    };
    for (int p = 0; p < kResidualP; ++p) {
      unsigned bits = lane_bits(e.live[p]);
      if (bits == 0) continue;
      const huang_lanes::V3T<B>& o = e.dir[p];
      const B x = xsimd::min(B(1.0), xsimd::max(B(-1.0), o.x));
      M near;
      if (uniform) {
        const B t = xsimd::asin(x);
        t.store_aligned(at);
        near = index((t + B(0.5 * kPi)) * B(nt / kPi), nt, ai);
      } else {
        x.store_aligned(at);  // asin only where a lane is near an edge
        near = index((x + B(1.0)) * B(0.5 * nt), nt, ai);
      }
      const B f = xsimd::atan2(o.z, o.y) - B(phi_i_);
      near = near | index((wrap(f) + B(kPi)) * B(np / kTwoPi), np, aj);
      unsigned settle = lane_bits(near);
      alignas(64) T phi[W];
      if (settle & bits) f.store_aligned(phi);
      // The lanes' weights in double and their bins' offsets in out_, for
      // all lanes at once (vectorised loops), then the live lanes deposited.
      const double s = scale_[p] * share;
      alignas(64) double wd[kMaxChannels][W];
      for (int c = 0; c < C_; ++c) {
        e.w[p][c].store_aligned(w[c]);
        for (int l = 0; l < W; ++l) wd[c][l] = s * static_cast<double>(w[c][l]);
      }
      const int lobe = lobe_index(p, L_);
      alignas(64) std::int64_t offset[W];
      const std::int64_t first = static_cast<std::int64_t>(lobe) * nt * np;
      for (int l = 0; l < W; ++l)
        offset[l] = (first + static_cast<std::int64_t>(ai[l]) * np + static_cast<std::int64_t>(aj[l])) * C_;
      for (; bits != 0; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        double* b = &out_[static_cast<std::size_t>(offset[l])];
        if (settle >> l & 1) {
          const double angle = at[l];
          b = bin(lobe, grid_.theta_bin(uniform ? angle : std::asin(angle)),
                  grid_.phi_bin(wrap_angle(static_cast<double>(phi[l]))));
        }
        for (int c = 0; c < C_; ++c) b[c] += wd[c][l];
      }
    }
    if (v_ >= kMinExactResidualV) {
      for (int c = 0; c < C_; ++c) residual_[c] += share * sum_lanes(e.residual[c]);
      return;
    }
    for (int c = 0; c < C_; ++c) e.residual[c].store_aligned(w[c]);
    for (int l = 0; l < W; ++l) {
      double wl[kMaxChannels];
      for (int c = 0; c < C_; ++c) wl[c] = share * static_cast<double>(w[c][l]);
      residual(wl, u[7][l], u[8][l]);
    }
  }
  // The distance to a bin edge, in bin widths, below which a lane's bin is
  // settled by BinGrid's rule: for doubles, the ulps by which xsimd's asin
  // and atan2 may differ from the C library's; for floats, the rounding of
  // the index g = (angle - lowest edge) n / range itself (a few float ulps
  // of g <= n).
  template <class T>
  static double near_edge(int n) {
    return std::is_same_v<T, float> ? 1e-6 * (n + 8) : 1e-9;
  }
  // wrap_angle() per lane: to [-pi, pi).
  template <class B>
  static B wrap(const B& a) {
    const B x = a + B(kPi);
    const B w = x - B(kTwoPi) * xsimd::floor(x * B(1.0 / kTwoPi)) - B(kPi);
    return xsimd::select(w >= B(kPi), B(-kPi), w);
  }
  void deposit(int p, double theta, double phi, const double* w) {
    const int i = grid_.theta_bin(theta), j = grid_.phi_bin(wrap_angle(phi));
    double* b = bin(lobe_index(p, L_), i, j);
    for (int c = 0; c < C_; ++c) b[c] += scale_[p] * w[c];
  }
  void residual(const double* w, double u1, double u2) override {
    const int i = v_ < kMinExactResidualV ? grid_.theta_bin(residual_theta(theta_i_, v_, u1, u2)) : 0;
    for (int c = 0; c < C_; ++c) residual_[static_cast<std::size_t>(i) * C_ + c] += w[c];
  }
  void lost(bool, const double*) override {}
  void incident(double) override {}
  // Adds another block's bins and residual (the same grid and model).
  void add(const BinSink& other) {
    for (std::size_t k = 0; k < out_.size(); ++k) out_[k] += other.out_[k];
    for (std::size_t k = 0; k < residual_.size(); ++k) residual_[k] += other.residual_[k];
  }
  // Spreads the residual (call once, after the points).
  void finish() {
    const int np = grid_.n_phi(), nt = grid_.n_theta();
    // The mirror image of phi bin j is bin np - 1 - j (the phi edges are
    // uniform on [-pi, pi), symmetric about 0).
    if (mirror_)
      for (int l = 0; l < L_; ++l)
        for (int i = 0; i < nt; ++i)
          for (int j = 0; j < np / 2; ++j) {
            double *a = bin(l, i, j), *b = bin(l, i, np - 1 - j);
            for (int c = 0; c < C_; ++c) a[c] = b[c] = 0.5 * (a[c] + b[c]);
          }
    std::vector<double> per_theta(residual_);
    if (v_ >= kMinExactResidualV) {
      const std::vector<double> mass = residual_theta_masses(grid_, theta_i_, v_);
      for (int i = 0; i < nt; ++i)
        for (int c = 0; c < C_; ++c) per_theta[static_cast<std::size_t>(i) * C_ + c] = residual_[c] * mass[i];
    }
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < np; ++j) {
        double* b = bin(lobe_index(kResidualP, L_), i, j);
        for (int c = 0; c < C_; ++c) b[c] += per_theta[static_cast<std::size_t>(i) * C_ + c] / np;
      }
  }

 private:
  double* bin(int lobe, int i, int j) {
    return &out_[((static_cast<std::size_t>(lobe) * grid_.n_theta() + i) * grid_.n_phi() + j) * C_];
  }
  const Paths& paths_;
  const BinGrid& grid_;
  double theta_i_, phi_i_;
  std::vector<double>& out_;
  int C_, L_;
  double v_;
  bool mirror_;
  double scale_[kResidualP];
  std::vector<double> residual_;  // per theta bin (sampled spread) or in row 0 (the total)
};

// to += from, term by term (the same model and channels).
void add_energies(HuangEnergies& to, const HuangEnergies& from) {
  for (std::size_t k = 0; k < to.lobe.size(); ++k) to.lobe[k] += from.lobe[k];
  for (std::size_t c = 0; c < to.masked.size(); ++c) {
    to.masked[c] += from.masked[c];
    to.stopped[c] += from.stopped[c];
  }
  to.incident += from.incident;
}

// Every term of e times f.
void scale_energies(HuangEnergies& e, double f) {
  for (double& x : e.lobe) x *= f;
  for (double& x : e.masked) x *= f;
  for (double& x : e.stopped) x *= f;
  e.incident *= f;
}

class EnergySink : public Sink {
 public:
  EnergySink(const Paths& paths, HuangEnergies& e) : paths_(paths), e_(e), C_(paths.channels()) {
    e_.lobe.assign(static_cast<std::size_t>(paths.params().lobes) * C_, 0.0);
    e_.masked.assign(C_, 0.0);
    e_.stopped.assign(C_, 0.0);
    e_.incident = 0.0;
  }
  void exit(int p, const Vec3&, const double* w) override { add(p, w, paths_.scale(p)); }
  void residual(const double* w, double, double) override { add(kResidualP, w, 1.0); }
  void lost(bool masked, const double* w) override {
    for (int c = 0; c < C_; ++c) (masked ? e_.masked : e_.stopped)[c] += w[c];
  }
  void incident(double w) override { e_.incident += w; }
  // W points' paths (integrate_lanes), each point's weight `share` times
  // its Exits weight: the same sums, in double.
  template <class B>
  void lanes(const huang_lanes::ExitsT<B>& x, double share) {
    for (int p = 0; p < kResidualP; ++p) add_lanes(p, x.w[p], paths_.scale(p) * share);
    add_lanes(kResidualP, x.residual, share);
    for (int c = 0; c < C_; ++c) {
      e_.masked[c] += share * sum_lanes(x.masked[c]);
      e_.stopped[c] += share * sum_lanes(x.stopped[c]);
    }
    e_.incident += share * sum_lanes(x.incident);
  }

 private:
  template <class B>
  void add_lanes(int p, const B* w, double s) {
    double* l = &e_.lobe[static_cast<std::size_t>(lobe_index(p, paths_.params().lobes)) * C_];
    for (int c = 0; c < C_; ++c) l[c] += s * sum_lanes(w[c]);
  }
  void add(int p, const double* w, double s) {
    double* l = &e_.lobe[static_cast<std::size_t>(lobe_index(p, paths_.params().lobes)) * C_];
    for (int c = 0; c < C_; ++c) l[c] += s * w[c];
  }
  const Paths& paths_;
  HuangEnergies& e_;
  int C_;
};

// density() for TT (stop_at 0) and TRT (stop_at 1): at that arrival the last
// interface is evaluated towards wr (the paper's last-interface evaluation):
// the VNDF density of the half vector of refraction m = (wr - eta d)/|.|
// times the Jacobian d(omega_m)/d(omega_r) = |wr.m| / (eta (w.m) + wr.m)^2
// (Walter et al. 2007, Eq. 17 with eta_o = 1), (1 - F) and the masking.
class LastInterfaceSink : public Sink {
 public:
  LastInterfaceSink(const Paths& paths, int stop_at, const Vec3& wr, std::vector<double>& out)
      : paths_(paths), stop_at_(stop_at), wr_(wr), out_(out) {}
  void exit(int, const Vec3&, const double*) override {}
  void residual(const double*, double, double) override {}
  void lost(bool, const double*) override {}
  void incident(double) override {}
  bool arrive(int k, const Hit& h, const Vec3& d, const double* w) override {
    if (k < stop_at_) return true;
    const double eta = paths_.params().eta;
    const Vec3 nf = -h.ns, wv = -d;
    const double wn = wv.dot(nf), on = wr_.dot(nf);
    // Cycles' eval() has no exit-side test for TT (form=cycles_eval).
    const bool any_side = stop_at_ == 0 && paths_.params().form == HuangForm::CyclesEval;
    if (!(wn > 0.0) || (!any_side && (!(on < 0.0) || !(wr_.dot(h.n0) > 0.0)))) return false;
    const Vec3 m = (wr_ - eta * d).normalized();
    const double om = wr_.dot(m), wm = wv.dot(m);
    if (!(om < 0.0) || !(wm > 0.0)) return false;
    const double F = fresnel_dielectric(wm, 1.0 / eta);
    if (F >= 1.0) return false;
    const double jac = -om / ((eta * wm + om) * (eta * wm + om));
    const double f = (1.0 - F) * paths_.surface().visible_density(nf, wv, m) * jac *
                     paths_.surface().leaving(wn, on);
    for (std::size_t c = 0; c < out_.size(); ++c) out_[c] += f * w[c];
    return false;
  }

 private:
  const Paths& paths_;
  int stop_at_;
  Vec3 wr_;
  std::vector<double>& out_;
};

// S_R(wi, wr) of the paper's R lobe: 1/(W cos theta_i) times the integral
// over the arc lit by wi and seen from wr of F(wi.h) D(h) G2 / 4 dl.
double r_lobe(const Paths& paths, const Vec3& wi, const Vec3& wr) {
  const Fiber& fb = paths.fiber();
  const Surface& sf = paths.surface();
  const Huang2022Params& p = paths.params();
  const Vec3 hv = (wi + wr).normalized();
  const double F = fresnel_dielectric(wi.dot(hv), p.eta);
  const double dt = kTwoPi / kArcNodes;
  // form=cycles_eval: the impact parameter across the projected width (unit
  // half width), which Cycles' eval() clamps (Paths::trace).
  const double bn = std::hypot(wi.y(), wi.z()), half = 0.5 * fb.projected_width(wi.y(), wi.z());
  const double across_v = -wi.z() / bn / half, across_w = wi.y() / bn / half;
  double sum = 0.0;
  for (int k = 0; k < kArcNodes; ++k) {
    const double t = (k + 0.5) * dt;
    const Hit h = fb.at(t);
    if (p.form == HuangForm::CyclesEval && std::abs(h.pv * across_v + h.pw * across_w) > kCyclesEvalMaxImpact)
      continue;
    const double in = wi.dot(h.ns), out = wr.dot(h.ns), c = hv.dot(h.ns);
    // Cycles' eval_r tests wr against the macro normal only (form=cycles_eval).
    const bool out_ok = out > 0.0 || p.form == HuangForm::CyclesEval;
    if (!(wi.dot(h.n0) > 0.0) || !(wr.dot(h.n0) > 0.0) || !(in > 0.0) || !out_ok || !(c > 0.0))
      continue;
    const double D = ggx::D(Vec3(std::sqrt(std::max(0.0, 1.0 - c * c)), 0.0, c), sf.alpha(), sf.alpha());
    const double G = sf.leaving(in, out) / (1.0 + sf.lambda(in));
    const double flux = p.mesonormal_flux ? 1.0 : wi.dot(h.n0) / in;
    sum += F * D * G / 4.0 * flux * fb.arc_per_dt(t) * dt;
  }
  const double cos_i = std::sqrt(wi.y() * wi.y() + wi.z() * wi.z());
  return sum / (fb.projected_width(wi.y(), wi.z()) * cos_i);
}

// Runs `scalar()` on the scalar Paths, or `lanes(tracer)` on the double or
// float lanes, as `choice` says (the float lanes unless told otherwise, and
// the scalar Paths where the lanes do not support p).
template <class Scalar, class Lanes>
void on_paths(HuangPaths choice, const Huang2022Params& p, double theta_i, double phi_i, Scalar&& scalar,
              Lanes&& lanes) {
  if (choice == HuangPaths::Scalar || !huang_lanes::FloatTracer::supports(p))
    scalar();
  else if (choice == HuangPaths::DoubleLanes)
    lanes(huang_lanes::DoubleTracer(p, theta_i, phi_i));
  else
    lanes(huang_lanes::FloatTracer(p, theta_i, phi_i));
}

// The lanes of `choice` (the double lanes where the scalar paths are chosen):
// the pilot of quadrature_points=auto needs the point set in blocks.
template <class Lanes>
void on_lanes(HuangPaths choice, const Huang2022Params& p, double theta_i, double phi_i, Lanes&& lanes) {
  on_paths(choice == HuangPaths::Scalar ? HuangPaths::DoubleLanes : choice, p, theta_i, phi_i, [] {}, lanes);
}

// ---- quadrature_points = auto ----------------------------------------------------
// The quadrature's error is measured as scripts/huang2022_quadrature_error.py
// and the atlas's bound do: per lobe and channel, the RMS over the bins
// holding at least 10 photons' weight of (error / SE), with SE^2 = (p2 -
// p^2) / N the variance of a bin of probability p in an N-photon simulation
// (N = quadrature_photons) whose photons carry their attenuation as weight
// (SPEC s4; S2, s6): p2, the mean of their squared weights, is the bin's probability
// at twice the absorption (the attenuation squared), which the pilot's
// points traced once more give; on a white fiber p2 = p. Masking (smith_g1)
// weights the photons, so p2 exceeds their mean squared weight by about the
// masking factor (tests/compare/test_huang2022_vs_simulation.cpp: the
// simulation's own variances are 0.89-0.95 of (p2 - p^2) / N). (p / N, the
// variance of unweighted photons, would overstate an absorbing fiber's
// standard errors by up to p / p2.) A pilot
// of the set's first 2^18 points, in the 16 blocks of integrate_blocks(),
// estimates it: block k's sum times 16 is one replicate of the pilot, so the
// spread of the 16 gives each bin's variance at 2^18 points. The blocks are
// segments of one Halton set, not independent replicates, and each is a worse
// point set than the whole, so the spread overstates the error rather than
// understating it (what auto's points give on the atlas's fibers:
// huang2022.h). The error falls as 1/sqrt(points) (a
// little faster: huang2022.h), so a lobe's points are the smallest multiple
// of 2^18 whose projected error is at most a tenth of a standard error in
// each of its channels (each lobe is judged on its own); the pilot's points
// are the first of every lobe's (the set's coordinate 0 offset by half a
// cell of 2^18 points, whatever the total).
constexpr long kPilotPoints = 1L << 18;
constexpr double kTargetErrorSE = 0.1;
constexpr double kMinPhotonsWeight = 10.0;  // bins holding at least this many photons' weight

// The points quadrature_points=auto takes for each of `groups` groups (a
// lobe and channel), from the pilot's kPointBlocks block sums (each point's
// weight 1, the pilot's estimate their sum over kPilotPoints; block k's
// times kPointBlocks a replicate of it) and the pilot's sums at twice the
// absorption (`squares`, the same entries): entry m belongs to group
// group(m). A group without a bin of kMinPhotonsWeight takes the pilot.
template <class Group>
std::vector<long> auto_points(const std::vector<std::vector<double>>& blocks, const std::vector<double>& squares,
                              int groups, Group&& group, double photons) {
  constexpr double K = kPointBlocks, kShare = 1.0 / kPilotPoints;
  std::vector<double> sum(groups, 0.0);
  std::vector<int> count(groups, 0);
  for (std::size_t m = 0; m < blocks[0].size(); ++m) {
    double mean = 0.0;
    for (const std::vector<double>& b : blocks) mean += b[m] * kShare;
    const double se2 = (squares[m] * kShare - mean * mean) / photons;
    if (!(mean * photons >= kMinPhotonsWeight) || !(se2 > 0.0)) continue;
    const int g = group(m);
    double ss = 0.0;
    for (const std::vector<double>& b : blocks) ss += (K * b[m] * kShare - mean) * (K * b[m] * kShare - mean);
    sum[g] += ss / (K * (K - 1.0)) / se2;  // (error / SE)^2 at the pilot
    ++count[g];
  }
  std::vector<long> points(groups, kPilotPoints);
  for (int g = 0; g < groups; ++g) {
    if (count[g] == 0) continue;
    // The group's mean squared error in SE^2 at the pilot, falling as 1 / points.
    const double needed = static_cast<double>(kPilotPoints) * (sum[g] / count[g]) / (kTargetErrorSE * kTargetErrorSE);
    const double pilots = std::max(1.0, std::ceil(needed / static_cast<double>(kPilotPoints)));
    if (pilots * kPilotPoints > static_cast<double>(kMaxQuadraturePoints))
      throw Error(fmt::format(
          "huang2022: quadrature_points=auto would need about {:.3g} points (at most 2^30) for a tenth of the "
          "standard error of {:g} photons; set quadrature_points to a number (error then above that bound) or a "
          "smaller quadrature_photons",
          needed, photons));
    points[g] = static_cast<long>(pilots) * kPilotPoints;
  }
  return points;
}

// Whether any channel absorbs.
bool absorbs(const Huang2022Params& p) {
  for (double s : p.sigma_a)
    if (s != 0.0) return true;
  return false;
}

// `p` at twice its absorption: its bins are the second moments of the
// simulated photons' weights (the attenuation squared).
Huang2022Params doubly_absorbing(Huang2022Params p) {
  for (double& s : p.sigma_a) s *= 2.0;
  return p;
}

// `p` with C more channels: its own C, then the same at twice the absorption
// (doubly_absorbing's).
Huang2022Params with_doubled_channels(const Huang2022Params& p) {
  Huang2022Params both = p;
  const std::vector<double> doubled = doubly_absorbing(p).sigma_a;
  both.sigma_a.insert(both.sigma_a.end(), doubled.begin(), doubled.end());
  return both;
}

// pilot(tracer, paths) for the fiber at twice its absorption, on the lanes
// of `choice`; nothing where no channel absorbs (p2 = p there).
template <class Pilot>
std::vector<double> at_twice_the_absorption(HuangPaths choice, const Huang2022Params& p, double theta_i,
                                            double phi_i, Pilot&& pilot) {
  std::vector<double> out;
  if (!absorbs(p)) return out;
  const Huang2022Params q = doubly_absorbing(p);
  const Paths paths(q, theta_i, phi_i);
  on_lanes(choice, q, theta_i, phi_i, [&](const auto& tracer) { out = pilot(tracer, paths); });
  return out;
}

// Entry m += the same entry of each block, in block order.
std::vector<double> sum_blocks(const std::vector<std::vector<double>>& blocks) {
  std::vector<double> out(blocks[0].size(), 0.0);
  for (const std::vector<double>& b : blocks)
    for (std::size_t m = 0; m < out.size(); ++m) out[m] += b[m];
  return out;
}

// Blocks of bins whose channels are C channels and then the same C at twice
// the absorption, made blocks of the first C; returns the sum over the
// blocks, in block order, of the other C.
std::vector<double> split_doubled_channels(std::vector<std::vector<double>>& blocks, int C) {
  const std::size_t size = blocks[0].size() / 2;
  std::vector<double> doubled(size, 0.0);
  for (std::vector<double>& b : blocks) {
    for (std::size_t e = 0; e < size / C; ++e)
      for (int c = 0; c < C; ++c) {
        doubled[e * C + c] += b[e * 2 * C + C + c];
        b[e * C + c] = b[e * 2 * C + c];  // (e C + c <= 2 e C + c: read before written)
      }
    b.resize(size);
  }
  return doubled;
}

// Per lobe, the most points of its channels' groups (lobe l's channel c is
// group l C + c).
std::vector<long> most_of_channels(const std::vector<long>& group_points, int lobes, int C) {
  std::vector<long> out(lobes, 0);
  for (int g = 0; g < lobes * C; ++g) out[g / C] = std::max(out[g / C], group_points[g]);
  return out;
}

// stretch(from, to, orders) for the points from `first` on that the lobes
// ask for (lobe l the points below lobe_points[l]), in stretches over which
// the same lobes take points, `orders` their exits (orders_of_lobe).
template <class Stretch>
void for_each_stretch(long first, const std::vector<long>& lobe_points, Stretch&& stretch) {
  const int lobes = static_cast<int>(lobe_points.size());
  for (long from = first;;) {
    long to = kMaxQuadraturePoints;
    unsigned orders = 0;
    for (int l = 0; l < lobes; ++l)
      if (lobe_points[l] > from) {
        to = std::min(to, lobe_points[l]);
        orders |= orders_of_lobe(l, lobes);
      }
    if (orders == 0) return;
    stretch(from, to, orders);
    from = to;
  }
}

}  // namespace

std::vector<double> Huang2022::bin_probabilities(const BinGrid& grid, double theta_i, double phi_i) const {
  const int C = static_cast<int>(params_.sigma_a.size());
  const std::size_t size = static_cast<std::size_t>(params_.lobes) * grid.n_theta() * grid.n_phi() * C;
  const Paths paths(params_, theta_i, phi_i);
  // Points `r` of `on`'s paths into kPointBlocks outputs, each point's weight
  // `share`, each block finished (mirror, residual spread) on its own
  // (`apart`), or the blocks summed into block 0 in block order and that finished.
  auto blocks_of = [&](const auto& tracer, const PointRange& r, double share, bool apart, const Paths& on) {
    const std::size_t n_out = static_cast<std::size_t>(on.params().lobes) * grid.n_theta() * grid.n_phi() *
                              on.params().sigma_a.size();
    std::vector<std::vector<double>> blocks(kPointBlocks, std::vector<double>(n_out, 0.0));
    std::deque<BinSink> sinks;
    for (std::vector<double>& o : blocks) sinks.emplace_back(on, grid, theta_i, phi_i, o);
    PointRange bins_only = r;  // (bins need no ledger)
    bins_only.orders &= ~huang_lanes::kLedger;
    integrate_blocks(tracer, bins_only, [&](int b, const auto& e, const auto* u) { sinks[b].lanes(e, u, share); });
    if (!apart)
      for (int b = 1; b < kPointBlocks; ++b) sinks[0].add(sinks[b]);
    for (int b = 0; b < (apart ? kPointBlocks : 1); ++b) sinks[b].finish();
    return blocks;
  };
  const long n = params_.quadrature_points;
  std::vector<double> out;
  if (n != kAutoQuadraturePoints) {
    on_paths(
        paths_, params_, theta_i, phi_i,
        [&] {
          out.assign(size, 0.0);
          BinSink sink(paths, grid, theta_i, phi_i, out);
          integrate(paths, n, sink);
          sink.finish();
        },
        [&](const auto& tracer) {
          out = std::move(blocks_of(tracer, {0, n, n}, 1.0 / static_cast<double>(n), false, paths)[0]);
        });
    return out;
  }
  // auto: the pilot's blocks finished one by one, then the points each lobe
  // asks for (the most of its channels') after them (the same set), in
  // stretches over which the same lobes take points, the paths following
  // only those lobes' orders; each of a lobe's points weighs 1 / its points
  // in the end. The standard errors need the second moment of the simulated
  // photons' weights in each bin: the pilot's points at twice the
  // absorption. Where the lanes hold twice the channels, these are C more
  // channels of the pilot's own paths (a channel's weights are apart from
  // the others' in the paths, so the first C are the pilot's alone, bit for
  // bit); else the pilot's points are traced once more.
  std::vector<std::vector<double>> pilot;
  std::vector<double> squares;
  if (absorbs(params_) && 2 * C <= huang_lanes::kMaxChannels) {
    const Huang2022Params both = with_doubled_channels(params_);
    const Paths paths_both(both, theta_i, phi_i);
    on_lanes(paths_, both, theta_i, phi_i, [&](const auto& tracer) {
      pilot = blocks_of(tracer, {0, kPilotPoints, kPilotPoints}, 1.0, true, paths_both);
    });
    squares = split_doubled_channels(pilot, C);
  } else {
    squares = at_twice_the_absorption(paths_, params_, theta_i, phi_i, [&](const auto& tracer, const Paths& on) {
      return blocks_of(tracer, {0, kPilotPoints, kPilotPoints}, 1.0, false, on)[0];
    });
  }
  on_lanes(paths_, params_, theta_i, phi_i, [&](const auto& tracer) {
    if (pilot.empty()) pilot = blocks_of(tracer, {0, kPilotPoints, kPilotPoints}, 1.0, true, paths);
    out = sum_blocks(pilot);
    if (squares.empty()) squares = out;  // no absorption: weights 0 or 1
    const std::size_t per_lobe = static_cast<std::size_t>(grid.n_theta()) * grid.n_phi() * C;
    const std::vector<long> points = auto_points(
        pilot, squares, params_.lobes * C,
        [&](std::size_t m) { return static_cast<int>(m / per_lobe) * C + static_cast<int>(m % C); },
        params_.quadrature_photons);
    const std::vector<long> lobe_points = most_of_channels(points, params_.lobes, C);
    for_each_stretch(kPilotPoints, lobe_points, [&](long from, long to, unsigned orders) {
      const std::vector<double> rest = blocks_of(tracer, {from, to, kPilotPoints, orders}, 1.0, false, paths)[0];
      for (std::size_t m = 0; m < size; ++m) out[m] += rest[m];
    });
    for (std::size_t m = 0; m < size; ++m) out[m] /= static_cast<double>(lobe_points[m / per_lobe]);
  });
  return out;
}

HuangEnergies Huang2022::energies(double theta_i, double phi_i) const {
  const Paths paths(params_, theta_i, phi_i);
  // Points `r` of `on`'s paths into kPointBlocks sums, each point's weight `share`.
  auto blocks_of = [&](const auto& tracer, const PointRange& r, double share, const Paths& on) {
    std::vector<HuangEnergies> blocks(kPointBlocks);
    std::deque<EnergySink> sinks;
    for (HuangEnergies& x : blocks) sinks.emplace_back(on, x);
    integrate_blocks(tracer, r, [&](int b, const auto& x, const auto*) { sinks[b].lanes(x, share); });
    return blocks;
  };
  // Block 0 plus the others, in block order.
  auto sum = [](const std::vector<HuangEnergies>& blocks) {
    HuangEnergies e = blocks[0];
    for (int b = 1; b < kPointBlocks; ++b) add_energies(e, blocks[b]);
    return e;
  };
  const long n = params_.quadrature_points;
  HuangEnergies e;
  if (n != kAutoQuadraturePoints) {
    on_paths(
        paths_, params_, theta_i, phi_i,
        [&] {
          EnergySink sink(paths, e);
          integrate(paths, n, sink);
        },
        [&](const auto& tracer) { e = sum(blocks_of(tracer, {0, n, n}, 1.0 / static_cast<double>(n), paths)); });
    return e;
  }
  // auto: the lobe energies as one bin each, then as bin_probabilities().
  std::vector<double> squares =
      at_twice_the_absorption(paths_, params_, theta_i, phi_i, [&](const auto& tracer, const Paths& on) {
        return sum(blocks_of(tracer, {0, kPilotPoints, kPilotPoints}, 1.0, on)).lobe;
      });
  on_lanes(paths_, params_, theta_i, phi_i, [&](const auto& tracer) {
    const std::vector<HuangEnergies> pilot = blocks_of(tracer, {0, kPilotPoints, kPilotPoints}, 1.0, paths);
    e = sum(pilot);
    if (squares.empty()) squares = e.lobe;  // no absorption: weights 0 or 1
    std::vector<std::vector<double>> lobes;
    for (const HuangEnergies& x : pilot) lobes.push_back(x.lobe);
    // (One count for every lobe: the furnace closes over the same paths.)
    const std::vector<long> each = auto_points(
        lobes, squares, static_cast<int>(lobes[0].size()), [](std::size_t m) { return static_cast<int>(m); },
        params_.quadrature_photons);
    const long points = *std::max_element(each.begin(), each.end());
    if (points > kPilotPoints)
      add_energies(e, sum(blocks_of(tracer, {kPilotPoints, points, kPilotPoints}, 1.0, paths)));
    scale_energies(e, 1.0 / static_cast<double>(points));
  });
  return e;
}

void Huang2022::density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
                        std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size()), L = params_.lobes;
  out.assign(C, 0.0);
  Huang2022Params q = params_;
  q.roughness = std::max(q.roughness, kMinDensityRoughness);
  const Paths paths(q, theta_i, phi_i);
  const Vec3 wi = paths.wi(), wr = direction_from_angles(theta_r, phi_i + phi);
  std::vector<double> s(C);
  for (int p = 0; p <= kResidualP; ++p) {
    if (lobe_index(p, L) != lobe) continue;
    std::fill(s.begin(), s.end(), 0.0);
    if (p == 0) {
      std::fill(s.begin(), s.end(), r_lobe(paths, wi, wr));
    } else if (p < kResidualP) {
      LastInterfaceSink sink(paths, p - 1, wr, s);
      integrate(paths, density_points_, sink);
    } else {
      // The residual: its energy times M_p(v = 4 alpha) / (2 pi) (Cycles).
      HuangEnergies e;
      EnergySink sink(paths, e);
      integrate(paths, density_points_, sink);
      const double m = std::exp(longitudinal::vmf_log_M_p(4.0 * q.roughness, theta_i, theta_r)) / kTwoPi;
      for (int c = 0; c < C; ++c) s[c] = e.lobe[static_cast<std::size_t>(lobe) * C + c] * m;
    }
    const double scale = paths.scale(p) * std::cos(theta_r);
    for (int c = 0; c < C; ++c) out[c] += scale * s[c];
  }
}

std::unique_ptr<Model> make_huang2022(const Huang2022Params& params) {
  return std::make_unique<Huang2022>(params);
}

namespace {

std::vector<std::string> huang_approximations(const Huang2022Params& p) {
  std::vector<std::string> a = {
      "far field: Cycles' wi read as our wi (the light); S normalised by the light's projected width",
      "TT, TRT: the paper's sampled microfacet normals as a fixed Halton point set (deterministic quadrature)",
      "no GGX glass albedo correction (Cycles' energy_scale table)"};
  if (p.residual == HuangResidual::CyclesEval)
    a.push_back("p >= 3: the residual of Cycles' eval() (T1 R2^2 T_avg A^3 / (1 - A (1 - T_avg)) from the second "
                "interface, uniform over the arc angle; kept for every exit direction where Cycles drops it inside a "
                "refraction cone when the second reflection leaves its side), M_p with v = 4 alpha, uniform in phi");
  else
    a.push_back("p >= 3: the residual of Cycles' sampler (geometric series from the TRT path, M_p with v = 4 alpha, "
                "uniform in phi), not Cycles' eval()'s");
  const bool cycles_eval = p.form == HuangForm::CyclesEval;
  if (p.mesonormal_flux)
    a.push_back(cycles_eval ? "flux onto the mesonormal (wi.ns) at the entry: not the projected width's once tilted "
                              "(paper, Cycles' eval())"
                            : "flux onto the mesonormal (wi.ns) at the entry: not the projected width's once tilted "
                              "(paper; Cycles' eval() also rescales at the inner interfaces: form=cycles_eval)");
  if (p.masking == HuangMasking::Correlated)
    a.push_back("masking: height-correlated G2 (Cycles' code)");
  if (cycles_eval) {
    a.push_back("form=cycles_eval: Cycles' eval() transport: each inner chord's light rescaled by (d.n0/d.ns) at the "
                "interface it leaves and (d.ns/d.n0) at the one it meets (not energy-conserving once tilted); TT exits "
                "not tested against the exit's normals; R's exit tested against the macro normal only; only impact "
                "parameters |h| <= 0.999 of the projected width, normalised by the whole width");
    a.push_back("form=cycles_eval: not reproduced: R's half vectors behind the mesonormal (Cycles' D counts them), "
                "TT where the exit's mesonormal faces away from the chord (Cycles still evaluates it), Cycles' zero "
                "for exits with tan(tilt) tan(theta_r) > 1, its roughness floor 1e-3 (bins), the Monte Carlo-Simpson "
                "quadrature itself");
    if (p.masking != HuangMasking::Correlated || !p.mesonormal_flux || p.residual != HuangResidual::CyclesEval)
      a.push_back("form=cycles_eval with masking, flux or residual not Cycles' eval()'s: not Cycles as shipped");
  }
  return a;
}

// The GGX alpha of a simulated fiber (ModelInfo::from_fiber). The model's
// facets are isotropic GGX with alpha in [0, 1]: a fiber it cannot represent
// is refused, naming the field and what is allowed; an approximate rule is
// noted in `mapping`.
double huang_roughness(const PhysicalFiber& f, FiberMapping& mapping) {
  auto refuse = [&](const std::string& why) -> double {
    throw Error(fmt::format("model huang2022: roughness: {}; huang2022 allows a smooth or isotropic ggx fiber "
                            "(alpha in [0, 1]), or --set roughness=A",
                            why));
  };
  // Every roughness type has its rule here: a type without one does not compile.
  const double alpha = std::visit(
      [&](const auto& g) -> double {
        using G = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<G, roughness::Smooth>) {
          return 0.0;
        } else if constexpr (std::is_same_v<G, roughness::ExitBlur>) {
          return refuse("an exit_blur fiber has no microfacets");
        } else if constexpr (std::is_base_of_v<roughness::MicrofacetAlpha, G>) {
          if (g.alpha_long != g.alpha_azim)
            return refuse(fmt::format("{} is anisotropic (huang2022's GGX is isotropic)", f.roughness_text()));
          if constexpr (std::is_same_v<G, roughness::Beckmann>)
            // Beckmann and GGX of the same alpha have the same density at the
            // mean normal, D = 1/(pi alpha^2) (Walter et al. 2007, Eqs. 25, 33).
            mapping.notes.push_back(fmt::format(
                "roughness: the {} fiber read as ggx of the same alpha (equal density at the mean normal; the "
                "tails differ)",
                f.roughness_text()));
          return g.alpha_long;
        } else {
          static_assert(std::is_same_v<G, roughness::Gaussian>, "a roughness type without a rule");
          if (g.beta_long != g.beta_azim)
            return refuse(fmt::format("{} is anisotropic (huang2022's GGX is isotropic)", f.roughness_text()));
          // Equal density at the mean normal: a Gaussian tilt of sd beta per
          // axis has slope density 1/(2 pi tan^2 beta) there, GGX 1/(pi alpha^2).
          const double a = std::sqrt(2.0) * std::tan(g.beta_long);
          mapping.notes.push_back(fmt::format(
              "roughness: the {} fiber read as ggx alpha = sqrt(2) tan(beta) = {:g} (equal density at the mean "
              "normal)",
              f.roughness_text(), a));
          return a;
        }
      },
      f.roughness);
  if (!(alpha >= 0.0 && alpha <= 1.0))
    return refuse(fmt::format("{} gives alpha = {:g}, outside [0, 1]", f.roughness_text(), alpha));
  return alpha;
}

// The rule from a simulated fiber (physical_defaults.h): eccentricity and
// tilt themselves, the roughness by huang_roughness() unless --set, the
// quadrature sized for the simulation's photons.
void huang2022_from_fiber(const PhysicalFiber& f, Huang2022Params& p, FiberMapping& mapping) {
  apply_fiber_basics(f, p);
  p.eccentricity = f.eccentricity;
  p.tilt = f.scale_tilt;
  if (!mapping.user_sets("roughness")) p.roughness = huang_roughness(f, mapping);
  if (f.photons > 0 && !mapping.user_sets("quadrature_photons")) p.quadrature_photons = static_cast<double>(f.photons);
}

// quadrature_points: "auto" or an integer in [1024, 2^30] (a number in files,
// the text "auto" for auto).
ParamSpec quadrature_points_param() {
  using P = Huang2022Params;
  const std::string key = "quadrature_points", allowed = "auto or an integer in [1024, 1073741824]";
  ParamSpec s = param_detail::blank_spec(
      key,
      "points of the Halton quadrature (bins, energies); auto: as many as make its estimated error a tenth of the "
      "standard error of quadrature_photons photons (a multiple of 2^18, per incident direction, from a pilot of 2^18)",
      "integer", "auto", allowed);
  auto ok = [](double x) { return x == std::floor(x) && x >= 1024.0 && x <= static_cast<double>(kMaxQuadraturePoints); };
  s.set = [key, allowed, ok](ModelParameters& p, const std::string& value) {
    double x;
    if (param_detail::trim(value) == "auto")
      p.as<P>().quadrature_points = kAutoQuadraturePoints;
    else if (param_detail::parse_double(value, x) && ok(x))
      p.as<P>().quadrature_points = static_cast<long>(x);
    else
      param_detail::fail(key, value, allowed);
  };
  auto is_auto = [](const ModelParameters& p) { return p.as<P>().quadrature_points == kAutoQuadraturePoints; };
  s.show = [is_auto](const ModelParameters& p) {
    return is_auto(p) ? std::string("auto") : std::to_string(p.as<P>().quadrature_points);
  };
  s.in_range = [is_auto, ok](const ModelParameters& p) {
    return is_auto(p) || ok(static_cast<double>(p.as<P>().quadrature_points));
  };
  s.attribute = [key, is_auto](const ModelParameters& p) {
    if (is_auto(p)) return ParamAttribute{key, true, "auto", {}};
    return ParamAttribute{key, false, "", {static_cast<double>(p.as<P>().quadrature_points)}};
  };
  return s;
}

}  // namespace

ModelInfo huang2022_info() {
  using P = Huang2022Params;
  ModelDefinition<P> m;
  m.name = "huang2022";
  m.reference =
      "Huang, Hullin, Hanika 2022, A Microfacet-based Hair Scattering Model (Cycles' Principled Hair "
      "Huang), far field";
  ParamSpec roughness = number_param("roughness", "GGX microfacet roughness alpha about the mesonormal (0: smooth)",
                                     "", "0.3", "a number in [0, 1]", &P::roughness,
                                     [](double x) { return x >= 0.0 && x <= 1.0; });
  roughness.from_fiber =
      "roughness (smooth: 0; ggx: alpha; beckmann: alpha, approximate; gaussian: sqrt(2) tan(beta), approximate; "
      "an anisotropic fiber or exit_blur is refused unless --set roughness)";
  ParamSpec tilt = number_param("tilt",
                                "cuticle scale tilt of the mesonormal, > 0 towards the root as fiber.scale_tilt "
                                "(Cycles' Huang Tilt)",
                                "deg", "0", "degrees in (-45, 45)", &P::tilt,
                                [](double x) { return std::abs(x) < 45.0; });
  tilt.from_fiber = "fiber.scale_tilt";
  ParamSpec ecc = eccentricity_param<P>();
  ecc.meaning = "minor/major axis ratio of the ellipse (Cycles' aspect ratio)";
  ParamSpec scale = list_param("lobe_scale", "factors of the R, TT, TRT lobes (Cycles' modulation; 1 = physical)",
                               "", "1,1,1", "a comma list of numbers >= 0 (R, TT, TRT)", &P::lobe_scale,
                               [](double x) { return x >= 0.0; });
  ParamSpec form = choice_param<P>(
      "form",
      "transport: paper (the paper's, Cycles' sampler's; masking, flux, residual as set) or cycles_eval (Cycles' "
      "eval() as shipped: inner chords rescaled by mesonormal cosine ratios, TT exits unchecked, R checked against "
      "the macro normal only, impact parameters |h| <= 0.999; also sets masking=correlated, flux=mesonormal, "
      "residual=cycles_eval, which later keys may change)",
      "paper", {"paper", "cycles_eval"},
      [](P& p, int i) {
        p.form = static_cast<HuangForm>(i);
        if (p.form == HuangForm::CyclesEval) {
          p.masking = HuangMasking::Correlated;
          p.mesonormal_flux = true;
          p.residual = HuangResidual::CyclesEval;
        }
      },
      [](const P& p) { return static_cast<int>(p.form); });
  ParamSpec masking = enum_param(
      "masking",
      "Smith masking: separable G1(i) G1(o) (the paper's ground truth, simulator smith_g1); correlated "
      "1/(1 + L_i + L_o) (Cycles); none (no masking of leaving light)",
      "separable", {"separable", "correlated", "none"}, &P::masking);
  ParamSpec flux = choice_param<P>(
      "flux", "light reaching the arc: mesonormal (wi.ns) dl (paper; Cycles' eval at the entry) or macro (wi.n0) dl "
      "(Cycles' sampler)",
      "mesonormal", {"mesonormal", "macro"},
      [](P& p, int i) { p.mesonormal_flux = i == 0; },
      [](const P& p) { return p.mesonormal_flux ? 0 : 1; });
  ParamSpec residual = enum_param(
      "residual",
      "p >= 3: sampler (Cycles' sampler: the series from the TRT path's third interface) or cycles_eval (Cycles' "
      "eval(): T1 R2^2 T_avg A^3 / (1 - A (1 - T_avg)) from the second interface, uniform over the arc angle)",
      "sampler", {"sampler", "cycles_eval"}, &P::residual);
  ParamSpec points = quadrature_points_param();
  ParamSpec photons = number_param(
      "quadrature_photons",
      "the photons whose standard error quadrature_points=auto sizes the quadrature for (a tenth of it)", "", "300000",
      "a finite number >= 1", &P::quadrature_photons, [](double x) { return std::isfinite(x) && x >= 1.0; });
  photons.from_fiber = "photons (the simulation's, per incident direction)";
  // Free parameters (what `fiberlab atlas` fits): the roughness and the tilt, in their ranges.
  m.params = {eta_param<P>(), sigma_a_param<P>(), fittable(roughness, 0.0, 1.0), fittable(tilt, -45.0 + 1e-6, 45.0 - 1e-6),
              ecc,            scale,              form,               masking,
              flux,           residual,           lobes_param<P>(), points,
              photons};
  m.make = [](const P& p) { return make_huang2022(p); };
  m.approximations = huang_approximations;
  m.from_fiber = huang2022_from_fiber;
  // The tilt is the fiber's cuticle tilt (same sign as scale_tilt): SPEC s7's
  // shifts of it (rays through the fiber's centre), as for the simulator.
  m.theta_r_shifts = [](const P& p) { return tilt_shifts(p.tilt); };
  return define_model(std::move(m));
}

}  // namespace fiberlab::analytic
