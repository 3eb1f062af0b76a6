#pragma once
// What is counted for one incident configuration (SPEC section 6): per lobe,
// (theta_r, phi) bin and channel the sum of weights S1 and of squared weights
// S2, per bin the photon count, and the energy ledger.
//
// Sums are kept in 128-bit fixed point (weights are in [0, 1], scaled by
// 2^60): integer addition is associative, so the totals are bit-identical
// whatever the number of threads or the order in which photons are added.
// The rounding of one weight is below 1e-18, far below any statistical error.
//
// The cells start as untouched zero pages (sim/store/zeroed_memory.h) and the tally
// remembers which pages of bins it wrote: adding, clearing, copying and
// exporting a tally visit only those, so a thread's tally costs what it holds
// (a 90 x 180 x 8-lobe, 3-channel tally is 14.5 MB; a run touches 1-40% of it).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/bin_grid.h"
#include "sim/store/exact_tally.h"
#include "sim/store/zeroed_memory.h"

namespace fiberlab::sim {

class Tally {
 public:
  using Fixed = __int128;
  static constexpr double kScale = 0x1.0p60;

  Tally(int lobes, int n_theta, int n_phi, int channels);
  Tally(const Tally& o);
  Tally& operator=(const Tally& o);
  Tally(Tally&&) noexcept = default;
  Tally& operator=(Tally&&) noexcept = default;

  int lobes() const { return lobes_; }
  int n_theta() const { return n_theta_; }
  int n_phi() const { return n_phi_; }
  int channels() const { return channels_; }

  // A photon that left in bin (i_theta, i_phi) of `lobe`, with weight[c] per
  // channel; 1 - weight[c] was absorbed.
  void score_exit(int lobe, int i_theta, int i_phi, const double* weight) {
    score_exit(bin_index(lobe, i_theta, i_phi), weight);
  }
  void score_exit(std::size_t bin, const double* weight) { score_exit(bin, weight, 1); }
  // The same with channel c's weight at weight[c * stride] (the scorer's
  // weights are [channel][photon]). Inline: the scorer's constant stride
  // then costs nothing.
  void score_exit(std::size_t bin, const double* weight, std::size_t stride) {
    touched_[bin / kPageBins] = 1;
    Fixed* cell = cells() + bin * block();
    ++cell[0];
    Fixed* s1 = cell + 1;
    Fixed* s2 = cell + 1 + channels_;
    for (int c = 0; c < channels_; ++c) {
      const double w = weight[c * stride];
      s1[c] += to_fixed(w);
      s2[c] += to_fixed(w * w);
    }
  }
  // Expected-value scoring (sim/life/exit_scoring.h): one of a photon's
  // exits, its S1 already in fixed point (s1[c], booked so that the photon's
  // parts never exceed its unit weight: see ExitScorer), S2 growing by
  // s2_growth[c] (the growth of the square of the photon's total in the bin),
  // and the count by one when this is the photon's first exit in the bin.
  // kChannels: channels(), when the caller knows it at compile time (0: not).
  template <int kChannels = 0>
  void score_exit_fixed(std::size_t bin, const Fixed* s1, const double* s2_growth, bool first) {
    const int channels = kChannels > 0 ? kChannels : channels_;
    touched_[bin / kPageBins] = 1;
    Fixed* cell = cells() + bin * block_of(channels);
    cell[0] += first ? 1 : 0;
    for (int c = 0; c < channels; ++c) {
      cell[1 + c] += s1[c];
      cell[1 + channels + c] += to_fixed(s2_growth[c]);
    }
  }
  // Expected-value scoring: a photon's total[c] in `lobe`, once it is
  // done there, added squared to the lobe's sum of squares of photon totals
  // (a photon may leave in several bins of a lobe, and the lobe's standard
  // error needs the sum over photons of the square of its total there, not
  // the sum of its bins' S2; the analog estimator books none: there each
  // photon leaves once and the lobe's S2 is its bins' S2).
  void score_lobe_total(int lobe, const double* total) {
    Fixed* sq = lobe_sq_.data() + static_cast<std::size_t>(lobe) * channels_;
    for (int c = 0; c < channels_; ++c) sq[c] += to_fixed(total[c] * total[c]);
  }
  // A photon's truncated weight, already in fixed point.
  void score_truncated_fixed(const Fixed* weight) {
    for (int c = 0; c < channels_; ++c) truncated_[c] += weight[c];
  }
  // Weight Russian roulette created (> 0) or destroyed (< 0) in fixed point,
  // absorbed along the path before it (expected-value scoring): the ledger's
  // signed `roulette`, with exited + absorbed + truncated + lost - roulette
  // = launched (sim/life/photon_life.h kRouletteBelow).
  void score_roulette_fixed(const Fixed* delta) {
    for (int c = 0; c < channels_; ++c) roulette_[c] += delta[c];
  }
  static Fixed to_fixed(double w) { return static_cast<Fixed>(static_cast<std::int64_t>(w * kScale + 0.5)); }
  static constexpr Fixed kOne = Fixed{1} << 60;
  // What a photon's parts may exceed its unit weight by, in fixed point, as
  // rounding (2^-40: see score_lost).
  static constexpr Fixed kRoundingAllowance = Fixed{1} << 20;
  // Every sum back to zero (only the touched pages are written): a thread's
  // tally is reused across rounds and incident directions.
  void clear();
  std::size_t bin_index(int lobe, int i_theta, int i_phi) const {
    return (static_cast<std::size_t>(lobe) * n_theta_ + i_theta) * n_phi_ + i_phi;
  }
  // Asks for a bin's cells ahead of score_exit (they are far apart in memory).
  void prefetch(std::size_t bin) const {
    const Fixed* cell = cells() + bin * block();
    __builtin_prefetch(cell, 1);
    __builtin_prefetch(reinterpret_cast<const char*>(cell + block()) - 1, 1);
  }
  // The same for every cache line of the bin's cells (a 3-channel bin is
  // 112 bytes: half of them straddle three lines, whose middle one the two
  // ends miss).
  // Always inline: GCC 12 removes an out-of-line call to it (prefetches are
  // no effect it counts).
  [[gnu::always_inline]] void prefetch_all(std::size_t bin) const {
    const char* first = reinterpret_cast<const char*>(cells() + bin * block());
    const char* last = reinterpret_cast<const char*>(cells() + (bin + 1) * block()) - 1;
    __builtin_prefetch(first, 1);
    if (last - first >= 64) __builtin_prefetch(first + 64, 1);
    __builtin_prefetch(last, 1);
  }
  // A photon still inside when it was stopped, with weight[c] left.
  void score_truncated(const double* weight);
  // The weight lost[c] that masking (roughness.masking: smith_g1) removed
  // from one photon, which kept kept[c] (exited or truncated; 0 when killed):
  // the ledger's `lost`. In exact arithmetic lost + kept <= 1; the products
  // that make them round by a few 2^-53, so when nothing was absorbed they
  // can exceed 1 by that much: lost is held at 1 - kept in the fixed point
  // here, so that absorbed (the complement) is never below 0. More than
  // rounding (2^-40) is a booking error: an internal error is thrown, never
  // clamped.
  void score_lost(const double* lost, const double* kept);
  // The same with the kept weight in fixed point (as booked).
  void score_lost(const double* lost, const Fixed* kept);
  // Every launched photon must have been scored (exited, truncated, lost): what
  // is absorbed is derived from that (launched - exited - truncated - lost, exact).
  void add_launched(std::uint64_t n) { photons_ += n; }
  // Exact: integer sums; on `threads` threads (a page each at a time).
  void add(const Tally& other, int threads = 1);
  // Nothing scored: no photon launched, no cell touched, no ledger entry.
  bool is_zero() const;
  // The same sums as exact integers in file order (checkpoints, MPI, merge),
  // and back (a checkpoint's partial sums before resuming).
  TallyShape shape() const { return {lobes_, n_theta_, n_phi_, channels_}; }
  ExactTally exact() const;
  // The same, a part at a time, read in place (what the result writer
  // streams): lobe l's counts and sums as ExactTally's lobe_counts and
  // lobe_sums give them, and the photons and ledger.
  void lobe_counts(int l, std::vector<std::uint64_t>& out) const;
  void lobe_sums(int l, BinSum which, std::vector<double>& value,
                 std::vector<std::int64_t>& residual) const;
  ExactLedger exact_ledger() const;
  // Per lobe, how many of its bins lie on pages the tally wrote: what
  // exporting and compressing the lobe costs, roughly (the result writer
  // starts with the heaviest lobes).
  std::vector<std::size_t> touched_bins_per_lobe() const;
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
  std::vector<double> roulette() const;   // [channel], signed

 private:
  // Bins are tracked in pages of kPageBins consecutive bins.
  static constexpr std::size_t kPageBins = 64;
  std::size_t bins() const { return static_cast<std::size_t>(lobes_) * n_theta_ * n_phi_; }
  std::size_t pages() const { return (bins() + kPageBins - 1) / kPageBins; }
  // Cells [first, end) of page p.
  std::size_t page_begin(std::size_t p) const { return p * kPageBins * block(); }
  std::size_t page_end(std::size_t p) const { return std::min((p + 1) * kPageBins, bins()) * block(); }
  Fixed* cells() const { return static_cast<Fixed*>(memory_.data()); }
  static std::vector<double> to_double(const std::vector<Fixed>& v);
  // One bin's numbers sit together (count, S1 per channel, S2 per channel) so
  // that scoring a photon touches one or two cache lines, not three arrays.
  static constexpr std::size_t block_of(int channels) { return 2 * static_cast<std::size_t>(channels) + 1; }
  std::size_t block() const { return block_of(channels_); }
  std::vector<double> column(int offset) const;  // S1 (offset 1) or S2 (1 + C)
  void copy_lobe(int l, std::uint64_t* count, ExactTally::Word* s1, ExactTally::Word* s2) const;

  int lobes_, n_theta_, n_phi_, channels_;
  std::uint64_t photons_ = 0;
  std::vector<Fixed> exited_fixed() const;  // [lobe][channel]: sums of S1
  ZeroedMemory memory_;                 // cells(): [bin][count, S1[C], S2[C]]
  std::vector<std::uint8_t> touched_;   // [page]: 1 once a cell of the page was written
  std::vector<Fixed> truncated_;
  std::vector<Fixed> lost_;
  std::vector<Fixed> roulette_;  // signed
  std::vector<Fixed> lobe_sq_;   // [lobe][channel]: score_lobe_total's
};

}  // namespace fiberlab::sim
