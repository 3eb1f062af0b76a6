#pragma once
// Per tracer slot (sim/life/finished_photons.h), the photon in it: the lobe of
// its latest exit and, for the bins of that lobe it has left in so far, its
// total in each (per channel). A photon's lobes never decrease along its rows
// (min(p, L - 1) with p growing; the medulla's `scattered` once scattered),
// so its exits in one lobe are consecutive and a run is emptied when the lobe
// changes. The scorer (sim/life/exit_scoring.h) reads a photon's total in a
// bin to grow S2 by the square of the photon's total (SPEC section 6).
//
// Flat arrays, a fixed number of entries per slot (grown for every slot when
// one run outgrows it): a run is found without following a pointer.
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fiberlab::sim {

class PhotonRuns {
 public:
  explicit PhotonRuns(std::size_t channels) : channels_(channels) {}

  // Room for slots [0, slots).
  void reserve(std::size_t slots) {
    if (slots <= lobe_.size()) return;
    lobe_.resize(slots, -1);
    size_.resize(slots, 0);
    bins_.resize(slots * capacity_);
    totals_.resize(slots * capacity_ * channels_);
  }
  std::size_t slots() const { return lobe_.size(); }
  int lobe(std::uint32_t slot) const { return lobe_[slot]; }
  // An empty run of `lobe` (-1: no photon).
  void start(std::uint32_t slot, int lobe) {
    lobe_[slot] = lobe;
    size_[slot] = 0;
  }
  // The photon's totals [channel] in `bin` of its run, or nullptr.
  // Branch-free over the run's length where AVX-512 allows (8 entries a
  // compare): a loop whose trip count follows the run mispredicts its exit
  // on nearly every row when exit splitting fills a run.
  double* find(std::uint32_t slot, std::size_t bin) {
    const std::uint64_t* bins = bins_.data() + slot * capacity_;
    const std::size_t n = size_[slot];
#if defined(__AVX512F__)
    const __m512i wanted = _mm512_set1_epi64(static_cast<long long>(bin));
    for (std::size_t e = 0; e < n; e += 8) {
      // (capacity_ is a multiple of 8: the vector lies within the slot's entries)
      const __mmask8 valid = n - e >= 8 ? __mmask8(0xff) : __mmask8((1u << (n - e)) - 1);
      const __mmask8 hits = _mm512_mask_cmpeq_epu64_mask(valid, _mm512_loadu_si512(bins + e), wanted);
      if (hits != 0) return totals_.data() + (slot * capacity_ + e + std::countr_zero(unsigned{hits})) * channels_;
    }
#else
    for (std::size_t e = 0; e < n; ++e)
      if (bins[e] == bin) return totals_.data() + (slot * capacity_ + e) * channels_;
#endif
    return nullptr;
  }
  // A new entry for `bin` with totals weight[c * stride].
  void append(std::uint32_t slot, std::size_t bin, const double* weight, std::size_t stride) {
    if (size_[slot] == capacity_) grow();
    const std::size_t e = slot * capacity_ + size_[slot]++;
    bins_[e] = bin;
    for (std::size_t c = 0; c < channels_; ++c) totals_[e * channels_ + c] = weight[c * stride];
  }
  // Asks for what find and append read.
  void prefetch(std::uint32_t slot) const {
    __builtin_prefetch(bins_.data() + slot * capacity_, 1);
    __builtin_prefetch(totals_.data() + slot * capacity_ * channels_, 1);
  }

 private:
  void grow() {
    const std::size_t slots = lobe_.size(), wider = 2 * capacity_;
    std::vector<std::uint64_t> bins(slots * wider);
    std::vector<double> totals(slots * wider * channels_);
    for (std::size_t s = 0; s < slots; ++s) {
      std::copy_n(bins_.data() + s * capacity_, size_[s], bins.data() + s * wider);
      std::copy_n(totals_.data() + s * capacity_ * channels_, size_[s] * channels_,
                  totals.data() + s * wider * channels_);
    }
    bins_.swap(bins);
    totals_.swap(totals);
    capacity_ = wider;
  }

  std::size_t channels_;
  std::size_t capacity_ = 32;
  std::vector<int> lobe_;
  std::vector<std::size_t> size_;
  std::vector<std::uint64_t> bins_;  // [slot][entry]
  std::vector<double> totals_;       // [slot][entry][channel]
};

}  // namespace fiberlab::sim
