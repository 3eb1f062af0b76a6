#pragma once
// Paths of light through a smooth circular cylinder, in the normal plane
// (SPEC s7; Marschner et al. 2003 s4 and Appendix B; d'Eon et al. 2011 s4):
// the one place where eta' (Bravais), Phi(p, h) and its fold (the TRT
// caustic), the attenuation T and the path weight A(p, h) are written. Used
// by the exact model (smooth_cylinder.h), d'Eon 2011 and Marschner 2003.
//   Phi(p, h) = 2 p gamma_t - 2 gamma_i + p pi, sin gamma_i = h,
//   sin gamma_t = h / eta', eta' = sqrt(eta^2 - sin^2 theta) / cos theta,
//   A(0, h) = f, A(p, h) = (1 - f)^2 f^(p-1) T^p,
//   f = F(eta, acos(cos theta cos gamma_i)) (3D Fresnel, common/fresnel.h),
//   T = exp(-sigma_a' 2 cos gamma_t) (chord) or exp(-4 sigma_a' cos^2 gamma_t)
//   (published), sigma_a' = sigma_a / cos theta_t, sin theta_t = sin theta / eta.
#include <cmath>
#include <vector>

#include "analytic/model.h"
#include "common/fresnel.h"

namespace fiberlab::analytic {

namespace cylinder {

// eta' of Bravais's law (Marschner 2003 Appendix B).
double eta_prime(double eta, double theta);
// Phi(p, gamma_i) and its derivative for the projected index eta_p.
double Phi(int p, double gamma_i, double eta_p);
double dPhi_dgamma(int p, double gamma_i, double eta_p);
// gamma_c > 0 where dPhi/dgamma = 0 (sin^2 gamma_c = (p^2 - eta'^2)/(p^2 - 1)),
// for p >= 2 and eta' < p; otherwise -1 (Phi monotonic). For p = 2 this is
// the TRT caustic, h^2 = (4 - eta'^2)/3 (SPEC s8).
double fold_gamma(int p, double eta_p);

// Transmittance of one internal segment at projected refraction angle
// gamma_t: chord exp(-sigma_a' 2 cos gamma_t), or as published
// exp(-2 sigma_a' (1 + cos 2 gamma_t)) = exp(-4 sigma_a' cos^2 gamma_t).
// Generic over the number type (double, or an xsimd batch of doubles whose
// exp is found by argument-dependent lookup), like the functions below.
template <class T>
T segment_transmittance(double sigma_a_prime, T cos_gamma_t, Absorption absorption) {
  using std::exp;
  // Chord: 2 cos(gamma_t); published (Marschner 2003 s4.3, the garbled "law of
  // cosines" sentence): 2 (1 + cos 2 gamma_t) = 4 cos^2(gamma_t), not a chord.
  const T length = absorption == Absorption::Chord ? T(2.0) * cos_gamma_t : T(4.0) * cos_gamma_t * cos_gamma_t;
  return exp(T(-sigma_a_prime) * length);
}

// x^n for an integer n >= 0 by repeated squaring (a few multiplications
// instead of std::pow's exp and log; within ~2 log2(n) ulp).
template <class T>
T integer_power(T x, int n) {
  T r(1.0);
  for (; n > 0; n >>= 1, x *= x)
    if (n & 1) r *= x;
  return r;
}

// The attenuation of paths at inclination theta (theta_i for the smooth
// fiber, theta_d for d'Eon 2011). Precomputes what does not depend on h.
class Attenuation {
 public:
  Attenuation(double eta, double theta, const std::vector<double>& sigma_a, Absorption absorption);
  double eta_p() const { return eta_p_; }
  int channels() const { return static_cast<int>(sigma_a_prime_.size()); }
  // f = F(eta, acos(cos theta cos gamma_i)).
  double f(double gamma_i) const { return f_cos(std::cos(gamma_i)); }
  template <class N>
  N f_cos(N cos_gamma_i) const {
    using std::max;
    using std::min;
    return fresnel_dielectric(min(N(1.0), max(N(0.0), N(cos_theta_) * cos_gamma_i)), N(eta_));
  }
  // T of one internal segment, per channel.
  void T(double gamma_i, double* out) const { T_sin(std::sin(gamma_i), out); }
  template <class N>
  void T_sin(N sin_gamma_i, N* out) const {
    using std::max;
    using std::sqrt;
    const N s = sin_gamma_i / N(eta_p_);
    const N cos_t = sqrt(max(N(0.0), N(1.0) - s * s));
    for (std::size_t c = 0; c < sigma_a_prime_.size(); ++c)
      out[c] = segment_transmittance(sigma_a_prime_[c], cos_t, absorption_);
  }
  // A(p, gamma_i) per channel (out[0..C)), from gamma_i or its cosine and
  // sine (any number type: one node per SIMD lane).
  void A(int p, double gamma_i, double* out) const { A(p, std::cos(gamma_i), std::sin(gamma_i), out); }
  template <class N>
  void A(int p, N cos_gamma_i, N sin_gamma_i, N* out) const {
    const N fr = f_cos(cos_gamma_i);
    const int C = channels();
    if (p == 0) {
      for (int c = 0; c < C; ++c) out[c] = fr;
      return;
    }
    T_sin(sin_gamma_i, out);
    const N base = (N(1.0) - fr) * (N(1.0) - fr) * integer_power(fr, p - 1);
    for (int c = 0; c < C; ++c) out[c] = base * integer_power(out[c], p);
  }
  // Sum of A(p', gamma_i) over every p' > P (P >= 0), per channel, in closed
  // form: (1 - f)^2 f^P T^(P+1) / (1 - f T).
  void A_beyond(int P, double gamma_i, double* out) const;

 private:
  double eta_, cos_theta_, eta_p_;
  std::vector<double> sigma_a_prime_;
  Absorption absorption_;
};

// Energy of every order p > P per channel, (1/2) int sum_{p>P} A dh, by
// 64-point Gauss-Legendre over gamma_i (the closed-form sum A_beyond is
// smooth in gamma).
void energy_beyond(const Attenuation& att, int P, std::vector<double>& out);
// The first order P >= p_first after which energy_beyond is at most tol in
// every channel, or max_p; `energy` holds energy_beyond at that P. The
// models that trace orders up to P and spread the rest uniformly in phi
// (the exact model, d'Eon 2011) stop there.
int last_order(const Attenuation& att, int p_first, double tol, int max_p, std::vector<double>& energy);

// A quadrature node of (1/2) integral over h in (-1, 1) of g(h) dh, written
// over gamma_i (h = sin gamma_i; weight includes cos(gamma_i) / 2), with the
// exit azimuth Phi(p, gamma_i) wrapped to [-pi, pi).
struct PathNode {
  double gamma, weight, phi;
  double cos_gamma = 0.0, sin_gamma = 0.0;  // set by smooth_nodes and panel_nodes
};
// Appends composite Gauss-Legendre nodes of (1/2) integral over gamma in
// [a, b] (panels of at most max_len, `order` <= 64 points each, 3 where a
// panel is shorter than 0.005) with phi left 0: the building block of the
// two functions below, public for Marschner 2003's phi function of Eq. 10.
void piece_nodes(double a, double b, int order, double max_len, std::vector<PathNode>& out);
// Nodes split at every crossing of Phi(p, .) with an edge of n_phi uniform
// bins on [-pi, pi) and at the fold: each node's phi is strictly inside one
// bin and each piece carries a smooth integrand. `order` points per piece.
void smooth_nodes(int p, double eta_p, int n_phi, int order, std::vector<PathNode>& out);
// Composite Gauss-Legendre over gamma_i in (-pi/2, pi/2), split at the fold,
// with panels over which Phi changes by at most max_dphi.
// Without want_phi, phi is left 0 (callers that build Phi's phasor themselves).
void panel_nodes(int p, double eta_p, double max_dphi, int order, std::vector<PathNode>& out,
                 bool want_phi = true);
// Bin of a wrapped phi in n uniform bins on [-pi, pi).
int phi_bin(double phi, int n_phi);
// Adds the smooth cylinder's lobe p, (1/2) integral of A(p, h) dh, to the phi
// bins it exits into (a delta detector), by smooth_nodes split at the bin
// edges: bins[j * C + c] for n_phi uniform bins and C = att.channels().
void add_smooth_lobe(const Attenuation& att, int p, int n_phi, std::vector<double>& bins);

}  // namespace cylinder

}  // namespace fiberlab::analytic
