#pragma once
// What is counted for one incident configuration (SPEC section 6): per lobe,
// (theta_r, phi) bin and channel the sum of weights S1 and of squared weights
// S2, per bin the photon count, and the energy ledger.
//
// Sums are kept in 128-bit fixed point (weights are in [0, 1], scaled by
// 2^60): integer addition is associative, so the totals are bit-identical
// whatever the number of threads or the order in which photons are added.
// The rounding of one weight is below 1e-18, far below any statistical error.
#include <cstdint>
#include <vector>

#include "common/bin_grid.h"
#include "sim/exact_tally.h"

namespace fiberlab::sim {

class Tally {
 public:
  using Fixed = __int128;
  static constexpr double kScale = 0x1.0p60;

  Tally(int lobes, int n_theta, int n_phi, int channels);

  int lobes() const { return lobes_; }
  int n_theta() const { return n_theta_; }
  int n_phi() const { return n_phi_; }
  int channels() const { return channels_; }

  // A photon that left in bin (i_theta, i_phi) of `lobe`, with weight[c] per
  // channel; 1 - weight[c] was absorbed.
  void score_exit(int lobe, int i_theta, int i_phi, const double* weight) {
    score_exit(bin_index(lobe, i_theta, i_phi), weight);
  }
  void score_exit(std::size_t bin, const double* weight);
  std::size_t bin_index(int lobe, int i_theta, int i_phi) const {
    return (static_cast<std::size_t>(lobe) * n_theta_ + i_theta) * n_phi_ + i_phi;
  }
  // Asks for a bin's cells ahead of score_exit (they are far apart in memory).
  void prefetch(std::size_t bin) const {
    const Fixed* cell = &bins_[bin * block()];
    __builtin_prefetch(cell, 1);
    __builtin_prefetch(reinterpret_cast<const char*>(cell + block()) - 1, 1);
  }
  // A photon still inside when it was stopped, with weight[c] left.
  void score_truncated(const double* weight);
  // Weight weight[c] removed from a photon by masking (roughness.masking:
  // smith_g1), or the whole weight of a path it killed: the ledger's `lost`.
  void score_lost(const double* weight);
  // Every launched photon must have been scored (exited, truncated, lost): what
  // is absorbed is derived from that (launched - exited - truncated - lost, exact).
  void add_launched(std::uint64_t n) { photons_ += n; }
  void add(const Tally& other);  // exact: integer sums
  // The same sums as exact integers in file order (checkpoints, MPI, merge),
  // and back (a checkpoint's partial sums before resuming).
  TallyShape shape() const { return {lobes_, n_theta_, n_phi_, channels_}; }
  ExactTally exact() const;
  void add(const ExactTally& e);

  std::uint64_t photons() const { return photons_; }
  // Results as float64, in the HDF5 index order [lobe][theta][phi][channel].
  std::vector<double> weight_sum() const;
  std::vector<double> weight_sq_sum() const;
  std::vector<std::uint64_t> count() const;  // [lobe][theta][phi]
  std::vector<double> exited() const;     // [lobe][channel]
  std::vector<double> absorbed() const;   // [channel]
  std::vector<double> truncated() const;  // [channel]
  std::vector<double> lost() const;       // [channel]

 private:
  static Fixed to_fixed(double w) { return static_cast<Fixed>(static_cast<std::int64_t>(w * kScale + 0.5)); }
  static std::vector<double> to_double(const std::vector<Fixed>& v);
  // One bin's numbers sit together (count, S1 per channel, S2 per channel) so
  // that scoring a photon touches one or two cache lines, not three arrays.
  std::size_t block() const { return 2 * static_cast<std::size_t>(channels_) + 1; }
  std::vector<double> column(int offset) const;  // S1 (offset 1) or S2 (1 + C)

  int lobes_, n_theta_, n_phi_, channels_;
  std::uint64_t photons_ = 0;
  std::vector<Fixed> exited_fixed() const;  // [lobe][channel]: sums of S1
  std::vector<Fixed> bins_;  // [bin][count, S1[C], S2[C]]
  std::vector<Fixed> truncated_;
  std::vector<Fixed> lost_;
};

}  // namespace fiberlab::sim
