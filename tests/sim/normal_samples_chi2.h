#pragma once
// Two-sample chi-square of two sets of roughness normals, shared by the tests
// of the gaussian sampler (test_gaussian_normal.cpp) and of the microfacet
// VNDF sampler (test_microfacet_normals.cpp): each normal m is binned by
// (m.u, azimuth of m about the fiber axis u relative to the tilted normal
// n_f), 20 x 20 bins over the 1st to 99th percentiles of the reference
// sample; bins with >= 30 counts in both samples enter, and the threshold is
// dof + 5 sqrt(2 dof) (chi-square(dof): mean dof, sd sqrt(2 dof)).
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "common/fiber_frame.h"
#include "common/units.h"

namespace fiberlab::sim::testing {

struct NormalsChi2 {
  double chi2 = 0.0;
  int dof = 0;
  double threshold() const { return dof + 5.0 * std::sqrt(2.0 * dof); }
};

// The azimuth of m about u (x) relative to that of nf.
inline double azimuth_offset(const Vec3& m, const Vec3& nf) {
  return wrap_angle(std::atan2(m.z(), m.y()) - std::atan2(nf.z(), nf.y()));
}

// The 1st and 99th percentiles of x: a histogram's range.
inline std::pair<double, double> central_range(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return {x[x.size() / 100], x[x.size() - 1 - x.size() / 100]};
}

// `tested` against `reference` (equal sizes), binned about nf.
inline NormalsChi2 two_sample_normals_chi2(const std::vector<Vec3>& tested,
                                           const std::vector<Vec3>& reference, const Vec3& nf) {
  constexpr int kBins = 20;
  std::vector<double> u, a;
  for (const Vec3& m : reference) {
    u.push_back(m.x());
    a.push_back(azimuth_offset(m, nf));
  }
  const auto [lo_u, hi_u] = central_range(u);
  const auto [lo_a, hi_a] = central_range(a);
  auto histogram = [&](const std::vector<Vec3>& sample) {
    std::vector<double> counts(kBins * kBins, 0.0);
    for (const Vec3& m : sample) {
      const int i = static_cast<int>(std::floor((m.x() - lo_u) / (hi_u - lo_u) * kBins));
      const int j = static_cast<int>(std::floor((azimuth_offset(m, nf) - lo_a) / (hi_a - lo_a) * kBins));
      if (i >= 0 && i < kBins && j >= 0 && j < kBins) counts[i * kBins + j] += 1.0;
    }
    return counts;
  };
  const std::vector<double> ha = histogram(tested), hb = histogram(reference);
  NormalsChi2 out;
  for (int k = 0; k < kBins * kBins; ++k) {
    if (ha[k] < 30 || hb[k] < 30) continue;
    const double diff = ha[k] - hb[k];
    out.chi2 += diff * diff / (ha[k] + hb[k]);
    ++out.dof;
  }
  return out;
}

}  // namespace fiberlab::sim::testing
