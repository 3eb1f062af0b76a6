#include "analytic/quadrature.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "common/units.h"

namespace fiberlab::analytic {

namespace {
GaussLegendre compute_rule(int n) {
  GaussLegendre r;
  r.x.resize(n);
  r.w.resize(n);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    // Initial guess (Tricomi), then Newton on P_n.
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = pk;
      }
      if (n == 1) p0 = 1.0, p1 = x;
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = pk;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
    }
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    r.x[i] = -x;
    r.x[n - 1 - i] = x;
    r.w[i] = r.w[n - 1 - i] = w;
  }
  if (n % 2 == 1) r.x[n / 2] = 0.0;
  return r;
}
}  // namespace

const GaussLegendre& gauss_legendre(int n) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<GaussLegendre>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[n];
  if (!slot) {
    if (n == 1) {
      slot = std::make_unique<GaussLegendre>(GaussLegendre{{0.0}, {2.0}});
    } else {
      slot = std::make_unique<GaussLegendre>(compute_rule(n));
    }
  }
  return *slot;
}

double gaussian_interval_mass(double a, double b, double mu, double beta) {
  const double s = 1.0 / (std::sqrt(2.0) * beta);
  const double za = (a - mu) * s, zb = (b - mu) * s;
  if (za >= 0.0) return 0.5 * (std::erfc(za) - std::erfc(zb));
  if (zb <= 0.0) return 0.5 * (std::erfc(-zb) - std::erfc(-za));
  return 1.0 - 0.5 * (std::erfc(-za) + std::erfc(zb));
}

void add_gaussian_interval_masses(const double* edges, int n, double mu, double beta, double* out,
                                  std::size_t stride) {
  if (n <= 0) return;
  const double s = 1.0 / (std::sqrt(2.0) * beta);
  // tail[k] = erfc(|z_k|): the erfc gaussian_interval_mass takes at edge k.
  std::vector<double> z(n + 1), tail(n + 1);
  for (int k = 0; k <= n; ++k) z[k] = (edges[k] - mu) * s, tail[k] = std::erfc(std::abs(z[k]));
  for (int j = 0; j < n; ++j) {
    double m;
    if (z[j] >= 0.0) m = 0.5 * (tail[j] - tail[j + 1]);
    else if (z[j + 1] <= 0.0) m = 0.5 * (tail[j + 1] - tail[j]);
    else m = 1.0 - 0.5 * (tail[j] + tail[j + 1]);
    out[j * stride] += m;
  }
}

}  // namespace fiberlab::analytic

namespace fiberlab::analytic {

ChebyshevPanels::ChebyshevPanels(double lo, double hi, int n_panels, int m)
    : lo_(lo), width_((hi - lo) / std::max(n_panels, 1)), n_panels_(std::max(n_panels, 1)),
      m_(std::max(m, 2)), unit_(m_) {
  for (int k = 0; k < m_; ++k) unit_[k] = 0.5 - 0.5 * std::cos(kPi * k / (m_ - 1));
}

double ChebyshevPanels::node(int g) const {
  const int pan = std::min(g / (m_ - 1), n_panels_ - 1);
  return lo_ + width_ * (pan + unit_[g - pan * (m_ - 1)]);
}

int ChebyshevPanels::basis(double x, double* l) const {
  const double u = width_ > 0.0 ? (x - lo_) / width_ : 0.0;
  const int pan = std::clamp(static_cast<int>(std::floor(u)), 0, n_panels_ - 1);
  const double t = std::clamp(u - pan, 0.0, 1.0);
  double den = 0.0;
  for (int k = 0; k < m_; ++k) {
    const double d = t - unit_[k];
    if (d == 0.0) {
      std::fill(l, l + m_, 0.0);
      l[k] = 1.0;
      return pan * (m_ - 1);
    }
    // Berrut & Trefethen Eq. 5.4: w_k = (-1)^k, halved at both ends.
    const double w = ((k % 2) ? -1.0 : 1.0) * ((k == 0 || k == m_ - 1) ? 0.5 : 1.0);
    den += (l[k] = w / d);
  }
  for (int k = 0; k < m_; ++k) l[k] /= den;
  return pan * (m_ - 1);
}

}  // namespace fiberlab::analytic
