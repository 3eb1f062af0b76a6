#include "analytic/quadrature.h"

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

}  // namespace fiberlab::analytic
