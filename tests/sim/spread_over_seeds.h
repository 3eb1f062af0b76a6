#pragma once
// The reported standard errors against the spread of the estimates over
// many seeds (SPEC sections 6 and 10), bins and lobe energies, lobe by lobe:
// tests/sim/test_estimator.cpp, tests/sim/test_exit_normals.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sim/store/result_file.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim::testing {

// The spread of P_b over M seeds against the mean reported SE_b^2, summed
// over a lobe's bins with an effective sample size of at least 30 per seed
// (SPEC section 10). For Gaussian estimates (M - 1) s_b^2 / sigma_b^2 is
// chi-square with M - 1 degrees of freedom, so the ratio of the sums has
// relative standard deviation at most sqrt(2 / (M - 1)) = 0.1 at M = 201
// (bins fully correlated; less otherwise); the reported SE^2 are themselves
// averages over M seeds. Accepted: ratio within [0.6, 1.5] (4 standard
// deviations below, 5 above).
inline void expect_errors_match_spread(Settings s, const char* what) {
  constexpr int kSeeds = 201;
  const int lobes = s.tally.lobes, bins = s.tally.n_theta * s.tally.n_phi;
  std::vector<double> sum(lobes * bins, 0.0), sum_sq(lobes * bins, 0.0), se2(lobes * bins, 0.0),
      ess(lobes * bins, 1e300);
  for (int seed = 0; seed < kSeeds; ++seed) {
    s.seed = 1000 + seed;
    const ResultFile r = testing::run(s, 1);
    const double n = static_cast<double>(r.photons[0]);
    for (int l = 0; l < lobes; ++l)
      for (int b = 0; b < bins; ++b) {
        const std::size_t c = r.cell(0, l, b / s.tally.n_phi, b % s.tally.n_phi, 0);
        const double p = r.weight_sum[c] / n;
        sum[l * bins + b] += p;
        sum_sq[l * bins + b] += p * p;
        se2[l * bins + b] += (r.weight_sq_sum[c] / n - p * p) / (n - 1.0) / kSeeds;
        const double e = r.weight_sq_sum[c] > 0 ? r.weight_sum[c] * r.weight_sum[c] / r.weight_sq_sum[c] : 0.0;
        ess[l * bins + b] = std::min(ess[l * bins + b], e);
      }
  }
  for (int l = 0; l < lobes; ++l) {
    double spread = 0.0, reported = 0.0;
    int used = 0;
    for (int b = 0; b < bins; ++b) {
      const int i = l * bins + b;
      if (ess[i] < 30.0) continue;
      const double mean = sum[i] / kSeeds;
      spread += (sum_sq[i] - kSeeds * mean * mean) / (kSeeds - 1);
      reported += se2[i];
      ++used;
    }
    ASSERT_GT(used, 0) << what << ", lobe " << l;
    const double ratio = spread / reported;
    std::printf("%s, lobe %d: %d bins, spread / reported SE^2 = %.3f\n", what, l, used, ratio);
    EXPECT_GT(ratio, 0.6) << what << ", lobe " << l;
    EXPECT_LT(ratio, 1.5) << what << ", lobe " << l;
  }
}

// The lobes' energies: the spread of E_l = exited / N over M seeds against
// the mean reported SE^2 of lobe_energy (what fiberlab info, compare's
// energy z, --target-error and Python's energy() use), every lobe, both
// estimators. (M - 1) s^2 / sigma^2 is chi-square with M - 1 degrees of
// freedom: at M = 201 the ratio has relative standard deviation 0.1;
// accepted within [0.6, 1.5] (4 standard deviations below, 5 above).
// Mutation: lobe_energy summing the bins' S2 under expected_value
// (sim/store/result_file.cpp) fails on the last lobe, whose photons leave in
// several of its bins (measured below).
inline void expect_lobe_errors_match_spread(Settings s, const char* what) {
  constexpr int kSeeds = 201;
  const int lobes = s.tally.lobes;
  std::vector<double> sum(lobes, 0.0), sum_sq(lobes, 0.0), se2(lobes, 0.0);
  for (int seed = 0; seed < kSeeds; ++seed) {
    s.seed = 5000 + seed;
    const ResultFile r = testing::run(s, 1);
    const double n = static_cast<double>(r.photons[0]);
    for (int l = 0; l < lobes; ++l) {
      const Estimate e = lobe_energy(r, 0, l, 0);
      EXPECT_DOUBLE_EQ(e.mean, r.exited[l * r.channels] / n);
      sum[l] += e.mean;
      sum_sq[l] += e.mean * e.mean;
      se2[l] += e.std_error * e.std_error / kSeeds;
    }
  }
  for (int l = 0; l < lobes; ++l) {
    const double mean = sum[l] / kSeeds;
    const double ratio = (sum_sq[l] - kSeeds * mean * mean) / (kSeeds - 1) / se2[l];
    std::printf("%s, lobe %d: spread / reported SE^2 of the lobe energy = %.3f\n", what, l, ratio);
    EXPECT_GT(ratio, 0.6) << what << ", lobe " << l;
    EXPECT_LT(ratio, 1.5) << what << ", lobe " << l;
  }
}

}  // namespace fiberlab::sim::testing
