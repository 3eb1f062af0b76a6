#pragma once
// Integration of the analytic models' lobes over the bins of a BinGrid
// (SPEC s6), apart from the lobe functions themselves
// (longitudinal_lobes.h, azimuthal_lobes.h, cylinder_paths.h):
// - theta_r: composite Gauss-Legendre nodes per theta bin, and the moments
//   of a Chebyshev interpolant in theta_r (a lobe's phi-bin integrals are
//   evaluated at a few theta_r and interpolated: linear in them, so each
//   theta bin needs only the moments sum_nodes w l_k(theta_r));
// - phi: the mass of a wrapped azimuthal distribution in every phi bin, by
//   differences of its cumulative at the bin edges (deposit_wrapped), or by
//   the Fourier series of the wrapped Gaussian (d'Eon et al. 2011 Eq. 11)
//   over a set of path nodes (FourierSums, GaussianFourierBins).
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <vector>

#include "analytic/cylinder_paths.h"
#include "analytic/quadrature.h"
#include "common/units.h"

namespace fiberlab::analytic {

// ---- theta_r -----------------------------------------------------------------------

// Nodes of 8-point composite Gauss-Legendre on [a, b] with panels no longer
// than max_len, split at `cut` where it lies inside (NaN: nowhere): calls
// node(theta_r, weight) for each.
template <class Node>
void panel_nodes(double a, double b, double cut, double max_len, Node&& node) {
  const GaussLegendre& gl = gauss_legendre(8);
  double cuts[3] = {a, b, b};
  int n_cuts = 2;
  if (cut > a && cut < b) cuts[1] = cut, n_cuts = 3;
  for (int c = 0; c + 1 < n_cuts; ++c) {
    const int m = std::max(1, static_cast<int>(std::ceil((cuts[c + 1] - cuts[c]) / max_len)));
    const double len = (cuts[c + 1] - cuts[c]) / m;
    for (int pn = 0; pn < m; ++pn) {
      const double mid = cuts[c] + (pn + 0.5) * len;
      for (int q = 0; q < 8; ++q) node(mid + 0.5 * len * gl.x[q], 0.5 * len * gl.w[q]);
    }
  }
}

// panel_nodes over the part within [lo, hi] of every theta bin i (edges
// ascending): calls visit(i, theta_r, weight), bin by bin in order.
template <class Visit>
void theta_panel_nodes(const std::vector<double>& edges, double lo, double hi, double cut, double max_len,
                       Visit&& visit) {
  for (int i = 0; i + 1 < static_cast<int>(edges.size()); ++i) {
    const double t0 = std::max(lo, edges[i]), t1 = std::min(hi, edges[i + 1]);
    if (!(t1 > t0)) continue;
    panel_nodes(t0, t1, cut, max_len, [&](double tr, double w) { visit(i, tr, w); });
  }
}

// Adds to out[i] the sum over the theta_panel_nodes of bin i (no cut) of
// term(theta_r, weight): each theta bin's integral of a longitudinal lobe.
template <class Term>
void add_theta_bin_integrals(const std::vector<double>& edges, double lo, double hi, double max_len, Term&& term,
                             std::vector<double>& out) {
  for (int i = 0; i + 1 < static_cast<int>(edges.size()); ++i) {
    const double t0 = std::max(lo, edges[i]), t1 = std::min(hi, edges[i + 1]);
    if (!(t1 > t0)) continue;
    double sum = 0.0;
    panel_nodes(t0, t1, std::numeric_limits<double>::quiet_NaN(), max_len,
                [&](double tr, double w) { sum += term(tr, w); });
    out[i] += sum;
  }
}

// A theta_r quadrature node: theta bin i, theta_r, weight (times the
// longitudinal lobe).
struct ThetaNode {
  int i;
  double theta, w;
};

// Polynomial interpolation in theta_r on [lo, hi] through the n Chebyshev
// points of the second kind x_k = mid - half cos(pi k / (n - 1)), by the
// barycentric formula (Berrut & Trefethen 2004, SIAM Review 46(3), Eq. 4.2,
// weights of Eq. 5.4).
class ChebyshevLine {
 public:
  ChebyshevLine(double lo, double hi, int n);
  int size() const { return static_cast<int>(x_.size()); }
  double node(int k) const { return x_[k]; }
  // moments[i * n + k] = sum over the nodes of bin i of w l_k(theta): the
  // weights of the node values in each theta bin's integral.
  std::vector<double> moments(const std::vector<ThetaNode>& nodes, int n_theta) const;

 private:
  std::vector<double> x_, bw_;
};

// ---- phi: cumulative differences -----------------------------------------------------

// Adds mass[c] times the mass of a wrapped distribution centred on mu in
// every one of n uniform bins on [-pi, pi) to res[j * C + c]. cdf(x) is the
// cumulative at offset x from the centre; the bins within window * width of
// mu get the differences of cdf at their edges (the bins beyond hold less
// than the window leaves out). A non-periodic cdf (one image) deposits each
// image crossed by the window; a periodic one (cdf(x + 2 pi) = cdf(x) + 1,
// every image at once) deposits every bin once when the window spans them all.
template <class Cdf>
void deposit_wrapped(const Cdf& cdf, double mu, double width, double window, bool periodic_cdf,
                     const double* mass, int C, int n, std::vector<double>& res) {
  const double delta = kTwoPi / n;
  const double R = window * width;
  long j0 = static_cast<long>(std::floor((mu - R + kPi) / delta));
  long j1 = static_cast<long>(std::floor((mu + R + kPi) / delta));
  if (periodic_cdf && j1 - j0 + 1 >= n) j0 = 0, j1 = n - 1;
  double prev = cdf(-kPi + j0 * delta - mu);
  for (long j = j0; j <= j1; ++j) {
    const double next = cdf(-kPi + (j + 1) * delta - mu);
    const double frac = next - prev;
    prev = next;
    long jj = j % n;
    if (jj < 0) jj += n;
    double* r = &res[static_cast<std::size_t>(jj) * C];
    for (int c = 0; c < C; ++c) r[c] += frac * mass[c];
  }
}

// ---- phi: Fourier series -------------------------------------------------------------

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
                   std::vector<double>& f_im) const;

 private:
  static constexpr std::size_t kLanes = 8, kTile = 256;
  typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));
  static Lanes load(const double* p) {
    Lanes v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static void store(double* p, Lanes v) { std::memcpy(p, &v, sizeof v); }
  void coefficients_tile(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                         std::vector<double>& f_im) const;
  template <std::size_t C>
  void tile_fused(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                  std::vector<double>& f_im) const;
  void tile_channel(std::size_t c, std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
                    std::vector<double>& f_im) const;
  std::vector<double> e_re_, e_im_;
  std::vector<std::vector<double>> mass_;  // [channel][node]
  std::vector<std::size_t> segments_;      // first node of each segment
};

// Order p's path nodes into the Fourier sums, as one segment: masses
// weight * A(p, gamma) per channel and the phasor e^{-i Phi(p, gamma)}, from
// the sine and cosine of gamma alone (nodes from cylinder::panel_nodes).
void add_fourier_nodes(const cylinder::Attenuation& att, int p, const std::vector<cylinder::PathNode>& nodes,
                       FourierSums& fourier);

// The phi-bin masses of sum over nodes of mass D(beta; phi - Phi) for the
// wrapped Gaussian D of Eq. 11, from its Fourier form: its coefficients are
// g_n = exp(-n^2 beta^2 / 2), so the mass of bin [a, b] is
//   F_0 dphi / 2pi + (1/pi) Re sum_{n>=1} F_n g_n (e^{i n b} - e^{i n a}) / (i n).
// Keeps the bin factors (e^{i n b} - e^{i n a}) / (i n), which depend on
// neither theta_r nor the channel, between calls.
class GaussianFourierBins {
 public:
  // Terms up to n_max (g_n < 1e-17 beyond ceil(8.9 / beta)).
  static int terms(double beta) { return static_cast<int>(std::ceil(8.9 / beta)); }
  // Adds the bin masses of `sums` (coefficients up to n_max, each segment cut
  // where its rest changes no bin by more than tol) to nb[j * C + c], for np
  // uniform bins.
  void add(const FourierSums& sums, int n_max, double beta, double tol, int np, int C, std::vector<double>& nb);

 private:
  std::vector<double> factor_re_, factor_im_;  // [n * np + j]
  std::vector<double> tail_, f_re_, f_im_, bin_sum_;
};

}  // namespace fiberlab::analytic
