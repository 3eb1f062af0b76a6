#include "sim/store/tally.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/error.h"

namespace fiberlab::sim {

Tally::Tally(int lobes, int n_theta, int n_phi, int channels)
    : lobes_(lobes), n_theta_(n_theta), n_phi_(n_phi), channels_(channels),
      memory_(bins() * block() * sizeof(Fixed)), touched_(pages(), 0) {
  truncated_.assign(channels, 0);
  lost_.assign(channels, 0);
  roulette_.assign(channels, 0);
  lobe_sq_.assign(static_cast<std::size_t>(lobes) * channels, 0);
}

Tally::Tally(const Tally& o) : Tally(o.lobes_, o.n_theta_, o.n_phi_, o.channels_) { add(o); }

Tally& Tally::operator=(const Tally& o) {
  if (this != &o) *this = Tally(o);
  return *this;
}

void Tally::clear() {
  Fixed* cell = cells();
  for (std::size_t p = 0; p < touched_.size(); ++p) {
    if (!touched_[p]) continue;
    std::fill(cell + page_begin(p), cell + page_end(p), Fixed{0});
    touched_[p] = 0;
  }
  photons_ = 0;
  std::fill(truncated_.begin(), truncated_.end(), Fixed{0});
  std::fill(lost_.begin(), lost_.end(), Fixed{0});
  std::fill(roulette_.begin(), roulette_.end(), Fixed{0});
  std::fill(lobe_sq_.begin(), lobe_sq_.end(), Fixed{0});
}

void Tally::score_truncated(const double* weight) {
  for (int c = 0; c < channels_; ++c) truncated_[c] += to_fixed(weight[c]);
}

void Tally::score_lost(const double* lost, const double* kept) {
  std::vector<Fixed> kept_fixed(channels_);
  for (int c = 0; c < channels_; ++c) kept_fixed[c] = to_fixed(kept[c]);
  score_lost(lost, kept_fixed.data());
}

void Tally::score_lost(const double* lost, const Fixed* kept) {
  constexpr Fixed one = kOne;
  // Rounding of a photon's products: a few 2^-53 per event, so 2^-40 (about
  // 1e-12 of the photon's weight) is far beyond it, and far below any real
  // double booking (of the order of the weight itself).
  constexpr Fixed rounding_allowance = kRoundingAllowance;
  for (int c = 0; c < channels_; ++c) {
    const Fixed room = one - kept[c], booked = to_fixed(lost[c]);
    if (booked - room > rounding_allowance)
      throw Error(fmt::format("internal error: a photon's lost weight {} plus its kept weight {} exceeds 1 "
                              "(channel {}) by more than rounding",
                              lost[c], static_cast<double>(kept[c]) / kScale, c));
    lost_[c] += std::min(booked, room);
  }
}

void Tally::add(const Tally& o, int threads) {
  if (!(o.shape() == shape())) throw Error("internal error: adding a tally of another shape");
  photons_ += o.photons_;
  Fixed* to = cells();
  const Fixed* from = o.cells();
  const auto pages = static_cast<std::ptrdiff_t>(touched_.size());
#pragma omp parallel for num_threads(std::max(1, threads)) schedule(static) if (threads > 1)
  for (std::ptrdiff_t p = 0; p < pages; ++p) {
    if (!o.touched_[p]) continue;
    touched_[p] = 1;
    for (std::size_t i = page_begin(p); i < page_end(p); ++i) to[i] += from[i];
  }
  for (int c = 0; c < channels_; ++c) {
    truncated_[c] += o.truncated_[c];
    lost_[c] += o.lost_[c];
    roulette_[c] += o.roulette_[c];
  }
  for (std::size_t i = 0; i < lobe_sq_.size(); ++i) lobe_sq_[i] += o.lobe_sq_[i];
}

bool Tally::is_zero() const {
  const auto zero = [](auto x) { return x == 0; };
  return photons_ == 0 && std::all_of(touched_.begin(), touched_.end(), zero) &&
         std::all_of(truncated_.begin(), truncated_.end(), zero) &&
         std::all_of(lost_.begin(), lost_.end(), zero) &&
         std::all_of(roulette_.begin(), roulette_.end(), zero) &&
         std::all_of(lobe_sq_.begin(), lobe_sq_.end(), zero);
}

ExactTally Tally::exact() const {
  ExactTally e(shape());
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_, C = channels_;
  for (int l = 0; l < lobes_; ++l)
    copy_lobe(l, e.count.data() + l * per_lobe, e.weight_sum.data() + l * per_lobe * C,
              e.weight_sq_sum.data() + l * per_lobe * C);
  ExactLedger ledger = exact_ledger();
  e.photons = ledger.photons;
  e.exited = std::move(ledger.exited);
  e.absorbed = std::move(ledger.absorbed);
  e.truncated = std::move(ledger.truncated);
  e.lost = std::move(ledger.lost);
  e.roulette = std::move(ledger.roulette);
  e.lobe_weight_sq_sum = std::move(ledger.lobe_weight_sq_sum);
  return e;
}

void Tally::lobe_counts(int l, std::vector<std::uint64_t>& out) const {
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_;
  const std::size_t first = static_cast<std::size_t>(l) * per_lobe;
  out.resize(per_lobe);  // every element is written: a reused buffer is not cleared first
  for (std::size_t i = 0; i < per_lobe; ++i)
    out[i] = touched_[(first + i) / kPageBins]
                 ? static_cast<std::uint64_t>(cells()[(first + i) * block()])
                 : 0;
}

// Straight from the cells into the file's values and residuals: no copy of
// the lobe as 128-bit words (fresh memory costs a page fault per 4 KiB here).
void Tally::lobe_sums(int l, BinSum which, std::vector<double>& value,
                      std::vector<std::int64_t>& residual) const {
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_, C = channels_;
  const std::size_t first = static_cast<std::size_t>(l) * per_lobe;
  const std::size_t offset = which == BinSum::S1 ? 1 : 1 + C;  // in a bin's block
  value.resize(per_lobe * C);
  residual.resize(per_lobe * C);
  for (std::size_t i = 0; i < per_lobe; ++i) {
    double* v = value.data() + i * C;
    std::int64_t* r = residual.data() + i * C;
    if (!touched_[(first + i) / kPageBins]) {
      std::fill(v, v + C, 0.0);
      std::fill(r, r + C, std::int64_t{0});
      continue;
    }
    const Fixed* sums = cells() + (first + i) * block() + offset;
    for (std::size_t c = 0; c < C; ++c)
      ExactTally::split(static_cast<ExactTally::Word>(sums[c]), v[c], r[c]);
  }
}

// Lobe l's touched bins into the arrays ([theta][phi], [theta][phi][channel]);
// the untouched ones are zero, left as they are (the arrays start zeroed).
void Tally::copy_lobe(int l, std::uint64_t* count, ExactTally::Word* s1, ExactTally::Word* s2) const {
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_, C = channels_;
  const std::size_t first = static_cast<std::size_t>(l) * per_lobe;
  for (std::size_t i = 0; i < per_lobe; ++i) {
    if (!touched_[(first + i) / kPageBins]) continue;
    const Fixed* cell = cells() + (first + i) * block();
    count[i] = static_cast<std::uint64_t>(cell[0]);
    for (std::size_t c = 0; c < C; ++c) {
      s1[i * C + c] = static_cast<ExactTally::Word>(cell[1 + c]);
      s2[i * C + c] = static_cast<ExactTally::Word>(cell[1 + C + c]);
    }
  }
}

// The ledger's exited and absorbed are derived from the bins (exact).
ExactLedger Tally::exact_ledger() const {
  ExactLedger e;
  e.photons = photons_;
  const std::size_t C = channels_;
  const std::vector<Fixed> exited = exited_fixed();
  for (Fixed x : exited) e.exited.push_back(static_cast<ExactTally::Word>(x));
  for (std::size_t c = 0; c < C; ++c) {
    Fixed absorbed = static_cast<Fixed>(photons_) << 60;
    for (int l = 0; l < lobes_; ++l) absorbed -= exited[static_cast<std::size_t>(l) * C + c];
    absorbed -= truncated_[c] + lost_[c];
    absorbed += roulette_[c];
    e.absorbed.push_back(static_cast<ExactTally::Word>(absorbed));
    e.truncated.push_back(static_cast<ExactTally::Word>(truncated_[c]));
    e.lost.push_back(static_cast<ExactTally::Word>(lost_[c]));
    e.roulette.push_back(static_cast<ExactTally::Word>(roulette_[c]));  // two's complement
  }
  for (Fixed x : lobe_sq_) e.lobe_weight_sq_sum.push_back(static_cast<ExactTally::Word>(x));
  return e;
}

void Tally::add(const ExactTally& e) {
  if (!(e.shape == shape())) throw Error("internal error: adding an exact tally of another shape");
  photons_ += e.photons;
  const std::size_t C = channels_;
  for (std::size_t b = 0; b < e.count.size(); ++b) {
    bool any = e.count[b] != 0;
    for (std::size_t c = 0; c < C && !any; ++c)
      any = e.weight_sum[b * C + c] != 0 || e.weight_sq_sum[b * C + c] != 0;
    if (!any) continue;
    touched_[b / kPageBins] = 1;
    Fixed* cell = cells() + b * block();
    cell[0] += e.count[b];
    for (std::size_t c = 0; c < C; ++c) {
      cell[1 + c] += static_cast<Fixed>(e.weight_sum[b * C + c]);
      cell[1 + C + c] += static_cast<Fixed>(e.weight_sq_sum[b * C + c]);
    }
  }
  // exited and absorbed follow from the bins, photons, truncated and lost.
  for (std::size_t c = 0; c < C; ++c) {
    truncated_[c] += static_cast<Fixed>(e.truncated[c]);
    lost_[c] += static_cast<Fixed>(e.lost[c]);
    roulette_[c] += static_cast<Fixed>(e.roulette[c]);
  }
  for (std::size_t i = 0; i < lobe_sq_.size(); ++i)
    lobe_sq_[i] += static_cast<Fixed>(e.lobe_weight_sq_sum[i]);
}

std::vector<double> Tally::to_double(const std::vector<Fixed>& v) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = static_cast<double>(v[i]) / kScale;
  return out;
}

std::vector<double> Tally::column(int offset) const {
  std::vector<double> out(bins() * channels_, 0.0);
  for (std::size_t b = 0; b < bins(); ++b) {
    if (!touched_[b / kPageBins]) continue;
    for (int c = 0; c < channels_; ++c)
      out[b * channels_ + c] = static_cast<double>(cells()[b * block() + offset + c]) / kScale;
  }
  return out;
}

std::vector<double> Tally::weight_sum() const { return column(1); }
std::vector<double> Tally::weight_sq_sum() const { return column(1 + channels_); }

std::vector<std::uint64_t> Tally::count() const {
  std::vector<std::uint64_t> out(bins(), 0);
  for (std::size_t b = 0; b < bins(); ++b)
    if (touched_[b / kPageBins]) out[b] = static_cast<std::uint64_t>(cells()[b * block()]);
  return out;
}
// The ledger (SPEC section 4) from the bins: exited is the sum of S1 over a
// lobe's bins, and every photon launched left a weight w that exited or was
// truncated, had weight removed by masking (lost) and 1 - w - lost absorbed
// (with Russian roulette, 1 + the weight it created - the weight it
// destroyed - w - lost: the signed term `roulette` is added to absorbed).
// Integer sums: exactly what per-photon counters would hold.
std::vector<Tally::Fixed> Tally::exited_fixed() const {
  std::vector<Fixed> out(static_cast<std::size_t>(lobes_) * channels_, 0);
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_;
  for (int l = 0; l < lobes_; ++l)
    for (std::size_t b = 0; b < per_lobe; ++b) {
      if (!touched_[(l * per_lobe + b) / kPageBins]) continue;
      const Fixed* s1 = cells() + (l * per_lobe + b) * block() + 1;
      for (int c = 0; c < channels_; ++c) out[static_cast<std::size_t>(l) * channels_ + c] += s1[c];
    }
  return out;
}

std::vector<double> Tally::exited() const { return to_double(exited_fixed()); }

std::vector<double> Tally::absorbed() const { return ExactTally::to_double(exact_ledger().absorbed); }
std::vector<double> Tally::truncated() const { return to_double(truncated_); }
std::vector<double> Tally::lost() const { return to_double(lost_); }
std::vector<double> Tally::roulette() const { return to_double(roulette_); }

std::vector<std::size_t> Tally::touched_bins_per_lobe() const {
  const std::size_t per_lobe = static_cast<std::size_t>(n_theta_) * n_phi_;
  std::vector<std::size_t> bins(static_cast<std::size_t>(lobes_), 0);
  for (std::size_t p = 0; p < pages(); ++p) {
    if (!touched_[p]) continue;
    // Page p's bins [p * kPageBins, end), split over the lobes they belong to.
    const std::size_t end = std::min((p + 1) * kPageBins, this->bins());
    for (std::size_t b = p * kPageBins; b < end;) {
      const std::size_t l = b / per_lobe, lobe_end = std::min(end, (l + 1) * per_lobe);
      bins[l] += lobe_end - b;
      b = lobe_end;
    }
  }
  return bins;
}

}  // namespace fiberlab::sim
