#include "sim/exit_scoring.h"

#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>

#include "common/units.h"

namespace fiberlab::sim {

ExitScorer::ExitScorer(const BinGrid& grid, std::vector<double> sigma_a, int lobes)
    : grid_(grid), sigma_a_(std::move(sigma_a)), last_lobe_(lobes - 1),
      weights_(sigma_a_.size() * FinishedPhotons::kCapacity), one_photon_(sigma_a_.size()) {}

void ExitScorer::score(const FinishedPhotons& f, Tally& tally) {
  using Batch = xsimd::batch<double>;
  constexpr int W = static_cast<int>(Batch::size);
  constexpr int kCap = FinishedPhotons::kCapacity;
  const int channels = static_cast<int>(sigma_a_.size());
  for (int c = 0; c < channels; ++c) {
    const Batch minus_sigma(-sigma_a_[c]);
    double* w = weights_.data() + static_cast<std::size_t>(c) * kCap;
    for (int i = 0; i < f.n; i += W)
      (Batch::load_aligned(f.weight + i) * xsimd::exp(minus_sigma * Batch::load_aligned(f.path + i)))
          .store_unaligned(w + i);
  }
  std::size_t bin[kCap];
  for (int i = 0; i < f.n; ++i) {
    if (!f.exited[i]) continue;
    bin[i] = tally.bin_index(std::min(f.segments[i], last_lobe_), grid_.theta_bin(f.theta[i]),
                             grid_.phi_bin(wrap_angle(f.phi[i] - f.phi_i[i])));
    tally.prefetch(bin[i]);
  }
  double* weight = one_photon_.data();
  for (int i = 0; i < f.n; ++i) {
    for (int c = 0; c < channels; ++c) weight[c] = weights_[static_cast<std::size_t>(c) * kCap + i];
    if (f.exited[i]) tally.score_exit(bin[i], weight);
    else if (!f.lost[i]) tally.score_truncated(weight);
  }
  // Masking's removals (issue 12), absorbed along the path up to each.
  for (const FinishedPhotons::Loss& l : f.losses) {
    for (int c = 0; c < channels; ++c) weight[c] = l.loss.weight * std::exp(-sigma_a_[c] * l.loss.path_length);
    tally.score_lost(weight);
  }
}

}  // namespace fiberlab::sim
