#include "sim/life/exit_scoring.h"

#include <fmt/format.h>
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/units.h"
#include "common/bin_grid.h"

namespace fiberlab::sim {

namespace {

using Batch = xsimd::batch<double>;
using Index = xsimd::batch<std::int64_t>;

// A bin index (a whole number below 2^52) as an integer (sim/simd/lanes.h).
Index to_index(const Batch& x) { return xsimd::bitwise_cast<Index>(life::to_bits(x)); }

// The closed-form fraction of a uniformly binned value: (v + offset) /
// period, in [0, 1) inside the grid. One formula for the values' bins and for
// the check of the edges below (edges_at_closed_form relies on it being the
// same operations).
template <class T>
T uniform_fraction(const T& v, double offset, double period) {
  return (v + T(offset)) / T(period);
}

// How far from a whole number (in bins) the closed-form position x n of a
// value must be for the settle step below to be skipped (see settled_bin).
constexpr double kSettleMargin = 0x1.0p-20;

// Whether every edge's own closed-form position, computed as block_bins
// computes a value's, lies within half the margin of its index. The
// positions are monotone in the value (each operation rounds monotonically),
// so then a value whose position is at least the margin away from every
// whole number lies strictly between the edges of its closed-form bin, and
// the settle step would not move it.
bool edges_at_closed_form(const std::vector<double>& edges, double offset, double period) {
  const int n = static_cast<int>(edges.size()) - 1;
  for (int i = 0; i <= n; ++i)
    if (!(std::abs(uniform_fraction(edges[i], offset, period) * n - i) <= kSettleMargin / 2))
      return false;
  return true;
}

// BinGrid::theta_bin / phi_bin (common/bin_grid.cpp, the definition) for a
// vector of values: the closed-form index, clamped, then settled on the
// grid's own edges, so the result is the scalar one exactly (a test compares
// them at and next to every edge, and at random values). When the edges are
// at their closed-form positions (`closed_form`, edges_at_closed_form) and
// every lane's position is at least kSettleMargin inside its bin, the index
// is already settled: nearly every vector, which then needs no gather of
// edges. A NaN fraction gives bin 0 (max(NaN, 0) is 0); such photons did not
// exit and their bins are never read.
Index settled_bin(const Batch& v, const Batch& fraction, int n, const std::vector<double>& edges,
                  bool closed_form) {
  const Batch position = fraction * Batch(n);
  Batch i = xsimd::min(xsimd::max(xsimd::floor(position), Batch(0.0)), Batch(n - 1));
  if (closed_form) {
    const Batch inside = position - i;  // exact (Sterbenz) where it matters: 0 <= i <= position
    if (xsimd::all((inside >= Batch(kSettleMargin)) & (inside <= Batch(1.0 - kSettleMargin))))
      return to_index(i);
  }
  const Index k = to_index(i);
  const Batch lo = Batch::gather(edges.data(), k), hi = Batch::gather(edges.data(), k + Index(1));
  const auto down = (i > Batch(0.0)) & (v < lo);
  const auto up = (!down) & (i < Batch(n - 1)) & (v >= hi);
  i = i - xsimd::select(down, Batch(1.0), Batch(0.0)) + xsimd::select(up, Batch(1.0), Batch(0.0));
  return to_index(i);
}

// wrap_angle(a) (common/units.h) where a + pi lies in (-2 pi, 4 pi): there
// fmod(a + pi, 2 pi) is a + pi, or a + pi - 2 pi computed exactly (Sterbenz),
// so this is the same number. `in_range` is false where it does not apply.
Batch wrapped(const Batch& a, Batch::batch_bool_type& in_range) {
  Batch t = a + Batch(kPi);
  in_range = (t > Batch(-kTwoPi)) & (t < Batch(2.0 * kTwoPi));
  t = xsimd::select(t >= Batch(kTwoPi), t - Batch(kTwoPi), t);
  t = xsimd::select(t < Batch(0.0), t + Batch(kTwoPi), t);
  const Batch w = t - Batch(kPi);
  return xsimd::select(w >= Batch(kPi), Batch(-kPi), w);
}

// How many rows ahead of the one being scored expected-value scoring asks
// for a row's tally cells and photon numbers: far enough that they arrive
// before the row is reached (a row takes tens of nanoseconds), near enough
// that the first-level cache still holds them then.
constexpr int kRowsAhead = 16;

}  // namespace

ExitScorer::ExitScorer(const BinGrid& grid, std::vector<double> sigma_a, int lobes,
                       std::vector<double> medulla_sigma_a, bool expected_value)
    : grid_(grid), sigma_a_(std::move(sigma_a)), last_lobe_(lobes - 1),
      medulla_sigma_a_(std::move(medulla_sigma_a)),
      weights_(sigma_a_.size() * FinishedPhotons::kCapacity), one_photon_(sigma_a_.size()),
      kept_(sigma_a_.size()), expected_value_(expected_value),
      absorption_(expected_value ? sigma_a_.size() * FinishedPhotons::kCapacity : 0),
      runs_(sigma_a_.size()), fixed_(sigma_a_.size()), growth_(sigma_a_.size()),
      // (equal-area theta bins go through a vector sine, not shown monotone: always settled)
      theta_closed_form_(grid.theta_binning == ThetaBinning::Uniform &&
                         edges_at_closed_form(grid.theta_edges, kPi / 2, kPi)),
      phi_closed_form_(edges_at_closed_form(grid.phi_edges, kPi, kTwoPi)) {}

void ExitScorer::block_bins(const FinishedPhotons& f, std::int64_t* theta_bin, std::int64_t* phi_bin) const {
  constexpr int W = static_cast<int>(Batch::size);
  const int n_theta = grid_.n_theta(), n_phi = grid_.n_phi();
  const bool uniform = grid_.theta_binning == ThetaBinning::Uniform;
  for (int i = 0; i < f.n; i += W) {
    const Batch theta = Batch::load_aligned(f.theta + i);
    const Batch theta_fraction = uniform ? uniform_fraction(theta, kPi / 2, kPi)
                                         : Batch(0.5) * (xsimd::sin(theta) + Batch(1.0));
    settled_bin(theta, theta_fraction, n_theta, grid_.theta_edges, theta_closed_form_)
        .store_aligned(theta_bin + i);
    Batch::batch_bool_type in_range;
    const Batch relative = Batch::load_aligned(f.phi + i) - Batch::load_aligned(f.phi_i + i);
    const Batch phi = wrapped(relative, in_range);
    settled_bin(phi, uniform_fraction(phi, kPi, kTwoPi), n_phi, grid_.phi_edges, phi_closed_form_)
        .store_aligned(phi_bin + i);
    // Lanes out of the vector wrap's range take the scalar one. Rows that
    // did not exit may have no direction (NaN: a truncated photon, an
    // expected-value row of Russian roulette alone): their bins are never
    // read, settled_bin gives them 0 as it does their theta, and a NaN must
    // not reach phi_bin's conversion to int.
    if (!xsimd::all(in_range | xsimd::isnan(relative)))
      for (int k = i; k < std::min(i + W, f.n); ++k)
        phi_bin[k] = f.exited[k] ? grid_.phi_bin(wrap_angle(f.phi[k] - f.phi_i[k])) : 0;
  }
}

void ExitScorer::score(const FinishedPhotons& f, Tally& tally) {
  constexpr int W = static_cast<int>(Batch::size);
  constexpr int kCap = FinishedPhotons::kCapacity;
  const int channels = static_cast<int>(sigma_a_.size());
  for (int c = 0; c < channels; ++c) {
    const Batch minus_sigma(-sigma_a_[c]);
    double* w = weights_.data() + static_cast<std::size_t>(c) * kCap;
    if (expected_value_) {
      // Beer-Lambert's factor kept apart: Russian roulette's rows need it
      // without the row's weight.
      double* a = absorption_.data() + static_cast<std::size_t>(c) * kCap;
      const Batch minus_medulla(medulla_sigma_a_.empty() ? 0.0 : -medulla_sigma_a_[c]);
      for (int i = 0; i < f.n; i += W) {
        Batch exponent = minus_sigma * Batch::load_aligned(f.path + i);
        if (!medulla_sigma_a_.empty())
          exponent = exponent + minus_medulla * Batch::load_aligned(f.medulla_path + i);
        const Batch factor = xsimd::exp(exponent);
        factor.store_unaligned(a + i);
        (Batch::load_aligned(f.weight + i) * factor).store_unaligned(w + i);
      }
    } else if (medulla_sigma_a_.empty()) {
      for (int i = 0; i < f.n; i += W)
        (Batch::load_aligned(f.weight + i) * xsimd::exp(minus_sigma * Batch::load_aligned(f.path + i)))
            .store_unaligned(w + i);
    } else {
      // Beer-Lambert in the cortex and in the medulla, each with its own sigma_a.
      const Batch minus_medulla(-medulla_sigma_a_[c]);
      for (int i = 0; i < f.n; i += W)
        (Batch::load_aligned(f.weight + i) *
         xsimd::exp(minus_sigma * Batch::load_aligned(f.path + i) +
                    minus_medulla * Batch::load_aligned(f.medulla_path + i)))
            .store_unaligned(w + i);
    }
  }
  alignas(64) std::int64_t theta_bin[kCap], phi_bin[kCap];
  block_bins(f, theta_bin, phi_bin);
  std::size_t bin[kCap];
  for (int i = 0; i < f.n; ++i) {
    if (!f.exited[i]) continue;
    const int lobe = f.scattered[i] ? last_lobe_ + 1 : std::min(f.segments[i], last_lobe_);
    bin[i] = tally.bin_index(lobe, static_cast<int>(theta_bin[i]),
                             static_cast<int>(phi_bin[i]));
    // (Expected-value rows are fetched a few rows ahead as they are scored:
    // a block of them holds twice the analog estimator's rows, too many to
    // have in flight at once.)
    if (expected_value_) lobe_[i] = lobe;
    else tally.prefetch(bin[i]);
  }
  if (expected_value_) {
    score_rows_expected_value(f, bin, tally);
    return;
  }
  double* weight = one_photon_.data();
  for (int i = 0; i < f.n; ++i) {
    if (f.exited[i]) {
      tally.score_exit(bin[i], weights_.data() + i, kCap);
    } else if (!f.lost[i]) {
      for (int c = 0; c < channels; ++c) weight[c] = weights_[static_cast<std::size_t>(c) * kCap + i];
      tally.score_truncated(weight);
    }
  }
  // Masking's removals, each absorbed along the path up to it,
  // summed per photon (a photon's removals are consecutive in f.losses).
  double* kept = kept_.data();
  for (std::size_t j = 0; j < f.losses.size();) {
    const int slot = f.losses[j].slot;
    std::fill(weight, weight + channels, 0.0);
    for (; j < f.losses.size() && f.losses[j].slot == slot; ++j) {
      const WeightLoss& l = f.losses[j].loss;
      for (int c = 0; c < channels; ++c) weight[c] += l.weight * std::exp(-sigma_a_[c] * l.path_length);
    }
    for (int c = 0; c < channels; ++c) kept[c] = weights_[static_cast<std::size_t>(c) * kCap + slot];
    tally.score_lost(weight, kept);
  }
}

// A photon's rows in order (sim/life/finished_photons.h): its exits added up
// per bin and per lobe, each row's weight booked in fixed point within the
// room its earlier rows left of its unit weight (plus what Russian roulette
// created for it), the weight roulette created or destroyed booked in the
// ledger's roulette term, and its masking losses (at its last row) booked
// against all it kept.
void ExitScorer::score_rows_expected_value(const FinishedPhotons& f, const std::size_t* bin,
                                           Tally& tally) {
  constexpr int kCap = FinishedPhotons::kCapacity;
  const int channels = static_cast<int>(sigma_a_.size());
  double* weight = one_photon_.data();
  reserve_slots(f);
  for (int i = 0; i < std::min(kRowsAhead, f.n); ++i) prefetch_row(f, i, bin, tally);
  std::size_t j = 0;  // the next of f.losses (in row order)
  for (int i = 0; i < f.n; ++i) {
    if (i + kRowsAhead < f.n) prefetch_row(f, i + kRowsAhead, bin, tally);
    const std::uint32_t slot = f.slot[i];
    if (f.roulette[i] != 0.0) score_roulette(f, i, tally);
    if (f.exited[i]) {
      // (The common three channels unrolled, their numbers in registers.)
      if (channels == 3) score_scored_exit<3>(f, i, bin[i], tally);
      else score_scored_exit<0>(f, i, bin[i], tally);
    } else if (f.last[i] && !f.lost[i] && !f.ended[i]) {
      book(weights_.data() + i, kCap, slot, fixed_.data());
      tally.score_truncated_fixed(fixed_.data());
    }
    if (!f.last[i]) continue;
    if (j < f.losses.size() && f.losses[j].slot == i) {
      std::fill(weight, weight + channels, 0.0);
      for (; j < f.losses.size() && f.losses[j].slot == i; ++j) {
        const WeightLoss& l = f.losses[j].loss;
        for (int c = 0; c < channels; ++c) weight[c] += l.weight * std::exp(-sigma_a_[c] * l.path_length);
      }
      // What it kept: 1 - its room (Tally::score_lost's 1 - kept is the room).
      const std::size_t at = static_cast<std::size_t>(slot) * channels;
      for (int c = 0; c < channels; ++c) fixed_[c] = Tally::kOne - room_[at + c];
      tally.score_lost(weight, fixed_.data());
    }
    end_photon(slot, tally);
  }
}

// Asks for what scoring row i reads and writes: its tally cells (an exit)
// and its photon's numbers so far (the block's stream of cells evicts them
// from the first-level cache between a photon's rows).
[[gnu::always_inline]] inline void ExitScorer::prefetch_row(const FinishedPhotons& f, int i,
                                                          const std::size_t* bin,
                                                          const Tally& tally) const {
  const std::size_t at = static_cast<std::size_t>(f.slot[i]) * sigma_a_.size();
  __builtin_prefetch(room_.data() + at, 1);
  if (!f.exited[i]) return;
  tally.prefetch_all(bin[i]);
  __builtin_prefetch(lobe_total_.data() + at, 1);
  runs_.prefetch(f.slot[i]);
}

// Room for every slot the block uses (once: slots are the tracer's, a
// pool's worth).
void ExitScorer::reserve_slots(const FinishedPhotons& f) {
  std::uint32_t top = 0;
  for (int i = 0; i < f.n; ++i) top = std::max(top, f.slot[i]);
  if (top < runs_.slots()) return;
  const std::size_t slots = top + 1, channels = sigma_a_.size();
  room_.resize(slots * channels, Tally::kOne);
  lobe_total_.resize(slots * channels, 0.0);
  runs_.reserve(slots);
}

void ExitScorer::end_photon(std::uint32_t slot, Tally& tally) {
  const std::size_t channels = sigma_a_.size(), at = slot * channels;
  std::fill_n(room_.begin() + at, channels, Tally::kOne);
  if (runs_.lobe(slot) >= 0) tally.score_lobe_total(runs_.lobe(slot), lobe_total_.data() + at);
  runs_.start(slot, -1);
}

// One row's weight in fixed point, into fixed_: at most the room the
// photon's earlier rows left of its unit weight. The parts of a split weight
// (w P and w (1 - P)) are rounded products whose sum can exceed w by a few
// 2^-53, and each part rounds to fixed point: on a white fiber that would
// leave the ledger's absorbed (the complement) a few units below 0. More
// than rounding (Tally::kRoundingAllowance) is a booking error: an internal
// error, never clamped.
template <int kChannels>
[[gnu::always_inline]] inline void ExitScorer::book(const double* weight, std::size_t stride,
                                                    std::uint32_t slot, Tally::Fixed* fixed) {
  const std::size_t channels = kChannels > 0 ? kChannels : sigma_a_.size(), at = slot * channels;
  for (std::size_t c = 0; c < channels; ++c) {
    Tally::Fixed w = Tally::to_fixed(weight[c * stride]);
    const Tally::Fixed room = room_[at + c];
    if (w > room) {
      if (w - room > Tally::kRoundingAllowance)
        throw Error(fmt::format("internal error: a photon's exits and truncated weight exceed 1 "
                                "(channel {}) by more than rounding", c));
      w = room;
    }
    room_[at + c] = room - w;
    fixed[c] = w;
  }
}

// Row i's Russian roulette (f.roulette[i], before absorption), absorbed along
// the path to it: weight created widens the photon's room; weight destroyed
// is booked like an exit (within the room), and the ledger's roulette term
// gains the signed amount.
void ExitScorer::score_roulette(const FinishedPhotons& f, int i, Tally& tally) {
  constexpr int kCap = FinishedPhotons::kCapacity;
  const std::size_t channels = sigma_a_.size(), at = f.slot[i] * channels;
  const double r = f.roulette[i];
  for (std::size_t c = 0; c < channels; ++c) growth_[c] = std::abs(r) * absorption_[c * kCap + i];
  if (r > 0.0) {
    for (std::size_t c = 0; c < channels; ++c) {
      fixed_[c] = Tally::to_fixed(growth_[c]);
      room_[at + c] += fixed_[c];
    }
  } else {
    book(growth_.data(), 1, f.slot[i], fixed_.data());
    for (std::size_t c = 0; c < channels; ++c) fixed_[c] = -fixed_[c];
  }
  tally.score_roulette_fixed(fixed_.data());
}

// Row i's exit in `bin`: the bin's S2 grows by (t + w)^2 - t^2 = w (2 t + w)
// with t the photon's total in the bin so far, so that it ends with the
// square of the photon's total (SPEC section 6); the lobe's likewise.
// kChannels: the number of channels, or 0 for sigma_a's (any number).
template <int kChannels>
void ExitScorer::score_scored_exit(const FinishedPhotons& f, int i, std::size_t bin, Tally& tally) {
  constexpr int kCap = FinishedPhotons::kCapacity;
  const std::uint32_t slot = f.slot[i];
  const std::size_t channels = kChannels > 0 ? kChannels : sigma_a_.size(), at = slot * channels;
  const double* weight = weights_.data() + i;
  // One row's numbers: fixed and growth (channels of them).
  constexpr std::size_t kLocal = kChannels > 0 ? kChannels : 1;
  Tally::Fixed fixed_local[kLocal];
  double growth_local[kLocal];
  Tally::Fixed* fixed = kChannels > 0 ? fixed_local : fixed_.data();
  double* growth = kChannels > 0 ? growth_local : growth_.data();
  book<kChannels>(weight, kCap, slot, fixed);
  // The photon's total in its lobe: squared into the lobe's sum of squares
  // once it is done there (a new lobe, or its end: end_photon).
  double* lobe_total = lobe_total_.data() + at;
  if (runs_.lobe(slot) != lobe_[i]) {
    if (runs_.lobe(slot) >= 0) tally.score_lobe_total(runs_.lobe(slot), lobe_total);
    runs_.start(slot, lobe_[i]);
    for (std::size_t c = 0; c < channels; ++c) lobe_total[c] = 0.0;
  }
  for (std::size_t c = 0; c < channels; ++c) lobe_total[c] += weight[c * kCap];
  if (double* total = runs_.find(slot, bin)) {
    for (std::size_t c = 0; c < channels; ++c) {
      const double w = weight[c * kCap];
      growth[c] = w * (2.0 * total[c] + w);
      total[c] += w;
    }
    tally.score_exit_fixed<kChannels>(bin, fixed, growth, false);
    return;
  }
  runs_.append(slot, bin, weight, kCap);
  for (std::size_t c = 0; c < channels; ++c) {
    const double w = weight[c * kCap];
    growth[c] = w * w;
  }
  tally.score_exit_fixed<kChannels>(bin, fixed, growth, true);
}

}  // namespace fiberlab::sim
