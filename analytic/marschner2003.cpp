// Marschner et al. 2003, section 4 (smooth circle) and section 5 (the practical
// model). Equation and section numbers refer to that paper; see marschner2003.h
// for the conventions and for the readings chosen where the PDF text is garbled.
#include "analytic/marschner2003.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/core.h>
#include <xsimd/xsimd.hpp>

#include "analytic/cylinder_paths.h"
#include "analytic/model_registry.h"
#include "analytic/quadrature.h"
#include "common/error.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace marschner2003 {
namespace {

constexpr double kPi3 = kPi * kPi * kPi;
// Smallest |dphi/dgamma| used in Eq. 8: the fold of Phi (the caustic) has a
// zero derivative and an integrable infinite density; we keep it finite.
constexpr double kMinSlope = 1e-10;

double clamp1(double x) { return std::clamp(x, -1.0, 1.0); }

// Snell's law in the normal plane (Bravais): sin(gamma_t) = sin(gamma_i) / eta'.
double gamma_t_exact(double gamma_i, double eta_p) {
  return std::asin(clamp1(std::sin(gamma_i) / eta_p));
}

// c = asin(1/eta') of section 5.2.1.
double c_of(double eta_p) { return std::asin(clamp1(1.0 / eta_p)); }

// Real roots of x^3 + P x + Q = 0 (depressed cubic), appended to `out`.
void depressed_cubic_roots(double P, double Q, std::vector<double>& out) {
  const double disc = Q * Q / 4.0 + P * P * P / 27.0;
  if (P >= 0.0 || disc > 0.0) {
    // One real root (Cardano).
    const double s = std::sqrt(std::max(disc, 0.0));
    out.push_back(std::cbrt(-Q / 2.0 + s) + std::cbrt(-Q / 2.0 - s));
  } else {
    // Three real roots (trigonometric form; P < 0 here).
    const double r = 2.0 * std::sqrt(-P / 3.0);
    const double arg = clamp1(3.0 * Q / (2.0 * P) * std::sqrt(-3.0 / P));
    const double t = std::acos(arg) / 3.0;
    for (int k = 0; k < 3; ++k) out.push_back(r * std::cos(t - 2.0 * kPi * k / 3.0));
  }
}

// 1 - smoothstep: 1 for x < a, 0 for x > b, smooth (cubic Hermite) between
// (section 5.2.2: "smoothstep(a, b, x) is 1 for x < a, 0 for x > b").
double fade(double a, double b, double x) {
  if (x <= a) return 1.0;
  if (x >= b) return 0.0;
  const double s = (x - a) / (b - a);
  return 1.0 - s * s * (3.0 - 2.0 * s);
}

template <class T>
double at_p(const std::vector<T>& v, int p, const char* name) {
  if (v.empty()) throw Error(fmt::format("marschner2003: parameter {} is an empty list", name));
  return v[std::min<std::size_t>(static_cast<std::size_t>(p), v.size() - 1)];
}

}  // namespace

// ---- Appendix B ---------------------------------------------------------------

double eta_prime(double eta, double theta) { return cylinder::eta_prime(eta, theta); }

double eta_double_prime(double eta, double theta) {
  const double s = std::sin(theta);
  return eta * eta * std::cos(theta) / std::sqrt(eta * eta - s * s);
}

namespace {
// F of Appendix B from sin(gamma) and |cos(gamma)| (N_p_bins has both).
double F_of(double eta_p, double eta_pp, double sin_gamma, double cos_i) {
  const double sin_t = sin_gamma / eta_p;
  if (std::abs(sin_t) >= 1.0) return 1.0;  // total internal reflection
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double r_s = (cos_i - eta_p * cos_t) / (cos_i + eta_p * cos_t);
  const double r_p = (eta_pp * cos_i - cos_t) / (eta_pp * cos_i + cos_t);
  return 0.5 * (r_s * r_s + r_p * r_p);
}
}  // namespace

double F(double eta_p, double eta_pp, double gamma) {
  return F_of(eta_p, eta_pp, std::sin(gamma), std::abs(std::cos(gamma)));
}

// ---- Eq. 3, Eq. 10 ------------------------------------------------------------

// Eq. 3 and its derivative: the one cylinder module's.
double Phi(int p, double gamma_i, double eta_p) { return cylinder::Phi(p, gamma_i, eta_p); }

double dPhi_dgamma(int p, double gamma_i, double eta_p) { return cylinder::dPhi_dgamma(p, gamma_i, eta_p); }

double gamma_t_cubic(double gamma_i, double eta_p) {
  const double c = c_of(eta_p);
  return 3.0 * c / kPi * gamma_i - 4.0 * c / kPi3 * gamma_i * gamma_i * gamma_i;
}

double Phi_cubic(int p, double gamma_i, double eta_p) {
  const double c = c_of(eta_p);
  return (6.0 * p * c / kPi - 2.0) * gamma_i - 8.0 * p * c / kPi3 * gamma_i * gamma_i * gamma_i +
         p * kPi;
}

double dPhi_cubic_dgamma(int p, double gamma_i, double eta_p) {
  const double c = c_of(eta_p);
  return (6.0 * p * c / kPi - 2.0) - 24.0 * p * c / kPi3 * gamma_i * gamma_i;
}

std::vector<double> gamma_roots_cubic(int p, double phi, double eta_p) {
  std::vector<double> roots;
  const double half_pi = 0.5 * kPi;
  const double c = c_of(eta_p);
  const double b = 6.0 * p * c / kPi - 2.0;  // linear coefficient
  const double a = -8.0 * p * c / kPi3;      // cubic coefficient (<= 0)
  // Phi_cubic over [-pi/2, pi/2] lies within p pi -/+ (|b| + |a| pi^3/8) pi/2...;
  // try every 2 pi branch of the target that can reach it.
  const double reach = std::abs(b) * half_pi + std::abs(a) * half_pi * half_pi * half_pi;
  const int k_lo = static_cast<int>(std::floor((p * kPi - reach - phi) / kTwoPi));
  const int k_hi = static_cast<int>(std::ceil((p * kPi + reach - phi) / kTwoPi));
  std::vector<double> cand;
  for (int k = k_lo; k <= k_hi; ++k) {
    const double target = phi + kTwoPi * k;
    const double d = p * kPi - target;  // a x^3 + b x + d = 0
    cand.clear();
    if (p == 0 || a == 0.0) {
      if (b != 0.0) cand.push_back(-d / b);
    } else {
      depressed_cubic_roots(b / a, d / a, cand);
    }
    for (double x : cand) {
      // Two Newton steps polish the closed form (cancellation near folds).
      for (int it = 0; it < 2 && p > 0; ++it) {
        const double f = a * x * x * x + b * x + d;
        const double df = 3.0 * a * x * x + b;
        if (std::abs(df) > 1e-8) x -= f / df;
      }
      if (x >= -half_pi - 1e-12 && x <= half_pi + 1e-12)
        roots.push_back(std::clamp(x, -half_pi, half_pi));
    }
  }
  std::sort(roots.begin(), roots.end());
  return roots;
}

std::vector<double> gamma_roots_exact(int p, double phi, double eta_p) {
  std::vector<double> roots;
  const double half_pi = 0.5 * kPi;
  // Monotonic pieces of Phi(p, .): dPhi/dgamma = 0 where
  // (p^2 - 1) cos^2 gamma = eta'^2 - 1 (Eq. 4 for p = 2).
  std::vector<double> knots{-half_pi};
  if (p >= 2) {
    const double cos2 = (eta_p * eta_p - 1.0) / (p * p - 1.0);
    if (cos2 < 1.0) {
      const double gc = std::acos(std::sqrt(std::max(cos2, 0.0)));
      knots.push_back(-gc);
      knots.push_back(gc);
    }
  }
  knots.push_back(half_pi);
  for (std::size_t piece = 0; piece + 1 < knots.size(); ++piece) {
    const double lo = knots[piece], hi = knots[piece + 1];
    const double f_lo = Phi(p, lo, eta_p), f_hi = Phi(p, hi, eta_p);
    const double f_min = std::min(f_lo, f_hi), f_max = std::max(f_lo, f_hi);
    const int k_lo = static_cast<int>(std::ceil((f_min - phi) / kTwoPi));
    const int k_hi = static_cast<int>(std::floor((f_max - phi) / kTwoPi));
    for (int k = k_lo; k <= k_hi; ++k) {
      const double target = phi + kTwoPi * k;
      // Newton safeguarded by bisection on a monotonic piece: the bracket keeps
      // it robust next to the fold, where dPhi/dgamma -> 0 and Newton alone
      // overshoots.
      double a = lo, b = hi;
      const bool increasing = f_hi > f_lo;
      double x = (f_hi == f_lo) ? 0.5 * (lo + hi)
                                : lo + (hi - lo) * std::clamp((target - f_lo) / (f_hi - f_lo), 0.0, 1.0);
      for (int it = 0; it < 100 && b - a > 1e-15; ++it) {
        const double r = Phi(p, x, eta_p) - target;
        if (r == 0.0) { a = b = x; break; }
        if ((r < 0.0) == increasing) a = x; else b = x;
        const double d = dPhi_dgamma(p, x, eta_p);
        double next = (d != 0.0) ? x - r / d : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        if (std::abs(next - x) < 1e-15) { x = next; break; }
        x = next;
      }
      roots.push_back(std::clamp(x, lo, hi));
    }
  }
  std::sort(roots.begin(), roots.end());
  return roots;
}

// ---- Section 4.3 --------------------------------------------------------------

double T(double sigma_a_prime, double gamma_t, Absorption absorption) {
  // Section 4.3 (published) or the chord: the one cylinder module's.
  return cylinder::segment_transmittance(sigma_a_prime, std::cos(gamma_t), absorption);
}

namespace {
// The part of A(p, h) that is the same for every channel: its Fresnel
// factors and the refraction angle the attenuation T needs.
struct PathFresnel {
  double fresnel;      // A(0) = F(eta', eta'', gamma_i); p > 0: (1 - F_in)^2 F_out^(p-1)
  double cos_gamma_t;  // cos(gamma_t), sin(gamma_t) = h / eta' (p > 0)
};
PathFresnel path_fresnel(int p, double gamma_i, double eta_p, double eta_pp) {
  const double f_in = F(eta_p, eta_pp, gamma_i);
  if (p == 0) return {f_in, 0.0};
  const double gamma_t = gamma_t_exact(gamma_i, eta_p);
  const double f_out = F(1.0 / eta_p, 1.0 / eta_pp, gamma_t);
  return {(1.0 - f_in) * (1.0 - f_in) * std::pow(f_out, p - 1), std::cos(gamma_t)};
}
// A(p, h) from its channel-independent part and one channel's sigma_a'.
double A_of(int p, const PathFresnel& pf, double sigma_a_prime, Absorption absorption) {
  if (p == 0) return pf.fresnel;
  return pf.fresnel * std::pow(cylinder::segment_transmittance(sigma_a_prime, pf.cos_gamma_t, absorption), p);
}
}  // namespace

double A(int p, double gamma_i, double eta_p, double eta_pp, double sigma_a_prime,
         Absorption absorption) {
  return A_of(p, path_fresnel(p, gamma_i, eta_p, eta_pp), sigma_a_prime, absorption);
}

Projection project(double eta, double theta, bool exact_roots, Absorption absorption) {
  Projection proj;
  proj.eta = eta;
  proj.theta = theta;
  proj.eta_p = eta_prime(eta, theta);
  proj.eta_pp = eta_double_prime(eta, theta);
  const double s = std::sin(theta) / eta;
  proj.cos_theta_t = std::sqrt(1.0 - s * s);
  proj.exact_roots = exact_roots;
  proj.absorption = absorption;
  return proj;
}

// ---- Eq. 8 --------------------------------------------------------------------

void N_p(int p, double phi, const Projection& proj, const std::vector<double>& sigma_a,
         std::vector<double>& out) {
  out.assign(sigma_a.size(), 0.0);
  const std::vector<double> roots = proj.exact_roots ? gamma_roots_exact(p, phi, proj.eta_p)
                                                     : gamma_roots_cubic(p, phi, proj.eta_p);
  for (double gamma_i : roots) {
    // |2 dphi/dh|^-1 = cos(gamma_i) / |2 dphi/dgamma_i| (h = sin gamma_i).
    const double slope = proj.exact_roots ? dPhi_dgamma(p, gamma_i, proj.eta_p)
                                          : dPhi_cubic_dgamma(p, gamma_i, proj.eta_p);
    const double jac = std::cos(gamma_i) / (2.0 * std::max(std::abs(slope), kMinSlope));
    // A(p, h): its Fresnel factors once for every channel.
    const PathFresnel pf = path_fresnel(p, gamma_i, proj.eta_p, proj.eta_pp);
    for (std::size_t ch = 0; ch < sigma_a.size(); ++ch) {
      const double sigma_prime = sigma_a[ch] / proj.cos_theta_t;
      out[ch] += A_of(p, pf, sigma_prime, proj.absorption) * jac;
    }
  }
}

Caustic caustic(const Projection& proj) {
  Caustic c;
  const double e = proj.eta_p;
  if (!(e < 2.0)) return c;  // merged (Eq. 4 has no real h)
  c.exists = true;
  if (proj.exact_roots) {
    // Eq. 4: h_c^2 = (4 - eta'^2) / 3; phi(h) = 4 asin(h/eta') - 2 asin(h) + 2 pi.
    const double h = std::sqrt((4.0 - e * e) / 3.0);
    c.h_c = h;
    c.gamma_c = std::asin(h);
    c.phi_c = wrap_angle(Phi(2, c.gamma_c, e));
    c.d2phi_dh2 = 4.0 * h / std::pow(e * e - h * h, 1.5) - 2.0 * h / std::pow(1.0 - h * h, 1.5);
  } else {
    // Fold of Eq. 10: dphi^/dgamma = B - 3 C gamma^2 = 0.
    const double cc = c_of(e);
    const double B = 12.0 * cc / kPi - 2.0, C = 16.0 * cc / kPi3;
    c.gamma_c = std::min(std::sqrt(B / (3.0 * C)), 0.5 * kPi);
    c.h_c = std::sin(c.gamma_c);
    c.phi_c = wrap_angle(Phi_cubic(2, c.gamma_c, e));
    const double cg = std::cos(c.gamma_c);
    // d2phi/dh2 = (phi'' cos + phi' sin) / cos^3 with phi' = 0 at the fold.
    c.d2phi_dh2 = -6.0 * C * c.gamma_c / std::max(cg * cg, 1e-300);
  }
  return c;
}

namespace {

// The glint of section 5.2.2 at one projection: where the caustic is (phi_c),
// how much power it carries (dh, at the path h_c = sin gamma_c) and the fade
// t past the merge.
struct Glint {
  double phi_c = 0.0, dh = 0.0, t = 0.0, gamma_c = 0.0;
};

Glint glint_of(const Projection& proj, const CausticParams& cp) {
  Glint gl;
  const Caustic c = caustic(proj);
  if (c.exists) {
    gl.phi_c = c.phi_c;
    // The garbled "2 2wc / |d2phi/dh2(hc)|" is 2 sqrt(2 w_c / |phi''(h_c)|): the
    // width of the h interval that phi ~ phi_c + phi''(h - h_c)^2 / 2 maps within
    // w_c of phi_c.
    gl.dh = std::min(cp.delta_h_m, 2.0 * std::sqrt(2.0 * cp.w_c / std::abs(c.d2phi_dh2)));
    gl.t = 1.0;
    gl.gamma_c = c.gamma_c;
  } else {
    gl.phi_c = 0.0;
    gl.dh = cp.delta_h_m;
    gl.t = cp.delta_eta > 0.0 ? fade(2.0, 2.0 + cp.delta_eta, proj.eta_p) : 0.0;
    // Past the merge the path that leaves at phi_c = 0 is h = 0.
    gl.gamma_c = 0.0;
  }
  return gl;
}

// x wrapped to [-pi, pi) (up to rounding at the ends), for any number type.
template <class N>
N wrap_pi(N x) {
  using std::floor;
  return x - N(kTwoPi) * floor((x + N(kPi)) * N(1.0 / kTwoPi));
}

// The factor that removes the caustic from N_TRT at exit angle phi (section
// 5.2.2): (1 - t g(w_c; phi - phi_c) / g(w_c; 0)) (1 - t g(w_c; phi + phi_c) /
// g(w_c; 0)), the differences wrapped to [-pi, pi). Generic over the number
// type: a double, or an xsimd batch of exit angles (exp and floor found by
// argument-dependent lookup).
template <class N>
N caustic_removal(const Glint& gl, const CausticParams& cp, N phi) {
  using std::exp;
  const N x_minus = wrap_pi(phi - N(gl.phi_c)) * N(1.0 / cp.w_c);
  const N x_plus = wrap_pi(phi + N(gl.phi_c)) * N(1.0 / cp.w_c);
  return (N(1.0) - N(gl.t) * exp(N(-0.5) * x_minus * x_minus)) *
         (N(1.0) - N(gl.t) * exp(N(-0.5) * x_plus * x_plus));
}

}  // namespace

void N_TRT(double phi, const Projection& proj, const std::vector<double>& sigma_a,
           const CausticParams& cp, std::vector<double>& out) {
  N_p(2, phi, proj, sigma_a, out);
  if (!(cp.w_c > 0.0)) return;  // no caustic smoothing: the exact Eq. 8 sum
  // Section 5.2.2, the procedure N_TRT(theta, phi; w_c, k_G, Delta eta', Delta h_M).
  const Glint gl = glint_of(proj, cp);
  if (gl.t == 0.0) return;
  const double remove = caustic_removal(gl, cp, phi);
  const double g_minus = g(cp.w_c, wrap_angle(phi - gl.phi_c)), g_plus = g(cp.w_c, wrap_angle(phi + gl.phi_c));
  // "A(2, theta, phi)" in the garbled procedure: we evaluate A(2, h) at the
  // path that forms the caustic, h_c (h = 0 past the merge).
  const PathFresnel pf = path_fresnel(2, gl.gamma_c, proj.eta_p, proj.eta_pp);
  for (std::size_t ch = 0; ch < sigma_a.size(); ++ch) {
    const double a2 = A_of(2, pf, sigma_a[ch] / proj.cos_theta_t, proj.absorption);
    out[ch] = out[ch] * remove + gl.t * cp.k_g * a2 * gl.dh * (g_minus + g_plus);
  }
}

namespace {

// gamma_i in [a, b] where a phi function monotonic on [a, b] (values fa, fb
// at the ends) crosses `target`: Newton safeguarded by bisection. It stops
// when a step is below 1e-13 rad: Newton's next step would be ~1e-26 /
// |phi'| (quadratic convergence), while phi near 2 pi carries a rounding
// error of ~1e-15, so a tighter stop only makes the iterate wander inside
// the rounding (a stop at 1e-15 would run into the 100-step cap at most
// crossings).
// `guess` is used where it lies inside (a, b); else linear interpolation.
template <class PhiOf, class SlopeOf>
double crossing(const PhiOf& phi_of, const SlopeOf& slope_of, double target, double a, double b, double fa,
                double fb, double guess) {
  const bool increasing = fb > fa;
  double x0 = a, x1 = b, x = guess > a && guess < b ? guess : a + (b - a) * (target - fa) / (fb - fa);
  for (int it = 0; it < 100 && x1 - x0 > 1e-15; ++it) {
    const double r = phi_of(x) - target;
    if (r == 0.0) return x;
    if ((r < 0.0) == increasing) x0 = x; else x1 = x;
    const double d = slope_of(x);
    double xn = d != 0.0 ? x - r / d : 0.5 * (x0 + x1);
    if (!(xn > x0 && xn < x1)) xn = 0.5 * (x0 + x1);
    if (std::abs(xn - x) < 1e-13) return xn;
    x = xn;
  }
  return x;
}

// Per node k (of n): weight * A(p, h) per channel c, out[c * n + k]; with
// a glint (section 5.2.2) also times the caustic's removal factor at the
// node's exit angle (PathNode::phi, unwrapped).
// A (section 4.3, Appendix B) from the shared cylinder::Attenuation:
// Appendix B's F(eta', eta'', gamma) is the 3D Fresnel reflectance at
// cos(i) = cos(theta_d) cos(gamma) (test BravaisFresnelEqualsThreeDimensionalFresnel),
// and leaving the fiber F(1/eta', 1/eta'', gamma_t) is the same number
// (the reflectance of a dielectric interface is the same from both sides),
// so A(p, h) = (1 - f)^2 f^(p-1) T^p with one f. Eight nodes per SIMD
// batch (xsimd), the remainder one by one.
void node_masses(const cylinder::Attenuation& att, int p, const std::vector<cylinder::PathNode>& nodes,
                 const Glint* glint, const CausticParams* cp, std::vector<double>& out) {
  using Batch = xsimd::batch<double>;
  constexpr std::size_t W = Batch::size;
  const int C = att.channels();
  const std::size_t n = nodes.size();
  out.resize(C * n);
  std::vector<Batch> mass_b(C);
  alignas(64) double ci[W], si[W], w[W], ph[W];
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    for (std::size_t l = 0; l < W; ++l) {
      const cylinder::PathNode& nd = nodes[k + l];
      ci[l] = nd.cos_gamma, si[l] = nd.sin_gamma, w[l] = nd.weight, ph[l] = nd.phi;
    }
    att.A(p, Batch::load_aligned(ci), Batch::load_aligned(si), mass_b.data());
    Batch wb = Batch::load_aligned(w);
    if (glint) wb *= caustic_removal(*glint, *cp, Batch::load_aligned(ph));
    for (int c = 0; c < C; ++c) (wb * mass_b[c]).store_unaligned(&out[c * n + k]);
  }
  std::vector<double> a(C);
  for (; k < n; ++k) {
    att.A(p, nodes[k].cos_gamma, nodes[k].sin_gamma, a.data());
    const double wk = nodes[k].weight * (glint ? caustic_removal(*glint, *cp, nodes[k].phi) : 1.0);
    for (int c = 0; c < C; ++c) out[c * n + k] = wk * a[c];
  }
}

// Phi(p, gamma_i) of Eq. 3 (exact roots) or of Eq. 10's cubic, and its
// slope; the cubic's coefficients once (the arithmetic of Phi_cubic and
// dPhi_cubic_dgamma).
class PhiOfGamma {
 public:
  PhiOfGamma(int p, const Projection& proj) : p_(p), e_(proj.eta_p), exact_(proj.exact_roots) {
    const double c_cubic = c_of(e_);
    b1_ = 6.0 * p * c_cubic / kPi - 2.0;
    b3_ = 8.0 * p * c_cubic / kPi3;
    d3_ = 24.0 * p * c_cubic / kPi3;
  }
  double operator()(double x) const { return exact_ ? Phi(p_, x, e_) : b1_ * x - b3_ * x * x * x + p_ * kPi; }
  double slope(double x) const { return exact_ ? dPhi_dgamma(p_, x, e_) : b1_ - d3_ * x * x; }
  // Its monotonic pieces on [-pi/2, pi/2]: split at the fold (dphi/dgamma = 0), if any.
  std::vector<double> branches() const {
    const double half_pi = 0.5 * kPi;
    double fold = -1.0;
    if (exact_) {
      fold = cylinder::fold_gamma(p_, e_);
    } else if (p_ >= 1) {
      if (b1_ > 0.0 && std::sqrt(b1_ / d3_) < half_pi) fold = std::sqrt(b1_ / d3_);
    }
    return fold > 0.0 && fold < half_pi ? std::vector<double>{-half_pi, -fold, fold, half_pi}
                                        : std::vector<double>{-half_pi, half_pi};
  }

 private:
  int p_;
  double e_;
  bool exact_;
  double b1_, b3_, d3_;
};

// Nodes over gamma_i whose exits fall into one phi bin each, grouped in
// pieces: each piece between consecutive crossings of a bin edge exits into
// one bin and carries a smooth integrand; long pieces in panels of at most
// pi/64, 5 points per panel (3 on panels shorter than 0.005 rad: one bin's
// worth of h). With want_phi each node's phi (unwrapped) is set.
struct Piece {
  std::size_t end;  // one past its last node
  int bin;          // the phi bin every node of it exits into
};
void edge_pieces(const PhiOfGamma& phi_of, int n_phi, bool want_phi, std::vector<cylinder::PathNode>& nodes,
                 std::vector<Piece>& pieces) {
  const double delta = kTwoPi / n_phi;
  auto slope_of = [&](double x) { return phi_of.slope(x); };
  static thread_local std::vector<double> cuts;
  nodes.clear();
  pieces.clear();
  const std::vector<double> br = phi_of.branches();
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    const double fa = phi_of(a), fb = phi_of(b);
    const double lo = std::min(fa, fb), hi = std::max(fa, fb);
    const bool increasing = fb > fa;
    // The targets ascend, so the crossings ascend in gamma from a where phi
    // increases and descend from b where it decreases: each is bracketed by
    // the one before and the piece's far end, and Newton starts from a
    // Newton step off the one before.
    double prev = increasing ? a : b, f_prev = increasing ? fa : fb;
    cuts.assign(1, a);
    for (long m = static_cast<long>(std::ceil((lo + kPi) / delta)); -kPi + m * delta < hi; ++m) {
      const double target = -kPi + m * delta;
      if (!(target > lo)) continue;
      const double slope = slope_of(prev);
      const double guess = slope != 0.0 ? prev + (target - f_prev) / slope : prev;
      prev = increasing ? crossing(phi_of, slope_of, target, prev, b, f_prev, fb, guess)
                        : crossing(phi_of, slope_of, target, a, prev, fa, f_prev, guess);
      f_prev = target;
      cuts.push_back(prev);
    }
    if (!increasing) std::reverse(cuts.begin() + 1, cuts.end());
    cuts.push_back(b);
    for (std::size_t q = 0; q + 1 < cuts.size(); ++q) {
      const std::size_t first = nodes.size();
      cylinder::piece_nodes(cuts[q], cuts[q + 1], 5, kPi / 64, nodes);
      if (nodes.size() == first) continue;
      // The piece's bin, from its middle.
      pieces.push_back({nodes.size(), cylinder::phi_bin(wrap_angle(phi_of(0.5 * (cuts[q] + cuts[q + 1]))), n_phi)});
      if (want_phi)
        for (std::size_t n = first; n < nodes.size(); ++n) nodes[n].phi = phi_of(nodes[n].gamma);
    }
  }
}

// The glints of section 5.2.2: t k_G A(2, h_c) dh g(w_c; phi -+ phi_c), their
// bin masses in closed form (images 2 pi away included; N_TRT wraps
// phi - phi_c), the same for every channel, added to out[j * C + c].
void add_glints(const Glint& gl, const CausticParams& cp, const Projection& proj, const std::vector<double>& sigma_a,
                int n_phi, std::vector<double>& out) {
  const std::size_t C = sigma_a.size();
  const double delta = kTwoPi / n_phi;
  std::vector<double> edges(n_phi + 1), glint_mass(n_phi, 0.0);
  for (int j = 0; j <= n_phi; ++j) edges[j] = -kPi + j * delta;
  for (int img = -1; img <= 1; ++img) {
    add_gaussian_interval_masses(edges.data(), n_phi, gl.phi_c + kTwoPi * img, cp.w_c, glint_mass.data());
    add_gaussian_interval_masses(edges.data(), n_phi, -gl.phi_c + kTwoPi * img, cp.w_c, glint_mass.data());
  }
  for (std::size_t ch = 0; ch < C; ++ch) {
    const double a2 = A(2, gl.gamma_c, proj.eta_p, proj.eta_pp, sigma_a[ch] / proj.cos_theta_t, proj.absorption);
    const double scale = gl.t * cp.k_g * a2 * gl.dh;
    for (int j = 0; j < n_phi; ++j) out[static_cast<std::size_t>(j) * C + ch] += scale * glint_mass[j];
  }
}

}  // namespace

void N_p_bins(int p, const Projection& proj, const std::vector<double>& sigma_a,
              const CausticParams* cp, int n_phi, std::vector<double>& out) {
  const std::size_t C = sigma_a.size();
  out.assign(static_cast<std::size_t>(n_phi) * C, 0.0);
  const bool glints = p == 2 && cp && cp->w_c > 0.0;
  const Glint gl = glints ? glint_of(proj, *cp) : Glint{};
  static thread_local std::vector<cylinder::PathNode> nodes;
  static thread_local std::vector<Piece> pieces;
  static thread_local std::vector<double> mass;
  // Section 5.2.2: the caustic's removal factor needs each node's phi.
  edge_pieces(PhiOfGamma(p, proj), n_phi, glints, nodes, pieces);
  const cylinder::Attenuation att(proj.eta, proj.theta, sigma_a, proj.absorption);
  node_masses(att, p, nodes, glints && gl.t != 0.0 ? &gl : nullptr, cp, mass);
  // Each piece's sum into its bin.
  const std::size_t n = nodes.size();
  for (std::size_t c = 0; c < C; ++c) {
    std::size_t k = 0;
    for (const Piece& pc : pieces) {
      double sum = 0.0;
      for (; k < pc.end; ++k) sum += mass[c * n + k];
      out[static_cast<std::size_t>(pc.bin) * C + c] += sum;
    }
  }
  if (glints && gl.t != 0.0) add_glints(gl, *cp, proj, sigma_a, n_phi, out);
}

// ---- Section 5.2.3 ------------------------------------------------------------

double eta_star(double eta, double a, double phi_h) {
  const double e1 = 2.0 * (eta - 1.0) * a * a - eta + 2.0;
  const double e2 = 2.0 * (eta - 1.0) / (a * a) - eta + 2.0;
  return 0.5 * ((e1 + e2) + std::cos(2.0 * phi_h) * (e1 - e2));
}

}  // namespace marschner2003

namespace {

namespace m3 = marschner2003;

class Marschner2003 final : public Model {
 public:
  Marschner2003(const Marschner2003Params& params, bool interpolate_theta)
      : params_(params), interpolate_theta_(interpolate_theta) {
    if (!(params.eta > 1.0))
      throw Error(fmt::format("marschner2003: eta = {} must be > 1", params.eta));
    if (params.sigma_a.empty()) throw Error("marschner2003: sigma_a needs at least one channel");
    for (double s : params.sigma_a)
      if (!(s >= 0.0) || !std::isfinite(s))
        throw Error(fmt::format("marschner2003: sigma_a = {} must be finite and >= 0", s));
    for (int p = 0; p <= 2; ++p) {
      const double beta = m3::at_p(params.beta_long, p, "beta_long");
      if (!(beta > 0.0))
        throw Error(fmt::format(
            "marschner2003: beta_long[{}] = {} must be > 0 (M_p is a Gaussian; its smooth "
            "limit is a delta that a density cannot represent)",
            p, beta));
      m3::at_p(params.alpha, p, "alpha");
    }
    if (!(params.eccentricity > 0.0))
      throw Error(fmt::format("marschner2003: eccentricity = {} must be > 0", params.eccentricity));
    if (!(params.w_c >= 0.0))
      throw Error(fmt::format("marschner2003: w_c = {} must be >= 0", params.w_c));
    if (params.lobes < 1)
      throw Error(fmt::format("marschner2003: lobes = {} must be >= 1", params.lobes));
    caustic_.k_g = params.k_g;
    caustic_.w_c = params.w_c;
    caustic_.delta_eta = params.delta_eta;
    caustic_.delta_h_m = params.delta_h_m;
  }

  std::string name() const override { return "marschner2003"; }
  int lobes() const override { return params_.lobes; }

  void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
               std::vector<double>& out) const override {
    const std::size_t channels = params_.sigma_a.size();
    out.assign(channels, 0.0);
    // Tally lobe -> p range (SPEC s6): lobe L-1 collects every p >= L-1; p > 2 is 0.
    const int last = params_.lobes - 1;
    if (lobe < 0 || lobe > last) return;
    const int p_lo = lobe, p_hi = (lobe == last) ? 2 : lobe;
    if (p_lo > 2) return;

    const double theta_d = 0.5 * (theta_r - theta_i);
    const double cos_d = std::cos(theta_d), cos_r = std::cos(theta_r);
    // SPEC s7: density = S cos^2(theta_r), S = sum M_p N_p / cos^2(theta_d) (Eq. 9).
    if (cos_d * cos_d < 1e-300) return;  // theta_r = -theta_i = +-90 deg: cos_r = 0 too
    const double geometry = (cos_r * cos_r) / (cos_d * cos_d);
    if (geometry == 0.0) return;

    for (int p = p_lo; p <= p_hi; ++p) {
      const double beta = m3::at_p(params_.beta_long, p, "beta_long");
      const double alpha = m3::at_p(params_.alpha, p, "alpha");
      const double M = m3::M_p(beta, alpha, theta_i, theta_r, params_.two_theta_h);
      if (M == 0.0) continue;
      double eta = params_.eta;
      if (p == 2 && params_.eccentricity != 1.0) {
        // Section 5.2.3: phi_h = (phi_i + phi_r)/2 = phi_i + phi/2 (SPEC s1, from
        // the major axis v); the paper's phi_h is measured from the minor axis
        // (see eta_star in the header: fixed by a ray trace of the ellipse).
        const double phi_h = phi_i + 0.5 * phi - 0.5 * kPi;
        eta = std::max(m3::eta_star(params_.eta, params_.eccentricity, phi_h), 1.0 + 1e-6);
      }
      // Eq. 9: N evaluated with eta'(eta, theta_d).
      const m3::Projection proj =
          m3::project(eta, theta_d, params_.exact_roots, params_.absorption);
      if (p == 2)
        m3::N_TRT(phi, proj, params_.sigma_a, caustic_, n_);
      else
        m3::N_p(p, phi, proj, params_.sigma_a, n_);
      for (std::size_t ch = 0; ch < channels; ++ch) out[ch] += M * n_[ch] * geometry;
    }
  }

  // The default per-bin 6 x 6 Gauss-Legendre rule cannot see a Gaussian M of
  // beta = 0.1 deg inside a 2 deg bin, nor the 1/sqrt caustics of N_TRT. Here
  // theta_r is split at theta_breakpoints, 4 Gauss-Legendre points per piece,
  // and each node goes to add_circular_node (N depends on theta_d only: a
  // circular fiber, or R and TT of any fiber) or add_eccentric_node (N_TRT of
  // an elliptical fiber, section 5.2.3). With w_c == 0 the caustics of an
  // elliptical fiber move with phi_h and are not split at (integrable, less
  // accurate).
  std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                        double phi_i) const override {
    const int nt = grid.n_theta(), np = grid.n_phi(), L = params_.lobes;
    const std::size_t C = params_.sigma_a.size();
    std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
    const GaussLegendre& gl = gauss_legendre(4);
    for (int lobe = 0; lobe < L; ++lobe) {
      const int p_lo = lobe, p_hi = std::min(2, lobe == L - 1 ? 2 : lobe);
      if (p_lo > 2) continue;
      const std::vector<double> tk = theta_breakpoints(grid, p_lo, p_hi, theta_i);
      // Eccentricity changes N_TRT only (section 5.2.3: eta* "to the code
      // that computes N_TRT"): a lobe without p = 2 takes the circular
      // fiber's phi-bin integrals over h whatever the eccentricity.
      const bool by_h = params_.eccentricity == 1.0 || p_hi < 2;
      std::vector<ThetaPoint> points[3];  // per order p: theta_r nodes of the circular fiber
      for (std::size_t s = 0; s + 1 < tk.size(); ++s) {
        const double t0 = tk[s], t1 = tk[s + 1];
        if (!(t1 > t0)) continue;
        const int i = grid.theta_bin(0.5 * (t0 + t1));
        for (int a = 0; a < static_cast<int>(gl.x.size()); ++a) {
          const double tr = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * gl.x[a];
          const double wt = 0.5 * (t1 - t0) * gl.w[a];
          if (negligible(p_lo, p_hi, theta_i, tr)) continue;
          if (by_h)
            add_circular_node(lobe, p_lo, p_hi, i, tr, wt, theta_i, nt, np, points, out);
          else
            add_eccentric_node(grid, lobe, i, tr, wt, theta_i, phi_i, out);
        }
      }
      for (int p = p_lo; p <= p_hi; ++p) add_interpolated(lobe, p, theta_i, points[p], nt, np, out);
    }
    return out;
  }

 private:
  struct ThetaPoint {
    int i;         // theta bin
    double theta;  // theta_r
    double w;      // quadrature weight times M_p and the geometry factor
  };

  // theta_r breakpoints: the bin edges and every half standard deviation
  // (in theta_r) within +-8 of each order's centre -theta_i + alpha[p].
  std::vector<double> theta_breakpoints(const BinGrid& grid, int p_lo, int p_hi, double theta_i) const {
    const double half_pi = 0.5 * kPi;
    std::vector<double> tk(grid.theta_edges.begin(), grid.theta_edges.end());
    for (int p = p_lo; p <= p_hi; ++p) {
      const double beta = m3::at_p(params_.beta_long, p, "beta_long");
      const double sd = params_.two_theta_h ? beta : 2.0 * beta;  // in theta_r
      const double centre = -theta_i + m3::at_p(params_.alpha, p, "alpha");
      for (int k = -16; k <= 16; ++k) {
        const double t = centre + 0.5 * k * sd;
        if (t > -half_pi && t < half_pi) tk.push_back(t);
      }
    }
    std::sort(tk.begin(), tk.end());
    tk.erase(std::unique(tk.begin(), tk.end()), tk.end());
    return tk;
  }

  // Whether every order's M at theta_r is below 1e-13 of its peak (beyond
  // ~7.7 standard deviations): there the node adds less than 1e-13 of the
  // lobe's density per bin (N and the geometry factor are bounded).
  bool negligible(int p_lo, int p_hi, double theta_i, double tr) const {
    for (int p = p_lo; p <= p_hi; ++p) {
      const double beta = m3::at_p(params_.beta_long, p, "beta_long");
      const double M = m3::M_p(beta, m3::at_p(params_.alpha, p, "alpha"), theta_i, tr, params_.two_theta_h);
      if (!(M < 1e-13 * m3::g(beta, 0.0))) return false;
    }
    return true;
  }

  // A theta_r node of a circular fiber (N depends on theta_d only): M and the
  // geometry factor of Eq. 9 once, N's phi-bin integrals either interpolated
  // later (R and TT: into points[p]) or exact here (TRT, whose caustics
  // crossing bin edges make its bins kink in theta_r).
  void add_circular_node(int lobe, int p_lo, int p_hi, int i, double tr, double wt, double theta_i, int nt, int np,
                         std::vector<ThetaPoint>* points, std::vector<double>& out) const {
    const std::size_t C = params_.sigma_a.size();
    const double theta_d = 0.5 * (tr - theta_i);
    const double cos_d = std::cos(theta_d), cos_r = std::cos(tr);
    if (cos_d * cos_d < 1e-300) return;
    const double geometry = (cos_r * cos_r) / (cos_d * cos_d);
    static thread_local std::vector<double> nbins;
    for (int p = p_lo; p <= p_hi; ++p) {
      const double beta = m3::at_p(params_.beta_long, p, "beta_long");
      const double M = m3::M_p(beta, m3::at_p(params_.alpha, p, "alpha"), theta_i, tr, params_.two_theta_h);
      if (M == 0.0) continue;
      const double f = wt * M * geometry;
      if (interpolate_theta_ && p < 2) {
        points[p].push_back({i, tr, f});
        continue;
      }
      const m3::Projection proj = m3::project(params_.eta, theta_d, params_.exact_roots, params_.absorption);
      m3::N_p_bins(p, proj, params_.sigma_a, p == 2 ? &caustic_ : nullptr, np, nbins);
      double* row = &out[(static_cast<std::size_t>(lobe) * nt + i) * np * C];
      for (std::size_t x = 0; x < nbins.size(); ++x) row[x] += f * nbins[x];
    }
  }

  // A theta_r node of an elliptical fiber's TRT lobe (N_TRT depends on phi
  // through eta*(phi_h), section 5.2.3): density() at points in phi, split
  // at the bin edges and every phi_step (min(2 deg, w_c / 2)); each piece
  // gets a 4-point Gauss-Legendre rule in u after
  // phi = a + (b - a)(1 - cos(pi u)) / 2, which makes a 1/sqrt singularity
  // at a piece end smooth.
  void add_eccentric_node(const BinGrid& grid, int lobe, int i, double tr, double wt, double theta_i, double phi_i,
                          std::vector<double>& out) const {
    const int nt = grid.n_theta(), np = grid.n_phi();
    const std::size_t C = params_.sigma_a.size();
    const GaussLegendre& gl = gauss_legendre(4);
    double phi_step = deg_to_rad(2.0);
    if (params_.w_c > 0.0) phi_step = std::min(phi_step, 0.5 * params_.w_c);
    std::vector<double> value;
    for (int j = 0; j < np; ++j) {
      const double f0 = grid.phi_edges[j], f1 = grid.phi_edges[j + 1];
      double* bin = &out[((static_cast<std::size_t>(lobe) * nt + i) * np + j) * C];
      const int n_sub = std::max(1, static_cast<int>(std::ceil((f1 - f0) / phi_step)));
      const double width = (f1 - f0) / n_sub;
      for (int sub = 0; sub < n_sub; ++sub) {
        const double lo = f0 + sub * width;
        for (int b = 0; b < 4; ++b) {
          const double u = 0.5 * (1.0 + gl.x[b]);  // in [0, 1]
          const double ph = lo + 0.5 * width * (1.0 - std::cos(kPi * u));
          const double w = wt * 0.5 * gl.w[b] * 0.5 * width * kPi * std::sin(kPi * u);
          density(lobe, theta_i, phi_i, tr, ph, value);
          for (std::size_t c = 0; c < C; ++c) bin[c] += w * value[c];
        }
      }
    }
  }

  // Adds order p of a circular fiber to `lobe`: sum over the theta_r nodes
  // of w N_p's phi-bin integrals at theta_d = (theta_r - theta_i) / 2, with
  // N_p_bins interpolated in theta_r between exact evaluations at
  // Chebyshev-Lobatto points (ChebyshevPanels: panels of at most
  // kPanelWidth, kPanelPoints points each) instead of evaluated at every
  // node: the interpolation is linear in N, so each bin's contribution is
  // sum_k (sum over its nodes of w l_k(theta_r)) N_p_bins(x_k).
  void add_interpolated(int lobe, int p, double theta_i, const std::vector<ThetaPoint>& pts,
                        int nt, int np, std::vector<double>& out) const {
    if (pts.empty()) return;
    double lo = pts.front().theta, hi = lo;
    for (const ThetaPoint& q : pts) lo = std::min(lo, q.theta), hi = std::max(hi, q.theta);
    const int n_pan = std::max(1, static_cast<int>(std::ceil((hi - lo) / deg_to_rad(kPanelWidthDeg))));
    const ChebyshevPanels cheb(lo, hi, n_pan, kPanelPoints);
    const int m = cheb.per_panel(), nodes = cheb.nodes();
    std::vector<double> mom(static_cast<std::size_t>(nt) * nodes, 0.0), l(m), nbins;
    for (const ThetaPoint& q : pts) {
      const int first = cheb.basis(q.theta, l.data());
      double* row = &mom[static_cast<std::size_t>(q.i) * nodes + first];
      for (int k = 0; k < m; ++k) row[k] += q.w * l[k];
    }
    const std::size_t row_size = static_cast<std::size_t>(np) * params_.sigma_a.size();
    for (int g = 0; g < nodes; ++g) {
      const m3::Projection proj = m3::project(params_.eta, 0.5 * (cheb.node(g) - theta_i),
                                              params_.exact_roots, params_.absorption);
      m3::N_p_bins(p, proj, params_.sigma_a, p == 2 ? &caustic_ : nullptr, np, nbins);
      for (int i = 0; i < nt; ++i) {
        const double mk = mom[static_cast<std::size_t>(i) * nodes + g];
        if (mk == 0.0) continue;
        double* row = &out[(static_cast<std::size_t>(lobe) * nt + i) * row_size];
        for (std::size_t x = 0; x < row_size; ++x) row[x] += mk * nbins[x];
      }
    }
  }

  Marschner2003Params params_;
  m3::CausticParams caustic_;
  bool interpolate_theta_ = true;
  // Measured against the per-node reference (90 x 180 bins, beta 0.5 to 10
  // deg, theta_i 0 to 80 deg): 20 deg panels of 11 points keep every bin of
  // R and TT within 2e-7 of the lobe's largest bin.
  static constexpr double kPanelWidthDeg = 20.0;
  static constexpr int kPanelPoints = 11;
  // Scratch for N, thread-local so that density() may run on many threads.
  static thread_local std::vector<double> n_;
};

thread_local std::vector<double> Marschner2003::n_;

}  // namespace

std::unique_ptr<Model> make_marschner2003(const Marschner2003Params& params) {
  return std::make_unique<Marschner2003>(params, true);
}

std::unique_ptr<Model> make_marschner2003_reference(const Marschner2003Params& params) {
  return std::make_unique<Marschner2003>(params, false);
}

}  // namespace fiberlab::analytic

// ---- Parameter table and registry entry -------------------------------------------

namespace fiberlab::analytic {

namespace {
std::vector<std::string> marschner_approximations(const Marschner2003Params& p) {
  std::vector<std::string> out;
  out.push_back(p.absorption == Absorption::Published
                    ? "absorption=published: exp(-4 sigma_a' cos^2 gamma_t) (s4.3; not the chord)"
                    : "absorption=chord: the chord length (SPEC s7)");
  out.push_back(p.two_theta_h
                    ? "longitudinal=two_theta_h: M a Gaussian in 2 theta_h (Zinke & Weber; energy-correct)"
                    : "longitudinal=theta_h: M a Gaussian in theta_h as published: about twice the energy "
                      "for small beta (d'Eon 2011 s4.1)");
  out.push_back(p.exact_roots ? "roots=exact: Phi(p, h) of Eq. 3 solved exactly"
                              : "roots=cubic: h from the cubic of Eq. 10 (< 0.75 deg error in phi)");
  if (p.w_c > 0.0)
    out.push_back(fmt::format(
        "TRT caustics replaced by glints (s5.2.2): w_c={:g} deg, k_g={:g}, delta_eta={:g}, delta_h_m={:g}",
        rad_to_deg(p.w_c), p.k_g, p.delta_eta, p.delta_h_m));
  else
    out.push_back("caustic smoothing off (w_c=0): N_TRT is the exact Eq. 8 sum over roots");
  if (p.eccentricity != 1.0)
    out.push_back(fmt::format("eccentricity {:g}: eta*(phi_h) in N_TRT only (s5.2.3)", p.eccentricity));
  out.push_back("lobes p >= 3 are not modelled (zero)");
  return out;
}
// The rule from a simulated fiber (physical_defaults.h): the eccentricity
// itself; the tilt as SPEC s7's shifts; the longitudinal widths by the
// calibrated rule in the model's width variable, floored at
// kMinMarschnerBeta (the Gaussian M needs beta > 0). The model has no
// azimuthal roughness (its N_p is the smooth fiber's, section 4.2, with only
// the caustic's w_c), so a fiber's azimuthal width is not represented: the
// mapping says so rather than dropping it unseen.
void marschner2003_from_fiber(const PhysicalFiber& f, Marschner2003Params& p, FiberMapping& mapping) {
  apply_fiber_basics(f, p);
  p.alpha = tilt_shifts(f.scale_tilt);
  p.eccentricity = f.eccentricity;
  LobeWidths w;
  apply_fiber_roughness(f, w, marschner2003_width_calibration(p.two_theta_h), mapping, kMinMarschnerBeta);
  p.beta_long = w.beta_long;
  if (std::any_of(w.beta_azim.begin(), w.beta_azim.end(), [](double b) { return b > 0.0; }))
    mapping.notes.push_back(fmt::format(
        "roughness: marschner2003 has no azimuthal roughness width; the azimuthal part of the {} fiber is not "
        "represented (only its longitudinal widths are used)",
        f.roughness_text()));
}

}  // namespace

ModelInfo marschner2003_info() {
  using P = Marschner2003Params;
  ModelDefinition<P> m;
  m.name = "marschner2003";
  m.reference = "Marschner, Jensen, Cammarano, Worley, Hanrahan 2003, Light Scattering from Human Hair Fibers";
  m.params = {
      eta_param<P>(),
      sigma_a_param<P>(),
      beta_long_param<P>("sd of the Gaussian M_p per lobe p, in theta_h (published) or 2 theta_h; > 0"),
      alpha_param<P>("shift of theta_r per lobe p (Marschner's alpha_p, a shift of theta_h, is half)"),
      absorption_param<P>("published"),
      lobes_param<P>(),
      eccentricity_param<P>(),
      bool_param("longitudinal", "variable of the Gaussian M: theta_h (published) or 2 theta_h (Zinke & Weber)",
                 "theta_h", {"theta_h", "two_theta_h"}, &P::two_theta_h),
      bool_param("roots", "roots of Phi(p, h) = phi: the cubic of Eq. 10 (published) or Eq. 3 exactly", "cubic",
                 {"cubic", "exact"}, &P::exact_roots),
      // Ranges: Table 1's, widened (k_g, delta_eta), or the variable's own
      // (an azimuthal width up to a half turn, an impact parameter in [0, 1]).
      number_param("k_g", "glint scale factor k_G (Table 1: 0.5 to 5)", "", "0.5", "a number in [0, 10]", &P::k_g,
                   [](double x) { return x >= 0.0 && x <= 10.0; }),
      number_param("w_c", "azimuthal width of the caustic (Table 1: 10 to 25 deg); 0 = no caustic smoothing",
                   "deg", "10", "degrees in [0, 180]", &P::w_c, [](double x) { return x >= 0.0 && x <= 180.0; }),
      number_param("delta_eta", "fade range of eta' past the caustic merge (Table 1: 0.2 to 0.4)", "", "0.3",
                   "a number in [0, 10]", &P::delta_eta, [](double x) { return x >= 0.0 && x <= 10.0; }),
      number_param("delta_h_m", "caustic intensity limit Delta h_M (Table 1: 0.5)", "", "0.5",
                   "a number in [0, 1]", &P::delta_h_m, [](double x) { return x >= 0.0 && x <= 1.0; }),
  };
  m.make = make_marschner2003;
  m.approximations = marschner_approximations;
  m.from_fiber = marschner2003_from_fiber;
  m.theta_r_shifts = [](const P& p) { return p.alpha; };
  return define_model(std::move(m));
}

}  // namespace fiberlab::analytic
