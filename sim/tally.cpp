#include "sim/tally.h"

#include "common/error.h"

namespace fiberlab::sim {

Tally::Tally(int lobes, int n_theta, int n_phi, int channels)
    : lobes_(lobes), n_theta_(n_theta), n_phi_(n_phi), channels_(channels) {
  const std::size_t bins = static_cast<std::size_t>(lobes) * n_theta * n_phi;
  bins_.assign(bins * block(), 0);
  exited_.assign(static_cast<std::size_t>(lobes) * channels, 0);
  absorbed_.assign(channels, 0);
  truncated_.assign(channels, 0);
}

void Tally::score_exit(int lobe, int i_theta, int i_phi, const double* weight) {
  Fixed* cell = &bins_[bin_index(lobe, i_theta, i_phi) * block()];
  ++cell[0];
  Fixed* s1 = cell + 1;
  Fixed* s2 = cell + 1 + channels_;
  for (int c = 0; c < channels_; ++c) {
    const Fixed w = to_fixed(weight[c]);
    s1[c] += w;
    s2[c] += to_fixed(weight[c] * weight[c]);
    exited_[static_cast<std::size_t>(lobe) * channels_ + c] += w;
    absorbed_[c] += static_cast<Fixed>(1) << 60;
    absorbed_[c] -= w;
  }
}

void Tally::score_truncated(const double* weight) {
  for (int c = 0; c < channels_; ++c) {
    const Fixed w = to_fixed(weight[c]);
    truncated_[c] += w;
    absorbed_[c] += (static_cast<Fixed>(1) << 60) - w;
  }
}

void Tally::add(const Tally& o) {
  photons_ += o.photons_;
  for (std::size_t i = 0; i < bins_.size(); ++i) bins_[i] += o.bins_[i];
  for (std::size_t i = 0; i < exited_.size(); ++i) exited_[i] += o.exited_[i];
  for (int c = 0; c < channels_; ++c) {
    absorbed_[c] += o.absorbed_[c];
    truncated_[c] += o.truncated_[c];
  }
}

ExactTally Tally::exact() const {
  ExactTally e(shape());
  e.photons = photons_;
  const std::size_t C = channels_;
  for (std::size_t b = 0; b < e.count.size(); ++b) {
    const Fixed* cell = &bins_[b * block()];
    e.count[b] = static_cast<std::uint64_t>(cell[0]);
    for (std::size_t c = 0; c < C; ++c) {
      e.weight_sum[b * C + c] = static_cast<ExactTally::Word>(cell[1 + c]);
      e.weight_sq_sum[b * C + c] = static_cast<ExactTally::Word>(cell[1 + C + c]);
    }
  }
  for (std::size_t i = 0; i < exited_.size(); ++i) e.exited[i] = static_cast<ExactTally::Word>(exited_[i]);
  for (std::size_t c = 0; c < C; ++c) {
    e.absorbed[c] = static_cast<ExactTally::Word>(absorbed_[c]);
    e.truncated[c] = static_cast<ExactTally::Word>(truncated_[c]);
  }
  return e;
}

void Tally::add(const ExactTally& e) {
  if (!(e.shape == shape())) throw Error("internal error: adding an exact tally of another shape");
  photons_ += e.photons;
  const std::size_t C = channels_;
  for (std::size_t b = 0; b < e.count.size(); ++b) {
    Fixed* cell = &bins_[b * block()];
    cell[0] += e.count[b];
    for (std::size_t c = 0; c < C; ++c) {
      cell[1 + c] += static_cast<Fixed>(e.weight_sum[b * C + c]);
      cell[1 + C + c] += static_cast<Fixed>(e.weight_sq_sum[b * C + c]);
    }
  }
  for (std::size_t i = 0; i < exited_.size(); ++i) exited_[i] += static_cast<Fixed>(e.exited[i]);
  for (std::size_t c = 0; c < C; ++c) {
    absorbed_[c] += static_cast<Fixed>(e.absorbed[c]);
    truncated_[c] += static_cast<Fixed>(e.truncated[c]);
  }
}

std::vector<double> Tally::to_double(const std::vector<Fixed>& v) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = static_cast<double>(v[i]) / kScale;
  return out;
}

std::vector<double> Tally::column(int offset) const {
  const std::size_t bins = bins_.size() / block();
  std::vector<double> out(bins * channels_);
  for (std::size_t b = 0; b < bins; ++b)
    for (int c = 0; c < channels_; ++c)
      out[b * channels_ + c] = static_cast<double>(bins_[b * block() + offset + c]) / kScale;
  return out;
}

std::vector<double> Tally::weight_sum() const { return column(1); }
std::vector<double> Tally::weight_sq_sum() const { return column(1 + channels_); }

std::vector<std::uint64_t> Tally::count() const {
  const std::size_t bins = bins_.size() / block();
  std::vector<std::uint64_t> out(bins);
  for (std::size_t b = 0; b < bins; ++b) out[b] = static_cast<std::uint64_t>(bins_[b * block()]);
  return out;
}
std::vector<double> Tally::exited() const { return to_double(exited_); }
std::vector<double> Tally::absorbed() const { return to_double(absorbed_); }
std::vector<double> Tally::truncated() const { return to_double(truncated_); }

}  // namespace fiberlab::sim
