#pragma once
// Scoring finished photons into a Tally (SPEC sections 4 and 6): the
// Beer-Lambert weight exp(-sigma_a[c] l) per channel along the whole internal
// path (times the photon's masking throughput), the lobe min(p, L - 1) and the
// (theta_r, phi_r - phi_i) bin; weight removed by masking as the ledger's lost.
#include <vector>

#include "common/bin_grid.h"
#include "sim/finished_photons.h"
#include "sim/tally.h"

namespace fiberlab::sim {

class ExitScorer {
 public:
  ExitScorer(const BinGrid& grid, std::vector<double> sigma_a, int lobes);
  // Weights are computed for a whole block at once (vectorised), the tally
  // cells of the exits are located and prefetched, then added.
  void score(const FinishedPhotons& f, Tally& tally);

 private:
  const BinGrid& grid_;
  std::vector<double> sigma_a_;
  int last_lobe_;
  std::vector<double> weights_;     // [channel][photon]
  std::vector<double> one_photon_;  // [channel]
};

}  // namespace fiberlab::sim
