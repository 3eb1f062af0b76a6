#pragma once
// One incident direction's tally as exact integers, in the result file's
// index order: what checkpoints store, MPI ranks add up and `merge` sums.
//
// Weights are fixed point (Tally: a weight w counts as round(w 2^60)), so a
// sum of any photons is an integer and adding sums is exact and associative:
// totals do not depend on how photons were split across threads, ranks,
// checkpoints or files, nor on the order the parts are added. float64 values
// are derived once, from the final integers (value / 2^60).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fiberlab::sim {

struct TallyShape {
  int lobes = 0, n_theta = 0, n_phi = 0, channels = 0;

  std::size_t bins() const { return static_cast<std::size_t>(lobes) * n_theta * n_phi; }
  std::size_t bin_cells() const { return bins() * channels; }
  friend bool operator==(const TallyShape&, const TallyShape&) = default;
};

// Which bin sum: S1 (weight_sum) or S2 (weight_sq_sum).
enum class BinSum { S1, S2 };

// A direction's photons and energy ledger (SPEC section 4) as exact words
// ([lobe][channel] for exited, [channel] for the others).
struct ExactLedger {
  std::uint64_t photons = 0;
  std::vector<unsigned __int128> exited, absorbed, truncated, lost;
  std::vector<unsigned __int128> roulette;  // signed, two's complement (ExactTally::roulette)
  std::vector<unsigned __int128> lobe_weight_sq_sum;  // [lobe][channel] (ExactTally's)
};

struct ExactTally {
  using Word = unsigned __int128;  // every sum is >= 0, but `roulette` (two's complement)
  static constexpr double kScale = 0x1.0p60;

  explicit ExactTally(const TallyShape& shape);

  TallyShape shape;
  std::uint64_t photons = 0;
  std::vector<std::uint64_t> count;             // [lobe][theta][phi]
  std::vector<Word> weight_sum, weight_sq_sum;  // [lobe][theta][phi][channel]
  std::vector<Word> exited;                     // [lobe][channel]
  std::vector<Word> absorbed, truncated;        // [channel]
  std::vector<Word> lost;                       // [channel]: removed by masking
  // [channel]: weight Russian roulette created minus weight it destroyed
  // (expected-value scoring; 0 otherwise), a signed 128-bit integer held in
  // two's complement: sums wrap modulo 2^128 and stay exact.
  std::vector<Word> roulette;
  // [lobe][channel]: the sum over photons of the square of each photon's
  // total in the lobe (expected-value scoring, Tally::score_lobe_square).
  // All 0 for the analog estimator, whose lobe S2 is the sum of its bins' S2.
  std::vector<Word> lobe_weight_sq_sum;
  bool has_lobe_weight_sq_sum() const;

  // Exact sum; throws fiberlab::Error when a count would overflow 64 bits.
  ExactTally& operator+=(const ExactTally& other);

  // Every number as one flat array of words (photons, count, weight_sum,
  // weight_sq_sum, exited, absorbed, truncated, lost, roulette,
  // lobe_weight_sq_sum), for element-wise sums
  // across MPI ranks; from_words() is its inverse.
  std::vector<Word> words() const;
  void from_words(const std::vector<Word>& w);

  // Per lobe and channel, the lobe's S1 (= exited) and S2 (lobe_weight_sq_sum
  // where kept, else the sum over its bins): [lobe][channel], S1 first, then
  // S2. What --target-error judges.
  std::vector<Word> lobe_moments() const;

  // Lobe l's bins in file order, as the result file stores them (the result
  // writer streams a direction one lobe and one sum at a time,
  // sim/store/result_stream.h): counts [theta][phi], and one sum [theta][phi][channel]
  // split into values and residuals (split(), below). Into the given
  // buffers, resized.
  void lobe_counts(int l, std::vector<std::uint64_t>& out) const;
  void lobe_sums(int l, BinSum which, std::vector<double>& value,
                 std::vector<std::int64_t>& residual) const;
  ExactLedger ledger() const {
    return {photons, exited, absorbed, truncated, lost, roulette, lobe_weight_sq_sum};
  }

  static std::vector<double> to_double(const std::vector<Word>& v);
  // The same for a signed (two's complement) sum: `roulette`.
  static std::vector<double> to_double_signed(const std::vector<Word>& v);
  // Format 2 stores a bin sum E as its float64 value v = E / 2^60, rounded
  // once (to_double), and the residual r = E - v 2^60, an int64 (|r| is at
  // most half an ulp of E: 0 below 2^53, below 2^20 for sums of about 10^5
  // photons), which deflates to a fraction of E's (high, low) pair.
  // split() throws fiberlab::Error if a residual does not fit 64 bits (a bin
  // sum of 2^56 or more, about 7e16 photons of weight 1). join() is its inverse and
  // accepts only what split() gives: it returns the index of the first cell
  // where v is not a finite, non-negative multiple of 2^-60 below 2^68, or
  // v 2^60 + r is not a 128-bit sum that rounds to v; -1 when every cell is
  // one.
  static void split(const std::vector<Word>& v, std::vector<double>& value,
                    std::vector<std::int64_t>& residual);
  // One word: what split() does to each. Inline: the result writer splits
  // every cell of a tally with it.
  static void split(Word e, double& value, std::int64_t& residual) {
    if (e >> 53 == 0) {  // nearly every bin: exact as a double
      value = static_cast<double>(static_cast<std::uint64_t>(e)) / kScale;
      residual = 0;
    } else {
      split_large(e, value, residual);
    }
  }
  static std::ptrdiff_t join(const std::vector<double>& value,
                             const std::vector<std::int64_t>& residual, std::vector<Word>& out);
  // Two uint64 per word, (high, low): how format 1 files stored them (and
  // how files store the ledger's sums).
  static std::vector<std::uint64_t> to_pairs(const std::vector<Word>& v);
  // The same into `out` (resized), so that a caller can reuse its buffer.
  static void to_double(const std::vector<Word>& v, std::vector<double>& out);
  static void to_pairs(const std::vector<Word>& v, std::vector<std::uint64_t>& out);
  static std::vector<Word> from_pairs(const std::vector<std::uint64_t>& v);

 private:
  static void split_large(Word e, double& value, std::int64_t& residual);  // e >= 2^53
};

}  // namespace fiberlab::sim
