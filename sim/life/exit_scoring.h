#pragma once
// Scoring finished photons into a Tally (SPEC sections 4 and 6): the
// Beer-Lambert weight exp(-sigma_a[c] l) per channel along the whole internal
// path (times the photon's masking throughput), the lobe min(p, L - 1) and the
// (theta_r, phi_r - phi_i) bin; weight removed by masking as the ledger's lost.
// With expected-value scoring a photon may leave in one bin more than once
// (the last lobe collects every p >= L - 1, and a rough point may score
// twice): its exits are added up per bin as they come (per slot,
// sim/life/finished_photons.h), so that S2 gains the square of its total.
#include <cstdint>
#include <vector>

#include "common/bin_grid.h"
#include "sim/life/finished_photons.h"
#include "sim/life/photon_runs.h"
#include "sim/store/tally.h"

namespace fiberlab::sim {

class ExitScorer {
 public:
  // lobes: tally.lobes, by p. medulla_sigma_a: the medulla's sigma_a (empty
  // without a medulla); with one, photons that scattered in it go to lobe
  // `lobes` (`scattered`, docs/FUR.md) and every photon's weight carries
  // exp(-medulla_sigma_a[c] medulla_path). expected_value: Settings::estimator.
  ExitScorer(const BinGrid& grid, std::vector<double> sigma_a, int lobes,
             std::vector<double> medulla_sigma_a = {}, bool expected_value = false);
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
  bool expected_value_;
  // Expected-value scoring: per row of a block, Beer-Lambert's factor
  // ([channel][row]; weights_ is the row's weight times it) and lobe.
  std::vector<double> absorption_;
  int lobe_[FinishedPhotons::kCapacity];
  // Per slot (sim/life/finished_photons.h), the photon in it so far: its
  // room in fixed point (1 plus what Russian roulette created for it, minus
  // what it booked, which is at most that) in a flat array ([slot][channel]);
  // its total in its latest lobe ([slot][channel], squared into the lobe's
  // sum of squares when it moves on or ends) and in that lobe's bins (runs_).
  std::vector<Tally::Fixed> room_;
  std::vector<double> lobe_total_;
  PhotonRuns runs_;
  std::vector<Tally::Fixed> fixed_;   // [channel]: one row's weight as booked
  std::vector<double> growth_;        // [channel]: one row's bin S2 growth
  void reserve_slots(const FinishedPhotons& f);
  template <int kChannels = 0>
  void book(const double* weight, std::size_t stride, std::uint32_t slot, Tally::Fixed* fixed);
  template <int kChannels>
  void score_scored_exit(const FinishedPhotons& f, int i, std::size_t bin, Tally& tally);
  void score_roulette(const FinishedPhotons& f, int i, Tally& tally);
  void end_photon(std::uint32_t slot, Tally& tally);
  void prefetch_row(const FinishedPhotons& f, int i, const std::size_t* bin, const Tally& tally) const;
  void score_rows_expected_value(const FinishedPhotons& f, const std::size_t* bin, Tally& tally);
  // The grid's edges are where block_bins' closed form puts them (to within
  // a margin), so that most vectors of bins need no settling on the edges.
  bool theta_closed_form_, phi_closed_form_;
};

}  // namespace fiberlab::sim
