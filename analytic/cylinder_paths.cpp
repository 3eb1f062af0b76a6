#include "analytic/cylinder_paths.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "analytic/quadrature.h"
#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab::analytic {

namespace cylinder {

double eta_prime(double eta, double theta) {
  const double s = std::sin(theta);
  const double c = std::max(std::cos(theta), 1e-300);
  return std::sqrt(eta * eta - s * s) / c;
}

double Phi(int p, double gamma_i, double eta_p) {
  const double gamma_t = std::asin(std::clamp(std::sin(gamma_i) / eta_p, -1.0, 1.0));
  return 2.0 * p * gamma_t - 2.0 * gamma_i + p * kPi;
}

double dPhi_dgamma(int p, double gamma_i, double eta_p) {
  const double s = std::sin(gamma_i) / eta_p;
  const double cos_t = std::sqrt(std::max(0.0, 1.0 - s * s));
  return 2.0 * p * std::cos(gamma_i) / (eta_p * cos_t) - 2.0;
}

double fold_gamma(int p, double eta_p) {
  if (p < 2 || eta_p >= p) return -1.0;
  const double s2 = (p * p - eta_p * eta_p) / (p * p - 1.0);
  return std::asin(std::sqrt(std::clamp(s2, 0.0, 1.0)));
}

Attenuation::Attenuation(double eta, double theta, const std::vector<double>& sigma_a,
                         Absorption absorption)
    : eta_(eta), cos_theta_(std::cos(theta)), eta_p_(eta_prime(eta, theta)),
      absorption_(absorption) {
  const double sin_t = std::sin(theta) / eta;
  const double cos_theta_t = std::sqrt(std::max(0.0, 1.0 - sin_t * sin_t));
  for (double s : sigma_a) sigma_a_prime_.push_back(s / cos_theta_t);
}

void Attenuation::A_beyond(int P, double gamma_i, double* out) const {
  const double fr = f(gamma_i);
  T(gamma_i, out);
  const double base = (1.0 - fr) * (1.0 - fr) * integer_power(fr, P);
  for (int c = 0; c < channels(); ++c) {
    const double denom = 1.0 - fr * out[c];
    // f T -> 1 only when f -> 1, where (1 - f)^2 / (1 - f T) -> 0.
    out[c] = denom > 1e-300 ? base * integer_power(out[c], P + 1) / denom : 0.0;
  }
}

void energy_beyond(const Attenuation& att, int P, std::vector<double>& out) {
  const int C = att.channels();
  out.assign(C, 0.0);
  const GaussLegendre& gl = gauss_legendre(64);
  std::vector<double> buf(C);
  for (int q = 0; q < 64; ++q) {
    const double g = 0.5 * kPi * gl.x[q];
    att.A_beyond(P, g, buf.data());
    for (int c = 0; c < C; ++c) out[c] += 0.25 * kPi * gl.w[q] * std::cos(g) * buf[c];
  }
}

int last_order(const Attenuation& att, int p_first, double tol, int max_p, std::vector<double>& energy) {
  for (int P = p_first;; ++P) {
    energy_beyond(att, P, energy);
    if (*std::max_element(energy.begin(), energy.end()) <= tol || P >= max_p) return P;
  }
}

int phi_bin(double phi, int n_phi) {
  const int j = static_cast<int>(std::floor((phi + kPi) / kTwoPi * n_phi));
  return std::clamp(j, 0, n_phi - 1);
}

void add_smooth_lobe(const Attenuation& att, int p, int n_phi, std::vector<double>& bins) {
  const int C = att.channels();
  std::vector<PathNode> nodes;
  std::vector<double> a(C);
  smooth_nodes(p, att.eta_p(), n_phi, 6, nodes);
  for (const PathNode& nd : nodes) {
    att.A(p, nd.gamma, a.data());
    double* r = &bins[static_cast<std::size_t>(phi_bin(nd.phi, n_phi)) * C];
    for (int c = 0; c < C; ++c) r[c] += nd.weight * a[c];
  }
}

constexpr int kMaxPieceOrder = 64;

void piece_nodes(double a, double b, int order, double max_len, std::vector<PathNode>& out) {
  if (!(b > a)) return;
  if (order < 1 || order > kMaxPieceOrder)
    throw std::logic_error("cylinder path nodes: Gauss-Legendre order outside 1..64");
  const int m = std::max(1, static_cast<int>(std::ceil((b - a) / max_len)));
  const double len = (b - a) / m;
  // Short pieces (high orders p cross a bin edge every few 1e-3 rad of
  // gamma) carry an integrand that is a low-degree polynomial to rounding
  // over their length: fewer points there (error ~ len^(2n), len < 0.005).
  if (len < 0.005) order = std::min(order, 3);
  // gauss_legendre() takes a lock; its rules never move once made, so each
  // thread keeps pointers to them (this runs once per piece: ~10^5 times per
  // Marschner 2003 prediction).
  static thread_local const GaussLegendre* rules[kMaxPieceOrder + 1] = {};
  if (!rules[order]) rules[order] = &gauss_legendre(order);
  const GaussLegendre& gl = *rules[order];
  // cos and sin of gamma = mid + half x_q by angle addition: one sine and
  // cosine per panel instead of one per node (to ~1 ulp). Those of half x_q
  // for half of the nodes only: the rule is symmetric (x_{n-1-q} = -x_q and
  // the middle node 0, exactly), cos even and sin odd (exactly, in libm too).
  const double half = 0.5 * len;
  double cq[kMaxPieceOrder], sq[kMaxPieceOrder];
  for (int q = 0; q < order; ++q) {
    const int mirror = order - 1 - q;
    if (mirror == q) cq[q] = 1.0, sq[q] = 0.0;
    else if (mirror < q) cq[q] = cq[mirror], sq[q] = -sq[mirror];
    else cq[q] = std::cos(half * gl.x[q]), sq[q] = std::sin(half * gl.x[q]);
  }
  for (int k = 0; k < m; ++k) {
    const double mid = a + k * len + half;
    const double cm = std::cos(mid), sm = std::sin(mid);
    for (int q = 0; q < order; ++q) {
      const double g = mid + half * gl.x[q];
      const double cg = cm * cq[q] - sm * sq[q], sg = sm * cq[q] + cm * sq[q];
      out.push_back({g, 0.5 * half * gl.w[q] * cg, 0.0, cg, sg});
    }
  }
}

namespace {

// The monotonic pieces of Phi(p, .) on [-pi/2, pi/2].
std::vector<double> monotonic_breaks(int p, double eta_p) {
  const double gc = fold_gamma(p, eta_p);
  if (gc > 0.0 && gc < kPi / 2) return {-kPi / 2, -gc, gc, kPi / 2};
  return {-kPi / 2, kPi / 2};
}

// gamma in [a, b] with Phi(gamma) = e, Phi monotonic on [a, b] and e strictly
// between Phi(a) and Phi(b): Newton safeguarded by bisection.
double solve_phi(int p, double eta_p, double e, double a, double b, double phi_a, double phi_b) {
  const bool increasing = phi_b > phi_a;
  double lo = a, hi = b;
  double x = a + (b - a) * (e - phi_a) / (phi_b - phi_a);
  for (int it = 0; it < 200; ++it) {
    const double g = Phi(p, x, eta_p) - e;
    if (g == 0.0) return x;
    if ((g < 0.0) == increasing) lo = x; else hi = x;
    const double d = dPhi_dgamma(p, x, eta_p);
    double xn = x - g / d;
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (std::abs(xn - x) <= 1e-16 * (1.0 + std::abs(x)) || hi - lo <= 1e-16) return xn;
    x = xn;
  }
  return x;
}

void add_piece_nodes(int p, double eta_p, double a, double b, int order, double max_len,
                     std::vector<PathNode>& out, bool want_phi = true) {
  const std::size_t first = out.size();
  piece_nodes(a, b, order, max_len, out);
  if (want_phi)
    for (std::size_t k = first; k < out.size(); ++k) out[k].phi = wrap_angle(Phi(p, out[k].gamma, eta_p));
}

}  // namespace

void smooth_nodes(int p, double eta_p, int n_phi, int order, std::vector<PathNode>& out) {
  out.clear();
  const double delta = kTwoPi / n_phi;
  const std::vector<double> br = monotonic_breaks(p, eta_p);
  std::vector<double> cuts;
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    const double pa = Phi(p, a, eta_p), pb = Phi(p, b, eta_p);
    const double lo = std::min(pa, pb), hi = std::max(pa, pb);
    cuts.assign(1, a);
    const long m0 = static_cast<long>(std::ceil((lo + kPi) / delta));
    const long m1 = static_cast<long>(std::floor((hi + kPi) / delta));
    for (long m = m0; m <= m1; ++m) {
      const double e = -kPi + m * delta;
      if (e <= lo || e >= hi) continue;
      cuts.push_back(solve_phi(p, eta_p, e, a, b, pa, pb));
    }
    cuts.push_back(b);
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c)
      add_piece_nodes(p, eta_p, cuts[c], cuts[c + 1], order, kPi / 64, out);
  }
}

void panel_nodes(int p, double eta_p, double max_dphi, int order, std::vector<PathNode>& out,
                 bool want_phi) {
  out.clear();
  const std::vector<double> br = monotonic_breaks(p, eta_p);
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    double slope = std::max(std::abs(dPhi_dgamma(p, a, eta_p)), std::abs(dPhi_dgamma(p, b, eta_p)));
    if (a < 0.0 && b > 0.0) slope = std::max(slope, std::abs(dPhi_dgamma(p, 0.0, eta_p)));
    const double max_len = std::min(kPi / 16, max_dphi / std::max(slope, 1e-12));
    add_piece_nodes(p, eta_p, a, b, order, max_len, out, want_phi);
  }
}

}  // namespace cylinder

}  // namespace fiberlab::analytic
