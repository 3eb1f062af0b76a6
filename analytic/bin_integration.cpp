#include "analytic/bin_integration.h"

#include <complex>

namespace fiberlab::analytic {

// ---- theta_r -----------------------------------------------------------------------

ChebyshevLine::ChebyshevLine(double lo, double hi, int n) : x_(n), bw_(n) {
  for (int k = 0; k < n; ++k) {
    x_[k] = 0.5 * (lo + hi) - 0.5 * (hi - lo) * std::cos(kPi * k / (n - 1));
    bw_[k] = ((k % 2) ? -1.0 : 1.0) * ((k == 0 || k == n - 1) ? 0.5 : 1.0);
  }
}

std::vector<double> ChebyshevLine::moments(const std::vector<ThetaNode>& nodes, int n_theta) const {
  const int nc = size();
  std::vector<double> mom(static_cast<std::size_t>(n_theta) * nc, 0.0), lk(nc);
  for (const ThetaNode& pt : nodes) {
    int exact = -1;
    double den = 0.0;
    for (int k = 0; k < nc; ++k) {
      const double d = pt.theta - x_[k];
      if (d == 0.0) { exact = k; break; }
      den += (lk[k] = bw_[k] / d);
    }
    double* row = &mom[static_cast<std::size_t>(pt.i) * nc];
    if (exact >= 0) {
      row[exact] += pt.w;
    } else {
      for (int k = 0; k < nc; ++k) row[k] += pt.w * lk[k] / den;
    }
  }
  return mom;
}

// ---- phi: Fourier series -------------------------------------------------------------

int FourierSums::coefficients(int N, const std::vector<double>& tail, double tol, std::vector<double>& f_re,
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

// Tiles of kTile nodes keep their z in the first-level cache across the n
// loop. Up to 4 channels run in one pass over the nodes (a template on the
// count keeps their sums in registers), more one channel at a time.
void FourierSums::coefficients_tile(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
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
void FourierSums::tile_fused(std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
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

void FourierSums::tile_channel(std::size_t c, std::size_t k0, std::size_t len, int N, std::vector<double>& f_re,
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

namespace {

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

// One node's masses and phasor. Phi = 2 p gamma_t - 2 gamma_i + p pi
// (cylinder_paths.h) gives
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

}  // namespace

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

void GaussianFourierBins::add(const FourierSums& sums, int n_max, double beta, double tol, int np, int C,
                              std::vector<double>& nb) {
  const double dphi = kTwoPi / np;
  // F_n = sum over nodes of mass e^{-i n Phi}, real and imaginary parts apart
  // (plain arithmetic: std::complex's products check for NaN on every call).
  f_re_.assign(static_cast<std::size_t>(n_max + 1) * C, 0.0);
  f_im_.assign(f_re_.size(), 0.0);
  // tail[n] = sum_{n' > n} g_n' min(dphi, 2 / n'): the truncation bound.
  tail_.assign(n_max + 1, 0.0);
  for (int n = n_max - 1; n >= 0; --n)
    tail_[n] = tail_[n + 1] + std::exp(-0.5 * (n + 1.0) * (n + 1.0) * beta * beta) * std::min(dphi, 2.0 / (n + 1.0));
  const int n_used = sums.coefficients(n_max, tail_, tol, f_re_, f_im_);
  if (static_cast<int>(factor_re_.size()) < (n_max + 1) * np) {
    factor_re_.assign(static_cast<std::size_t>(n_max + 1) * np, 0.0);
    factor_im_.assign(factor_re_.size(), 0.0);
    for (int n = 1; n <= n_max; ++n)
      for (int j = 0; j < np; ++j) {
        const double lo = -kPi + j * dphi, hi = lo + dphi;
        const std::complex<double> d =
            (std::polar(1.0, n * hi) - std::polar(1.0, n * lo)) / std::complex<double>(0.0, n);
        factor_re_[static_cast<std::size_t>(n) * np + j] = d.real();
        factor_im_[static_cast<std::size_t>(n) * np + j] = d.imag();
      }
  }
  for (int n = 1; n <= n_used; ++n) {
    const double g = std::exp(-0.5 * n * n * beta * beta) / kPi;
    for (int c = 0; c < C; ++c) {
      f_re_[static_cast<std::size_t>(n) * C + c] *= g;
      f_im_[static_cast<std::size_t>(n) * C + c] *= g;
    }
  }
  // Bin by bin the sum over n above, run with the bins innermost
  // (contiguous, independent: vectorized) per channel.
  for (int c = 0; c < C; ++c) {
    bin_sum_.assign(np, f_re_[c] * dphi / kTwoPi);
    for (int n = 1; n <= n_used; ++n) {
      const double fr = f_re_[static_cast<std::size_t>(n) * C + c];
      const double fi = f_im_[static_cast<std::size_t>(n) * C + c];
      const double* d_re = &factor_re_[static_cast<std::size_t>(n) * np];
      const double* d_im = &factor_im_[static_cast<std::size_t>(n) * np];
      double* v = bin_sum_.data();
      for (int j = 0; j < np; ++j) v[j] += fr * d_re[j] - fi * d_im[j];
    }
    for (int j = 0; j < np; ++j) nb[static_cast<std::size_t>(j) * C + c] += bin_sum_[j];
  }
}

}  // namespace fiberlab::analytic
