#pragma once
// Scoring finished photons into a Tally (SPEC sections 4 and 6): the
// Beer-Lambert weight exp(-sigma_a[c] l) per channel along the whole internal
// path (times the photon's masking throughput), the lobe min(p, L - 1) and the
// (theta_r, phi_r - phi_i) bin; weight removed by masking as the ledger's lost.
#include <cstdint>
#include <vector>

#include "common/bin_grid.h"
#include "sim/life/finished_photons.h"
#include "sim/store/tally.h"

namespace fiberlab::sim {

class ExitScorer {
 public:
  // lobes: tally.lobes, by p. medulla_sigma_a: the medulla's sigma_a (empty
  // without a medulla); with one, photons that scattered in it go to lobe
  // `lobes` (`scattered`, docs/FUR.md) and every photon's weight carries
  // exp(-medulla_sigma_a[c] medulla_path).
  ExitScorer(const BinGrid& grid, std::vector<double> sigma_a, int lobes,
             std::vector<double> medulla_sigma_a = {});
  // Weights are computed for a whole block at once (vectorised), the tally
  // cells of the exits are located and prefetched, then added.
  void score(const FinishedPhotons& f, Tally& tally);
  // The theta and relative phi bins of a block's photons, vectorised (the
  // same numbers as BinGrid::theta_bin / phi_bin of wrap_angle(phi - phi_i)).
  void block_bins(const FinishedPhotons& f, std::int64_t* theta_bin, std::int64_t* phi_bin) const;

 private:
  const BinGrid& grid_;
  std::vector<double> sigma_a_;
  int last_lobe_;
  std::vector<double> medulla_sigma_a_;
  std::vector<double> weights_;     // [channel][photon]
  std::vector<double> one_photon_;  // [channel]
  std::vector<double> kept_;        // [channel]: a photon's exited or truncated weight
  // The grid's edges are where block_bins' closed form puts them (to within
  // a margin), so that most vectors of bins need no settling on the edges.
  bool theta_closed_form_, phi_closed_form_;
};

}  // namespace fiberlab::sim
