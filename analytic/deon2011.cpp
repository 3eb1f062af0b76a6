#include "analytic/deon2011.h"

#include <fmt/core.h>
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>

#include "analytic/model_registry.h"
#include "analytic/quadrature.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace deon2011 {

double log_I0(double x) {
  x = std::abs(x);
  if (x < 30.0) {
    // I0(x) = sum_k (x^2/4)^k / (k!)^2: positive terms, no cancellation.
    const double y = 0.25 * x * x;
    double term = 1.0, sum = 1.0;
    for (int k = 1; k < 500; ++k) {
      term *= y / (static_cast<double>(k) * k);
      sum += term;
      if (term < 1e-17 * sum) break;
    }
    return std::log(sum);
  }
  // Asymptotic expansion (Abramowitz & Stegun 9.7.1), a_k = ((2k-1)!!)^2 / (k! 8^k).
  double term = 1.0, sum = 1.0;
  for (int k = 1; k < 60; ++k) {
    term *= (2.0 * k - 1.0) * (2.0 * k - 1.0) / (8.0 * k * x);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return x - 0.5 * std::log(kTwoPi * x) + std::log(sum);
}

double log_csch(double x) { return std::log(2.0) - x - std::log1p(-std::exp(-2.0 * x)); }

double log_M_p(double v, double theta_i, double theta_r) {
  // Eq. 7: M_p = csch(1/v) / (2v) * exp(-sin theta_i sin theta_r / v) * I0(cos theta_i cos theta_r / v).
  // For small v each factor over/underflows while the product is O(1/sqrt v):
  // add the logarithms (their sum loses ~|1/v| * 1e-16 absolutely, i.e.
  // 1e-12 relative at v = 1e-4).
  const double a = std::cos(theta_i) * std::cos(theta_r) / v;
  const double b = std::sin(theta_i) * std::sin(theta_r) / v;
  return log_csch(1.0 / v) - std::log(2.0 * v) - b + log_I0(a);
}

double M_p(double v, double theta_i, double theta_r) { return std::exp(log_M_p(v, theta_i, theta_r)); }

double D_p(double beta, double phi) {
  phi = wrap_angle(phi);
  const int K = static_cast<int>(std::ceil(8.5 * beta / kTwoPi)) + 1;
  const double norm = 1.0 / (std::sqrt(kTwoPi) * beta);
  double s = 0.0;
  for (int k = -K; k <= K; ++k) {
    const double x = (phi - kTwoPi * k) / beta;
    s += std::exp(-0.5 * x * x);
  }
  return s * norm;
}

double F_half_angle(double eta, double theta_i, double theta_r, double phi) {
  const double x = std::sin(theta_i) * std::sin(theta_r) +
                   std::cos(theta_i) * std::cos(theta_r) * std::cos(phi);
  // cos(arccos(x) / 2) = sqrt((1 + x) / 2).
  return fresnel_dielectric(std::sqrt(std::clamp(0.5 * (1.0 + x), 0.0, 1.0)), eta);
}

void N_p(int p, double beta, const Fiber& fiber, double theta_i, double theta_r, double phi,
         int order, std::vector<double>& out) {
  const int C = static_cast<int>(fiber.sigma_a.size());
  out.assign(C, 0.0);
  const double theta_d = 0.5 * (theta_r - theta_i);
  const cylinder::Attenuation att(fiber.eta, theta_d, fiber.sigma_a, fiber.absorption);
  const GaussLegendre& gl = gauss_legendre(order);
  std::vector<double> a(C);
  const bool half = p == 0 && fiber.r_half_angle;
  const double f_half = half ? F_half_angle(fiber.eta, theta_i, theta_r, phi) : 0.0;
  for (int q = 0; q < order; ++q) {
    const double h = gl.x[q];
    const double g = std::asin(h);
    const double d = D_p(beta, phi - cylinder::Phi(p, g, att.eta_p()));
    if (half) {
      for (int c = 0; c < C; ++c) out[c] += 0.5 * gl.w[q] * f_half * d;
    } else {
      att.A(p, g, a.data());
      for (int c = 0; c < C; ++c) out[c] += 0.5 * gl.w[q] * a[c] * d;
    }
  }
}

}  // namespace deon2011

namespace {
constexpr double kSmoothBeta = 1e-4;   // beta_azim below this: the smooth N_p
constexpr double kDeltaBeta = 1e-7;    // beta_long below this: M_p is a delta
constexpr double kDensityFloor = 1e-3; // density(): floor of both betas
constexpr double kResidualTol = 1e-6;  // energy left to the uniform residual
// Per order and theta_r node: bound on a phi bin's change from the Fourier
// terms left out (see FourierSums).
constexpr double kFourierTol = 1e-13;

// Energy of every order p > P per channel, (1/2) int sum_{p>P} A dh, by
// 64-point Gauss-Legendre over gamma_i (the closed-form sum is smooth in gamma).
void residual_energy(const cylinder::Attenuation& att, int P, std::vector<double>& out) {
  const int C = att.channels();
  out.assign(C, 0.0);
  const GaussLegendre& gl = gauss_legendre(64);
  double a[64];
  std::vector<double> buf(C);
  (void)a;
  for (int q = 0; q < 64; ++q) {
    const double g = 0.5 * kPi * gl.x[q];
    att.A_beyond(P, g, buf.data());
    for (int c = 0; c < C; ++c) out[c] += 0.25 * kPi * gl.w[q] * std::cos(g) * buf[c];
  }
}

// Add mass[c] times the wrapped Gaussian's (Eq. 11) mass in every one of n
// uniform bins on [-pi, pi) to res[j * C + c].
void deposit_gaussian(double mu, double beta, const double* mass, int C, int n,
                      std::vector<double>& res) {
  const double delta = kTwoPi / n;
  const double R = 8.5 * beta;
  const long j0 = static_cast<long>(std::floor((mu - R + kPi) / delta));
  const long j1 = static_cast<long>(std::floor((mu + R + kPi) / delta));
  const double s = 1.0 / (std::sqrt(2.0) * beta);
  auto cdf = [&](double e) { return 0.5 * std::erfc(-(e - mu) * s); };
  double prev = cdf(-kPi + j0 * delta);
  for (long j = j0; j <= j1; ++j) {
    const double next = cdf(-kPi + (j + 1) * delta);
    const double frac = next - prev;
    prev = next;
    long jj = j % n;
    if (jj < 0) jj += n;
    double* r = &res[static_cast<std::size_t>(jj) * C];
    for (int c = 0; c < C; ++c) r[c] += frac * mass[c];
  }
}

// The sums F_n = sum over nodes of mass e^{-i n Phi} (n = 0..N) of the
// Fourier deposit of Eq. 11. The nodes are collected first, in segments (one
// per order p), then the sums run with the nodes innermost: each node's
// e^{-i n Phi} by the recurrence z_{n+1} = z_n e^{-i Phi}, the sum over nodes
// in independent lanes (vectorized).
//
// A segment stops at the n beyond which its terms provably cannot move any
// phi bin by more than `tol`: with masses m_k >= 0, |F_n| <= E = sum_k m_k,
// and the bin factor |(e^{i n b} - e^{i n a}) / (i n)| <= min(b - a, 2 / n),
// so the terms n > N change a bin by at most
//   (E / pi) sum_{n > N} g_n min(b - a, 2 / n),   g_n = exp(-n^2 beta^2 / 2).
// High orders carry little energy and stop early.
class FourierSums {
 public:
  void clear(int channels) {
    e_re_.clear();
    e_im_.clear();
    mass_.assign(channels, {});
    segments_.clear();
  }
  // Starts the segment of the nodes added next.
  void begin_segment() { segments_.push_back(e_re_.size()); }
  // A node of the given mass per channel and phasor e^{-i Phi} = re + i im.
  void add(double re, double im, const double* mass) {
    e_re_.push_back(re);
    e_im_.push_back(im);
    for (std::size_t c = 0; c < mass_.size(); ++c) mass_[c].push_back(mass[c]);
  }
  // One SIMD batch of nodes: phasors re[l] + i im[l], masses mass[c] lane l.
  void add_lanes(const double* re, const double* im, const xsimd::batch<double>* mass) {
    constexpr std::size_t W = xsimd::batch<double>::size;
    const std::size_t k = e_re_.size();
    e_re_.insert(e_re_.end(), re, re + W);
    e_im_.insert(e_im_.end(), im, im + W);
    for (std::size_t c = 0; c < mass_.size(); ++c) {
      mass_[c].resize(k + W);
      mass[c].store_unaligned(mass_[c].data() + k);
    }
  }
  // Adds F_n to f_re/f_im[n * C + c], n = 0..N_segment <= N, where the
  // segment's N follows from tail[n] = sum_{n' > n} g_n' min(dphi, 2 / n')
  // (tail.size() == N + 1) and tol as above. Returns the largest N_segment
  // (F_n = 0 above it).
  int coefficients(int N, const std::vector<double>& tail, double tol, std::vector<double>& f_re,
                   std::vector<double>& f_im) const {
    const std::size_t K = e_re_.size(), C = mass_.size();
    int n_used = 0;
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      const std::size_t b = segments_[s], e = s + 1 < segments_.size() ? segments_[s + 1] : K;
      double energy = 0.0;
      for (std::size_t c = 0; c < C; ++c) {
        double sum = 0.0;
        for (std::size_t k = b; k < e; ++k) sum += mass_[c][k];
        energy = std::max(energy, sum);
      }
      int n_seg = N;
      while (n_seg > 0 && energy / kPi * tail[n_seg - 1] <= tol) --n_seg;
      n_used = std::max(n_used, n_seg);
      for (std::size_t k0 = b; k0 < e; k0 += kTile) coefficients_tile(k0, std::min(kTile, e - k0), n_seg, f_re, f_im);
    }
    return n_used;
  }

 private:
  // Tiles of kTile nodes keep their z in the first-level cache across the n
  // loop. Up to 4 channels run in one pass over the nodes (a template on the
  // count keeps their sums in registers), more one channel at a time.
  void coefficients_tile(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                         std::vector<double>& f_im) const {
    switch (mass_.size()) {
      case 1: return tile_fused<1>(k0, len, N, f_re, f_im);
      case 2: return tile_fused<2>(k0, len, N, f_re, f_im);
      case 3: return tile_fused<3>(k0, len, N, f_re, f_im);
      case 4: return tile_fused<4>(k0, len, N, f_re, f_im);
      default:
        for (std::size_t c = 0; c < mass_.size(); ++c) tile_channel(c, k0, len, N, f_re, f_im);
    }
  }
  template <std::size_t C>
  void tile_fused(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                  std::vector<double>& f_im) const {
    double zr[kTile], zi[kTile];
    std::fill(zr, zr + len, 1.0);
    std::fill(zi, zi + len, 0.0);
    const double* er = e_re_.data() + k0;
    const double* ei = e_im_.data() + k0;
    const double* m[C];
    for (std::size_t c = 0; c < C; ++c) m[c] = mass_[c].data() + k0;
    for (int n = 0; n <= N; ++n) {
      // kLanes partial sums in one vector register each (GCC vector
      // extension), added up at the end; z advanced to z e^{-i Phi} in the
      // same pass.
      Lanes sr[C] = {}, si[C] = {};
      std::size_t k = 0;
      for (; k + kLanes <= len; k += kLanes) {
        const Lanes a = load(zr + k), b = load(zi + k);
        for (std::size_t c = 0; c < C; ++c) {
          const Lanes mk = load(m[c] + k);
          sr[c] += mk * a;
          si[c] += mk * b;
        }
        const Lanes cr = load(er + k), ci = load(ei + k);
        store(zr + k, a * cr - b * ci);
        store(zi + k, a * ci + b * cr);
      }
      double sum_r[C], sum_i[C];
      for (std::size_t c = 0; c < C; ++c) {
        sum_r[c] = sum_i[c] = 0.0;
        for (std::size_t l = 0; l < kLanes; ++l) sum_r[c] += sr[c][l], sum_i[c] += si[c][l];
      }
      for (; k < len; ++k) {
        for (std::size_t c = 0; c < C; ++c) {
          sum_r[c] += m[c][k] * zr[k];
          sum_i[c] += m[c][k] * zi[k];
        }
        const double next_re = zr[k] * er[k] - zi[k] * ei[k];
        zi[k] = zr[k] * ei[k] + zi[k] * er[k];
        zr[k] = next_re;
      }
      for (std::size_t c = 0; c < C; ++c) {
        f_re[static_cast<std::size_t>(n) * C + c] += sum_r[c];
        f_im[static_cast<std::size_t>(n) * C + c] += sum_i[c];
      }
    }
  }
  void tile_channel(std::size_t c, std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                    std::vector<double>& f_im) const {
    const std::size_t C = mass_.size();
    double zr[kTile], zi[kTile];
    std::fill(zr, zr + len, 1.0);
    std::fill(zi, zi + len, 0.0);
    const double* er = e_re_.data() + k0;
    const double* ei = e_im_.data() + k0;
    const double* m = mass_[c].data() + k0;
    for (int n = 0; n <= N; ++n) {
      double sum_r = 0.0, sum_i = 0.0;
      for (std::size_t k = 0; k < len; ++k) {
        sum_r += m[k] * zr[k];
        sum_i += m[k] * zi[k];
        const double next_re = zr[k] * er[k] - zi[k] * ei[k];
        zi[k] = zr[k] * ei[k] + zi[k] * er[k];
        zr[k] = next_re;
      }
      f_re[static_cast<std::size_t>(n) * C + c] += sum_r;
      f_im[static_cast<std::size_t>(n) * C + c] += sum_i;
    }
  }
  static constexpr std::size_t kLanes = 8, kTile = 256;
  typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));
  static Lanes load(const double* p) {
    Lanes v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static void store(double* p, Lanes v) { std::memcpy(p, &v, sizeof v); }
  std::vector<double> e_re_, e_im_;
  std::vector<std::vector<double>> mass_;  // [channel][node]
  std::vector<std::size_t> segments_;      // first node of each segment
};

// (re + i im)^n for n >= 0 by repeated squaring, any number type.
template <class N>
void complex_power(N& re, N& im, int n) {
  N r(1.0), i(0.0), xr = re, xi = im;
  for (; n > 0; n >>= 1) {
    if (n & 1) {
      const N t = r * xr - i * xi;
      i = r * xi + i * xr;
      r = t;
    }
    const N t = xr * xr - xi * xi;
    xi = N(2.0) * xr * xi;
    xr = t;
  }
  re = r;
  im = i;
}

// Order p's nodes into the Fourier sums: masses weight * A(p, gamma) per
// channel and the phasor e^{-i Phi(p, gamma)}, from the sine and cosine of
// gamma alone. Phi = 2 p gamma_t - 2 gamma_i + p pi (cylinder_paths.h) gives
//   e^{-i Phi} = (-1)^p (cos gamma_t - i sin gamma_t)^(2p) (cos gamma_i + i sin gamma_i)^2,
// sin gamma_t = sin gamma_i / eta' (|sin gamma_i| <= 1 < eta'): no asin, no
// wrap of Phi, no sine and cosine of Phi. One node per SIMD lane (xsimd).
template <class N>
void fourier_node(const cylinder::Attenuation& att, int p, N ci, N si, N weight, N* mass, N& re, N& im) {
  using std::max;
  using std::sqrt;
  att.A(p, ci, si, mass);
  for (int c = 0; c < att.channels(); ++c) mass[c] *= weight;
  const N st = si / N(att.eta_p()), ct = sqrt(max(N(0.0), N(1.0) - st * st));
  N tr = ct, ti = -st;
  complex_power(tr, ti, 2 * p);
  const N ir = ci * ci - si * si, ii = N(2.0) * ci * si;  // e^{2 i gamma_i}
  const N sign((p % 2) ? -1.0 : 1.0);
  re = sign * (tr * ir - ti * ii);
  im = sign * (tr * ii + ti * ir);
}

void add_fourier_nodes(const cylinder::Attenuation& att, int p, const std::vector<cylinder::PathNode>& nodes,
                       FourierSums& fourier) {
  using Batch = xsimd::batch<double>;
  constexpr std::size_t W = Batch::size;
  const int C = att.channels();
  fourier.begin_segment();
  std::vector<Batch> mass_b(C);
  std::vector<double> mass(C);
  alignas(64) double ci[W], si[W], w[W], re[W], im[W];
  std::size_t k = 0;
  for (; k + W <= nodes.size(); k += W) {
    for (std::size_t l = 0; l < W; ++l)
      ci[l] = nodes[k + l].cos_gamma, si[l] = nodes[k + l].sin_gamma, w[l] = nodes[k + l].weight;
    Batch bre, bim;
    fourier_node(att, p, Batch::load_aligned(ci), Batch::load_aligned(si), Batch::load_aligned(w),
                 mass_b.data(), bre, bim);
    bre.store_aligned(re);
    bim.store_aligned(im);
    fourier.add_lanes(re, im, mass_b.data());
  }
  for (; k < nodes.size(); ++k) {
    double r, i;
    fourier_node(att, p, nodes[k].cos_gamma, nodes[k].sin_gamma, nodes[k].weight, mass.data(), r, i);
    fourier.add(r, i, mass.data());
  }
}

// Eq. 12's Fresnel term F(eta, arccos(wi . wr) / 2) (deon2011::F_half_angle)
// at every phi point k of a theta_r: wi . wr = a + b cos(phi_k) with
// a = sin theta_i sin theta_r, b = cos theta_i cos theta_r, and
// cos(arccos(x) / 2) = sqrt((1 + x) / 2). SIMD lanes (xsimd) through the
// shared generic Fresnel (common/fresnel.h).
void half_angle_fresnel(double a, double b, const std::vector<double>& cos_phi, double eta,
                        std::vector<double>& out) {
  using Batch = xsimd::batch<double>;
  constexpr std::size_t W = Batch::size;
  const std::size_t n = cos_phi.size();
  out.resize(n);
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    const Batch x = Batch(a) + Batch(b) * Batch::load_unaligned(cos_phi.data() + k);
    const Batch u = xsimd::sqrt(xsimd::min(Batch(1.0), xsimd::max(Batch(0.0), 0.5 * (1.0 + x))));
    fresnel_dielectric(u, Batch(eta)).store_unaligned(out.data() + k);
  }
  for (; k < n; ++k)
    out[k] = fresnel_dielectric(std::sqrt(std::clamp(0.5 * (1.0 + a + b * cos_phi[k]), 0.0, 1.0)), eta);
}

// G_0(phi) = (1/2) int D_0(phi - Phi(0, h)) dh = (D_0 * |cos(psi/2)|/4)(phi):
// the R lobe's azimuthal shape before Eq. 12's direction-dependent Fresnel.
//
// For beta >= kG0SeriesBeta by its Fourier series: |cos(psi/2)| =
// 2/pi + sum_{k>=1} (-1)^(k+1) 4 / (pi (4k^2 - 1)) cos(k psi), and the
// detector multiplies coefficient k by g_k = exp(-k^2 beta^2 / 2), so
//   G_0(phi) = 1/4 [2/pi + sum_k (-1)^(k+1) 4 g_k / (pi (4k^2 - 1)) cos(k phi)],
// summed to the K = ceil(8.9 / beta) with g_K < 1e-17 (the terms beyond add
// up to < 1e-20); cos(k phi) by the Chebyshev recurrence (rounding ~K^2 1e-16
// on terms that shrink as g_k / k^2). Narrower detectors: the quadrature below.
constexpr double kG0SeriesBeta = 0.005;
double G0_series(double phi, double beta) {
  const int K = static_cast<int>(std::ceil(8.9 / beta));
  const double c1 = std::cos(phi);
  double c_prev = 1.0, c = c1, s = 2.0 / kPi;
  for (int k = 1; k <= K; ++k) {
    const double g = std::exp(-0.5 * k * k * beta * beta);
    s += ((k % 2) ? 4.0 : -4.0) * g / (kPi * (4.0 * k * k - 1.0)) * c;
    const double c_next = 2.0 * c1 * c - c_prev;
    c_prev = c;
    c = c_next;
  }
  return 0.25 * s;
}

// By composite Gauss-Legendre over psi, split at the kinks of |cos(psi/2)|.
double G0_quadrature(double phi, double beta, double refine) {
  const double a = phi - 8.5 * beta, b = phi + 8.5 * beta;
  std::vector<double> cuts{a};
  // |cos(psi/2)| has kinks at psi = pi + 2 pi k: split there.
  for (long k = static_cast<long>(std::ceil((a - kPi) / kTwoPi)); kPi + kTwoPi * k < b; ++k)
    cuts.push_back(kPi + kTwoPi * k);
  cuts.push_back(b);
  const GaussLegendre& gl = gauss_legendre(8);
  const double max_len = std::min(0.5 * beta, 0.2) / refine;
  const double norm = 1.0 / (std::sqrt(kTwoPi) * beta);
  double s = 0.0;
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    const int m = std::max(1, static_cast<int>(std::ceil((cuts[c + 1] - cuts[c]) / max_len)));
    const double len = (cuts[c + 1] - cuts[c]) / m;
    for (int k = 0; k < m; ++k) {
      const double mid = cuts[c] + (k + 0.5) * len;
      for (int q = 0; q < 8; ++q) {
        const double psi = mid + 0.5 * len * gl.x[q];
        const double x = (phi - psi) / beta;
        s += 0.5 * len * gl.w[q] * norm * std::exp(-0.5 * x * x) * std::abs(std::cos(0.5 * psi)) * 0.25;
      }
    }
  }
  return s;
}

double G0(double phi, double beta, double refine) {
  if (beta < kSmoothBeta) return std::abs(std::cos(0.5 * phi)) * 0.25;
  return beta >= kG0SeriesBeta ? G0_series(phi, beta) : G0_quadrature(phi, beta, refine);
}

// One group of orders sharing M_p and the detector: a single p, or (open)
// every p >= p0 of the last lobe.
struct Term {
  int lobe, p0, p1;  // orders p0..p1 traced explicitly
  bool residual;     // plus every p > p1, spread uniformly in phi
  bool coarse;       // high orders (p > kFineOrders): base theta resolution
  double v, alpha, beta;
};
// Orders of the last lobe above this get the base Chebyshev count in theta_r:
// their energy is small, so their (equally sharp) features need less
// relative accuracy.
constexpr int kFineOrders = 20;

}  // namespace

Deon2011::Deon2011(ModelParams params) : params_(std::move(params)), max_order_(params_.max_order) {
  auto bad = [](const std::string& what) { throw Error("deon2011: " + what); };
  if (!(params_.eta > 1.0)) bad(fmt::format("eta = {} must be > 1", params_.eta));
  if (params_.eccentricity != 1.0)
    bad(fmt::format("eccentricity = {} unsupported (the model is for circular fibers: 1)",
                    params_.eccentricity));
  if (params_.lobes < 1) bad("lobes must be >= 1");
  if (params_.sigma_a.empty()) bad("sigma_a needs at least one channel");
  if (params_.beta_long.empty() || params_.beta_azim.empty() || params_.alpha.empty())
    bad("beta_long, beta_azim and alpha need at least one entry");
  for (double b : params_.beta_long)
    if (!(b >= 0.0) || !std::isfinite(b)) bad(fmt::format("beta_long = {} must be >= 0", b));
  for (double b : params_.beta_azim)
    if (!(b >= 0.0) || !std::isfinite(b)) bad(fmt::format("beta_azim = {} must be >= 0", b));
  for (double s : params_.sigma_a)
    if (!(s >= 0.0) || !std::isfinite(s)) bad(fmt::format("sigma_a = {} must be >= 0", s));
  if (params_.quadrature_order < 1) bad("quadrature_order must be >= 1");
  if (params_.max_order < 0) bad("max_order must be >= 0");
}

void Deon2011::density(int lobe, double theta_i, double, double theta_r, double phi,
                       std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size());
  out.assign(C, 0.0);
  const int L = params_.lobes;
  const deon2011::Fiber fiber{params_.eta, params_.sigma_a, params_.absorption,
                              params_.r_half_angle_fresnel};
  const double cos_r = std::cos(theta_r);
  // theta_r at which N_p is evaluated (its theta_d = (theta_rn - theta_i) / 2).
  const double theta_rn = params_.specular_theta_d ? -theta_i : theta_r;
  int p_end = lobe;
  std::vector<double> res;
  if (lobe >= L - 1) {
    const cylinder::Attenuation att(params_.eta, 0.5 * (theta_rn - theta_i), params_.sigma_a,
                                    params_.absorption);
    for (p_end = lobe;; ++p_end) {
      residual_energy(att, p_end, res);
      if (*std::max_element(res.begin(), res.end()) <= kResidualTol || p_end >= max_order_) break;
    }
  }
  std::vector<double> n;
  for (int p = lobe; p <= p_end; ++p) {
    const double bl = std::max(for_lobe(params_.beta_long, p), kDensityFloor);
    const double ba = std::max(for_lobe(params_.beta_azim, p), kDensityFloor);
    const double m = deon2011::M_p(bl * bl, theta_i, theta_r - for_lobe(params_.alpha, p));
    // Eq. 10 quadrature: the paper's 35 points suffice for beta >= 2 deg;
    // below, scale the order as 1 / beta.
    const int order = std::min(
        4000, std::max(params_.quadrature_order,
                       static_cast<int>(std::ceil(params_.quadrature_order * deg_to_rad(2.0) / ba))));
    deon2011::N_p(p, ba, fiber, theta_i, theta_rn, phi, order, n);
    for (int c = 0; c < C; ++c) out[c] += m * n[c] * cos_r;
  }
  if (lobe >= L - 1) {
    const double bl = std::max(for_lobe(params_.beta_long, p_end), kDensityFloor);
    const double m = deon2011::M_p(bl * bl, theta_i, theta_r - for_lobe(params_.alpha, p_end));
    for (int c = 0; c < C; ++c) out[c] += m * res[c] / kTwoPi * cos_r;
  }
}

std::vector<double> Deon2011::bin_probabilities(const BinGrid& grid, double theta_i,
                                                double) const {
  const int nt = grid.n_theta(), np = grid.n_phi(), L = params_.lobes;
  const int C = static_cast<int>(params_.sigma_a.size());
  std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
  const deon2011::Fiber fiber{params_.eta, params_.sigma_a, params_.absorption,
                              params_.r_half_angle_fresnel};

  // Terms: lobes 0..L-2 one order each; the last lobe one term per order
  // whose parameters still differ, then one open term.
  const int list_len = static_cast<int>(std::max(
      {params_.beta_long.size(), params_.beta_azim.size(), params_.alpha.size()}));
  std::vector<Term> terms;
  auto make_term = [&](int lobe, int p, int p1, bool residual, bool coarse) {
    const double bl = for_lobe(params_.beta_long, p);
    return Term{lobe, p, p1, residual, coarse, bl * bl, for_lobe(params_.alpha, p),
                for_lobe(params_.beta_azim, p)};
  };
  for (int l = 0; l < L - 1; ++l) terms.push_back(make_term(l, l, l, false, false));
  const int p_open = std::max(L - 1, list_len - 1);
  for (int p = L - 1; p < p_open; ++p) terms.push_back(make_term(L - 1, p, p, false, false));
  // The last explicit order: where the remaining energy drops below
  // kResidualTol (or max_order), judged at the specular direction, the M_p
  // peak and 3 sigma either side; fixed for the whole theta_r range so that
  // N_p stays smooth in theta_r.
  std::vector<double> res;
  int p_last = p_open;
  {
    const double bl = for_lobe(params_.beta_long, p_open), al = for_lobe(params_.alpha, p_open);
    std::vector<double> probes{-theta_i};
    if (!params_.specular_theta_d)
      for (double d : {-3.0, 0.0, 3.0}) probes.push_back(al - theta_i + d * bl);
    for (double tr : probes) {
      tr = std::clamp(tr, -kPi / 2, kPi / 2);
      const cylinder::Attenuation att(params_.eta, 0.5 * (tr - theta_i), params_.sigma_a,
                                      params_.absorption);
      for (int P = p_open;; ++P) {
        residual_energy(att, P, res);
        if (*std::max_element(res.begin(), res.end()) <= kResidualTol || P >= max_order_) {
          p_last = std::max(p_last, P);
          break;
        }
      }
    }
  }
  if (p_last <= kFineOrders || p_open > kFineOrders) {
    terms.push_back(make_term(L - 1, p_open, p_last, true, p_open > kFineOrders));
  } else {
    terms.push_back(make_term(L - 1, p_open, kFineOrders, false, false));
    terms.push_back(make_term(L - 1, kFineOrders + 1, p_last, true, true));
  }

  // Eq. 12 needs the R lobe's azimuthal shape at Gauss points of every phi bin.
  constexpr int kPhiOrder = 6;
  const GaussLegendre& glp = gauss_legendre(kPhiOrder);
  const double dphi = kTwoPi / np;
  std::vector<double> g0;
  const bool r_special = params_.r_half_angle_fresnel && terms.front().p0 == 0;
  // cos(phi) at those points, hoisted out of Eq. 12's Fresnel term (which is
  // evaluated for every theta_r point and phi point: F_half_angle inlined).
  std::vector<double> cos_ph;
  if (r_special) {
    g0.resize(static_cast<std::size_t>(np) * kPhiOrder);
    cos_ph.resize(g0.size());
    for (int j = 0; j < np; ++j)
      for (int q = 0; q < kPhiOrder; ++q) {
        const double ph = -kPi + (j + 0.5) * dphi + 0.5 * dphi * glp.x[q];
        g0[j * kPhiOrder + q] = G0(ph, terms.front().beta, refine_);
        cos_ph[j * kPhiOrder + q] = std::cos(ph);
      }
  }
  const double sin_i = std::sin(theta_i), cos_i = std::cos(theta_i);
  // g0 times the phi quadrature weights: row j of the R lobe at theta_r is
  // sum_q F_jq gw[jq] (Eq. 12's Fresnel F_jq = F(eta, arccos(wi . wr) / 2)).
  std::vector<double> gw(g0.size()), r_fresnel(g0.size());
  for (std::size_t jq = 0; jq < g0.size(); ++jq) gw[jq] = 0.5 * dphi * glp.w[jq % kPhiOrder] * g0[jq];
  auto r_row = [&](double theta_r, std::vector<double>& row) {
    half_angle_fresnel(sin_i * std::sin(theta_r), cos_i * std::cos(theta_r), cos_ph, params_.eta, r_fresnel);
    row.assign(np, 0.0);
    for (int j = 0; j < np; ++j)
      for (int q = 0; q < kPhiOrder; ++q) row[j] += r_fresnel[j * kPhiOrder + q] * gw[j * kPhiOrder + q];
  };
  std::vector<double> r_row_buf;

  std::vector<cylinder::PathNode> nodes;
  std::vector<double> a(C);
  std::vector<double> bin_factor_re, bin_factor_im, bin_sum;  // [n * np + j], see the Fourier deposit
  FourierSums fourier;
  std::vector<double> fourier_tail;
  // Phi-bin integrals of sum_{p in term} N_p at exit inclination theta_r: [j * C + c].
  auto azimuthal = [&](const Term& t, double theta_r, std::vector<double>& nb) {
    nb.assign(static_cast<std::size_t>(np) * C, 0.0);
    const cylinder::Attenuation att(params_.eta, 0.5 * (theta_r - theta_i), params_.sigma_a,
                                    params_.absorption);
    // Wide detectors: deposit through the Fourier series of Eq. 11 (terms up
    // to g_n < 1e-17) unless it is 64x longer than the erfc window per node
    // (the same sum either way; measured at 180 phi bins, 3 channels: the
    // Fourier deposit is 7x faster at beta 3 deg, 4x at 2 deg, 2x at 1 deg,
    // and 1.6x slower at 0.5 deg, where the erfc window is 4 bins).
    int n_fourier = 0;
    if (t.beta >= kSmoothBeta) {
      const int n_max = static_cast<int>(std::ceil(8.9 / t.beta));
      const double window = 17.0 * t.beta / dphi;
      if (n_max <= 64.0 * window) n_fourier = n_max;
    }
    // F_n = sum over nodes of mass e^{-i n Phi}, real and imaginary parts apart
    // (plain arithmetic: std::complex's NaN-checking products are 3x slower).
    std::vector<double> f_re(static_cast<std::size_t>(n_fourier + 1) * C, 0.0), f_im(f_re.size(), 0.0);
    fourier.clear(C);
    for (int p = t.p0; p <= t.p1; ++p) {
      if (p == 0 && r_special) {
        r_row(theta_r, r_row_buf);
        for (int j = 0; j < np; ++j)
          for (int c = 0; c < C; ++c) nb[static_cast<std::size_t>(j) * C + c] += r_row_buf[j];
      } else if (t.beta < kSmoothBeta) {
        cylinder::add_smooth_lobe(att, p, np, nb);
      } else {
        // Panels over which Phi moves by up to 4 beta: 8 Gauss points resolve the
        // detector to ~1e-12 there (checked against beta / 4 panels).
        cylinder::panel_nodes(p, att.eta_p(), std::min(4.0 * t.beta, 1.0) / refine_, 8, nodes,
                              n_fourier == 0);
        if (n_fourier > 0) {
          add_fourier_nodes(att, p, nodes, fourier);
        } else {
          for (const auto& nd : nodes) {
            att.A(p, nd.gamma, a.data());
            for (int c = 0; c < C; ++c) a[c] *= nd.weight;
            deposit_gaussian(nd.phi, t.beta, a.data(), C, np, nb);
          }
        }
      }
    }
    if (n_fourier > 0) {
      // tail[n] = sum_{n' > n} g_n' min(dphi, 2 / n'): the truncation bound.
      fourier_tail.assign(n_fourier + 1, 0.0);
      for (int n = n_fourier - 1; n >= 0; --n)
        fourier_tail[n] = fourier_tail[n + 1] + std::exp(-0.5 * (n + 1.0) * (n + 1.0) * t.beta * t.beta) *
                                                    std::min(dphi, 2.0 / (n + 1.0));
      const int n_used = fourier.coefficients(n_fourier, fourier_tail, kFourierTol / (refine_ * refine_), f_re, f_im);
      // Eq. 11 in Fourier form: the wrapped Gaussian's coefficients are
      // g_n = exp(-n^2 beta^2 / 2), so the bin mass is
      // F_0 dphi / 2pi + (1/pi) Re sum_{n>=1} F_n g_n (e^{i n b} - e^{i n a}) / (i n).
      // The bin factors (e^{i n b} - e^{i n a}) / (i n) depend on neither
      // theta_r nor the channel: tabulated once per call (bin_factor).
      if (static_cast<int>(bin_factor_re.size()) < (n_fourier + 1) * np) {
        bin_factor_re.assign(static_cast<std::size_t>(n_fourier + 1) * np, 0.0);
        bin_factor_im.assign(bin_factor_re.size(), 0.0);
        for (int n = 1; n <= n_fourier; ++n)
          for (int j = 0; j < np; ++j) {
            const double lo = -kPi + j * dphi, hi = lo + dphi;
            const std::complex<double> d =
                (std::polar(1.0, n * hi) - std::polar(1.0, n * lo)) / std::complex<double>(0.0, n);
            bin_factor_re[static_cast<std::size_t>(n) * np + j] = d.real();
            bin_factor_im[static_cast<std::size_t>(n) * np + j] = d.imag();
          }
      }
      for (int n = 1; n <= n_used; ++n) {
        const double g = std::exp(-0.5 * n * n * t.beta * t.beta) / kPi;
        for (int c = 0; c < C; ++c) {
          f_re[static_cast<std::size_t>(n) * C + c] *= g;
          f_im[static_cast<std::size_t>(n) * C + c] *= g;
        }
      }
      // Bin by bin the same sum over n as written above, run with the bins
      // innermost (contiguous, independent: vectorized) per channel.
      for (int c = 0; c < C; ++c) {
        bin_sum.assign(np, f_re[c] * dphi / kTwoPi);
        for (int n = 1; n <= n_used; ++n) {
          const double fr = f_re[static_cast<std::size_t>(n) * C + c];
          const double fi = f_im[static_cast<std::size_t>(n) * C + c];
          const double* d_re = &bin_factor_re[static_cast<std::size_t>(n) * np];
          const double* d_im = &bin_factor_im[static_cast<std::size_t>(n) * np];
          double* v = bin_sum.data();
          for (int j = 0; j < np; ++j) v[j] += fr * d_re[j] - fi * d_im[j];
        }
        for (int j = 0; j < np; ++j) nb[static_cast<std::size_t>(j) * C + c] += bin_sum[j];
      }
    }
    if (t.residual) {
      residual_energy(att, t.p1, res);
      for (int j = 0; j < np; ++j)
        for (int c = 0; c < C; ++c) nb[static_cast<std::size_t>(j) * C + c] += res[c] / np;
    }
  };

  std::vector<double> nb;
  const GaussLegendre& glm = gauss_legendre(8);
  for (const Term& t : terms) {
    double* lobe_out = &out[static_cast<std::size_t>(t.lobe) * nt * np * C];
    if (t.v < kDeltaBeta * kDeltaBeta) {
      // M_p -> delta(theta_r - alpha + theta_i) / cos(theta_i): all of it in one theta bin.
      const double tr = t.alpha - theta_i;
      if (std::abs(tr) > kPi / 2) continue;  // shifted off the sphere (documented loss)
      const double w = std::cos(tr) / std::cos(theta_i);
      const double trn = params_.specular_theta_d ? -theta_i : tr;
      azimuthal(t, trn, nb);
      const int i = grid.theta_bin(tr);
      for (std::size_t k = 0; k < nb.size(); ++k) lobe_out[static_cast<std::size_t>(i) * np * C + k] += w * nb[k];
      continue;
    }
    // Support of M_p cos(theta_r): where it is within e^-30 (1e-13) of its
    // maximum; what lies beyond is dropped (below 1e-12 of the lobe).
    auto log_weight = [&](double tr) {
      return deon2011::log_M_p(t.v, theta_i, tr - t.alpha) + std::log(std::max(std::cos(tr), 1e-300));
    };
    constexpr int kScan = 512;
    const double step = kPi / kScan;
    double peak = log_weight(std::clamp(t.alpha - theta_i, -kPi / 2, kPi / 2));
    std::vector<double> lw(kScan + 1);
    for (int s = 0; s <= kScan; ++s) peak = std::max(peak, lw[s] = log_weight(-kPi / 2 + s * step));
    int s0 = kScan, s1 = 0;
    for (int s = 0; s <= kScan; ++s)
      if (lw[s] > peak - 30.0) s0 = std::min(s0, s), s1 = std::max(s1, s);
    const double peak_at = std::clamp(t.alpha - theta_i, -kPi / 2, kPi / 2);
    double lo = std::max(-kPi / 2, std::min(-kPi / 2 + (s0 - 1) * step, peak_at - step));
    double hi = std::min(kPi / 2, std::max(-kPi / 2 + (s1 + 1) * step, peak_at + step));
    // Quadrature points of M_p cos(theta_r) over each theta bin within
    // [lo, hi], panels below sqrt(v)/3, split at theta_r = -theta_i (where
    // Eq. 12's Fresnel term has a kink in the forward direction).
    struct ThetaPoint {
      int i;
      double theta, w;
    };
    std::vector<ThetaPoint> tp;
    const double max_len = std::min(std::sqrt(t.v) / 3.0, 0.05) / refine_;
    for (int i = 0; i < nt; ++i) {
      const double t0 = std::max(grid.theta_edges[i], lo), t1 = std::min(grid.theta_edges[i + 1], hi);
      if (!(t1 > t0)) continue;
      std::vector<double> cuts{t0};
      if (-theta_i > t0 && -theta_i < t1) cuts.push_back(-theta_i);
      cuts.push_back(t1);
      for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
        const int m = std::max(1, static_cast<int>(std::ceil((cuts[c + 1] - cuts[c]) / max_len)));
        const double len = (cuts[c + 1] - cuts[c]) / m;
        for (int pn = 0; pn < m; ++pn) {
          const double mid = cuts[c] + (pn + 0.5) * len;
          for (int q = 0; q < 8; ++q) {
            const double tr = mid + 0.5 * len * glm.x[q];
            const double wm = 0.5 * len * glm.w[q] * std::exp(log_weight(tr));
            if (wm > 0.0) tp.push_back({i, tr, wm});
          }
        }
      }
    }
    if (t.p0 == 0 && t.p1 == 0 && r_special && !t.residual && !params_.specular_theta_d) {
      // R with Eq. 12: F depends on (theta_r, phi) itself: direct 2D quadrature.
      for (const ThetaPoint& pt : tp) {
        r_row(pt.theta, r_row_buf);
        for (int j = 0; j < np; ++j) {
          double* o = &lobe_out[(static_cast<std::size_t>(pt.i) * np + j) * C];
          for (int c = 0; c < C; ++c) o[c] += pt.w * r_row_buf[j];
        }
      }
      continue;
    }
    if (params_.specular_theta_d) {
      // N_p does not depend on theta_r: one evaluation, times int_bin M cos.
      azimuthal(t, -theta_i, nb);
      std::vector<double> wbin(nt, 0.0);
      for (const ThetaPoint& pt : tp) wbin[pt.i] += pt.w;
      for (int i = 0; i < nt; ++i) {
        if (wbin[i] == 0.0) continue;
        double* o = &lobe_out[static_cast<std::size_t>(i) * np * C];
        for (std::size_t x = 0; x < nb.size(); ++x) o[x] += wbin[i] * nb[x];
      }
      continue;
    }
    // Chebyshev points (second kind) on [lo, hi] for N_p's theta_r
    // dependence. Its features (caustics moving with theta_d) are about
    // beta_azim wide in phi: more points for narrow detectors (measured:
    // 8x the base count at 2 deg reaches 1e-7 of the bin probabilities).
    // Orders p > 2 move their caustics faster with theta_d: twice the points.
    const double narrow = t.coarse ? 1.0
                                   : std::clamp(deg_to_rad(16.0) / std::max(t.beta, 1e-12), 1.0, 16.0) *
                                         (t.p1 > 2 ? 2.0 : 1.0);
    const int nc = std::clamp(static_cast<int>(std::ceil(refine_ * narrow * (4.0 + 8.0 * (hi - lo)))), 3, 200);
    std::vector<double> xs(nc), bw(nc);
    for (int k = 0; k < nc; ++k) {
      xs[k] = 0.5 * (lo + hi) - 0.5 * (hi - lo) * std::cos(kPi * k / (nc - 1));
      bw[k] = ((k % 2) ? -1.0 : 1.0) * ((k == 0 || k == nc - 1) ? 0.5 : 1.0);
    }
    // Moments m[i][k] = int_{bin i} M_p cos(theta_r) l_k(theta_r) d theta_r.
    std::vector<double> mom(static_cast<std::size_t>(nt) * nc, 0.0), lk(nc);
    for (const ThetaPoint& pt : tp) {
      int exact = -1;
      double den = 0.0;
      for (int k = 0; k < nc; ++k) {
        const double d = pt.theta - xs[k];
        if (d == 0.0) { exact = k; break; }
        den += (lk[k] = bw[k] / d);
      }
      double* row = &mom[static_cast<std::size_t>(pt.i) * nc];
      if (exact >= 0) {
        row[exact] += pt.w;
      } else {
        for (int k = 0; k < nc; ++k) row[k] += pt.w * lk[k] / den;
      }
    }
    for (int k = 0; k < nc; ++k) {
      azimuthal(t, xs[k], nb);
      for (int i = 0; i < nt; ++i) {
        const double mk = mom[static_cast<std::size_t>(i) * nc + k];
        if (mk == 0.0) continue;
        double* o = &lobe_out[static_cast<std::size_t>(i) * np * C];
        for (std::size_t x = 0; x < nb.size(); ++x) o[x] += mk * nb[x];
      }
    }
  }
  // The interpolation in theta_r can leave rounding-level negatives (1e-28)
  // where the probability is zero.
  for (double& x : out) x = std::max(x, 0.0);
  return out;
}

std::unique_ptr<Model> make_deon2011(const ModelParams& params) {
  return std::make_unique<Deon2011>(params);
}

}  // namespace fiberlab::analytic

// ---- Parameter table and registry entry -------------------------------------------

namespace fiberlab::analytic {

namespace {
std::vector<std::string> deon_approximations(const ModelParams& p) {
  std::vector<std::string> out;
  out.push_back(p.absorption == Absorption::Published
                    ? "absorption=published: exp(-4 sigma_a' cos^2 gamma_t) (as published; not the chord)"
                    : "absorption=chord: the chord length (SPEC s7)");
  if (p.r_half_angle_fresnel)
    out.push_back("r_fresnel=half_angle: R lobe Fresnel at half the angle between wi and wr (Eq. 12), "
                  "not per h (Eq. 14)");
  out.push_back(p.specular_theta_d
                    ? "n_theta_d=specular: N_p at theta_d = -theta_i (the simulator's exit_blur exactly)"
                    : "n_theta_d=exit: N_p evaluated at each exit direction's theta_d (per bin), as published");
  out.push_back("M_p: von Mises-Fisher longitudinal lobe (Eq. 7); tilt as a shift of theta_r (alpha)");
  out.push_back(fmt::format("orders p > {} of the last lobe: their energy spread uniformly in phi",
                            p.max_order));
  return out;
}
}  // namespace

ModelInfo deon2011_info() {
  ModelInfo m;
  m.name = "deon2011";
  m.reference = "d'Eon, Francois, Hill, Letteri, Aubry 2011, An Energy-Conserving Hair Reflectance Model";
  m.params = {
      eta_param(),
      sigma_a_param(),
      beta_long_param("longitudinal width per lobe p: v_p = beta_long_p^2 in M_p (Eq. 7), ~ the sd of theta_r"),
      beta_azim_param("azimuthal width per lobe p: sd of the Gaussian detector D_p (Eq. 11)"),
      alpha_param("shift of theta_r per lobe p (M_p(theta_r - alpha_p))"),
      absorption_param("published"),
      lobes_param(),
      integer_param("quadrature_order", "Gauss-Legendre order of the N_p integral over h (density())", "35",
                    &ModelParams::quadrature_order, 1),
      choice_param(
          "r_fresnel", "Fresnel of the R lobe: Eq. 12 half angle (published) or Eq. 14 per h", "half_angle",
          {"half_angle", "per_h"}, [](ModelParams& p, int i) { p.r_half_angle_fresnel = i == 0; },
          [](const ModelParams& p) { return p.r_half_angle_fresnel ? 0 : 1; }),
      integer_param("max_order", "highest order p traced explicitly in the last lobe", "40",
                    &ModelParams::max_order, 1),
      choice_param(
          "n_theta_d", "theta_d of N_p: the exit direction's (published) or the specular cone's", "exit",
          {"exit", "specular"}, [](ModelParams& p, int i) { p.specular_theta_d = i == 1; },
          [](const ModelParams& p) { return p.specular_theta_d ? 1 : 0; }),
  };
  m.make = make_deon2011;
  m.approximations = deon_approximations;
  m.from_fiber = [](const PhysicalFiber& f, ModelParams& p, FiberMapping& mapping) {
    if (f.eccentricity != 1.0)
      throw Error(fmt::format("model deon2011: circular fibers only; this fiber has eccentricity {:g}",
                              f.eccentricity));
    apply_fiber_basics(f, p);
    apply_fiber_roughness(f, p, deon2011_width_calibration(), mapping);
  };
  return m;
}

}  // namespace fiberlab::analytic
