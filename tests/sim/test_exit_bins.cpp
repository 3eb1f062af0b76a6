// The scorer's vectorised bin lookup (ExitScorer::block_bins) against the
// grid's own scalar lookup (BinGrid::theta_bin / phi_bin of
// wrap_angle(phi - phi_i): the definition), at and next to every edge, for
// both theta binnings and for incident azimuths far outside [-pi, pi).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "common/bin_grid.h"
#include "common/units.h"
#include "sim/life/exit_scoring.h"

namespace fiberlab::sim {
namespace {

// Values at, just below and just above every edge, plus random ones.
std::vector<double> probes(const std::vector<double>& edges, double lo, double hi, int seed) {
  std::vector<double> v;
  for (double e : edges)
    for (double x : {std::nextafter(e, -INFINITY), e, std::nextafter(e, INFINITY)})
      if (x >= lo && x <= hi) v.push_back(x);
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  for (int i = 0; i < 5000; ++i) v.push_back(u(gen));
  return v;
}

void expect_block_bins_match(const BinGrid& grid, const std::vector<double>& theta,
                             const std::vector<double>& phi, double phi_i) {
  ExitScorer scorer(grid, {0.0}, 4);
  FinishedPhotons f;
  alignas(64) std::int64_t theta_bin[FinishedPhotons::kCapacity], phi_bin[FinishedPhotons::kCapacity];
  for (std::size_t start = 0; start < theta.size(); start += FinishedPhotons::kCapacity) {
    f.n = static_cast<int>(std::min<std::size_t>(FinishedPhotons::kCapacity, theta.size() - start));
    for (int i = 0; i < f.n; ++i) {
      f.theta[i] = theta[start + i];
      f.phi[i] = phi[(start + i) % phi.size()];
      f.phi_i[i] = phi_i;
      f.exited[i] = true;
    }
    scorer.block_bins(f, theta_bin, phi_bin);
    for (int i = 0; i < f.n; ++i) {
      ASSERT_EQ(theta_bin[i], grid.theta_bin(f.theta[i])) << "theta " << f.theta[i];
      ASSERT_EQ(phi_bin[i], grid.phi_bin(wrap_angle(f.phi[i] - phi_i)))
          << "phi " << f.phi[i] << " phi_i " << phi_i;
    }
  }
}

TEST(ExitBins, VectorLookupEqualsTheGridsAtEveryEdge) {
  // Mutations caught: the settle step dropped or one-sided (values next to
  // an edge land one bin off), the wrap's 2 pi shift on the wrong side.
  for (ThetaBinning binning : {ThetaBinning::Uniform, ThetaBinning::EqualArea}) {
    const BinGrid grid = BinGrid::make(90, 180, binning);
    const std::vector<double> theta = probes(grid.theta_edges, -kPi / 2, kPi / 2, 1);
    // Exit azimuths at the edges shifted by phi_i, so that phi - phi_i
    // probes the relative edges too.
    for (double phi_i : {0.0, 0.3, -2.9, kPi, -kPi, 7.5, -20.0}) {
      std::vector<double> phi;
      for (double e : probes(grid.phi_edges, -kPi, kPi, 2)) {
        const double p = e + phi_i;
        if (p >= -kPi && p <= kPi) phi.push_back(p);
        else phi.push_back(e);  // keep atan2's range
      }
      expect_block_bins_match(grid, theta, phi, phi_i);
    }
  }
}

// A truncated photon (or an expected-value row of Russian roulette alone)
// has no direction (NaN theta and phi) and shares its block with exited
// ones. An incident azimuth far outside [-pi, pi) sends the block's exited
// photons to the scalar wrap; one inside keeps the NaN rows on the vector
// path (block_bins leaves them to settled_bin, as their theta). The exited
// photons' bins are still the grid's, and no NaN reaches a conversion to
// int (undefined behaviour: the sanitizer job, which runs this test,
// reports it; it found the scalar wrap converting truncated photons' NaN).
// Mutation caught: the scalar fallback skipped for a whole vector once it
// holds a NaN (exited lanes of phi_i -20 land in wrong bins).
TEST(ExitBins, TruncatedPhotonsInABlockAreSkipped) {
  for (const double phi_i : {-20.0, 0.3}) {
    const BinGrid grid = BinGrid::make(90, 180, ThetaBinning::Uniform);
    ExitScorer scorer(grid, {0.0}, 4);
    FinishedPhotons f;
    alignas(64) std::int64_t theta_bin[FinishedPhotons::kCapacity], phi_bin[FinishedPhotons::kCapacity];
    f.n = 64;
    for (int i = 0; i < f.n; ++i) {
      f.exited[i] = i % 3 != 0;
      f.theta[i] = f.exited[i] ? -1.5 + 0.04 * i : std::nan("");
      f.phi[i] = f.exited[i] ? -3.1 + 0.09 * i : std::nan("");
      f.phi_i[i] = phi_i;
    }
    scorer.block_bins(f, theta_bin, phi_bin);
    for (int i = 0; i < f.n; ++i) {
      if (!f.exited[i]) continue;
      EXPECT_EQ(theta_bin[i], grid.theta_bin(f.theta[i]));
      EXPECT_EQ(phi_bin[i], grid.phi_bin(wrap_angle(f.phi[i] - phi_i))) << "phi_i " << phi_i;
    }
  }
}

}  // namespace
}  // namespace fiberlab::sim
