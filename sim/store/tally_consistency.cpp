#include "sim/store/tally_consistency.h"

#include <fmt/core.h>

namespace fiberlab::sim {

namespace {

using Word = ExactTally::Word;
constexpr Word kOne = Word{1} << 60;  // a weight of 1 in fixed point (ExactTally::kScale)

double as_double(Word w) { return static_cast<double>(w) / ExactTally::kScale; }

}  // namespace

std::string tally_inconsistency(const ExactTally& t, bool one_exit_per_photon) {
  const TallyShape& s = t.shape;
  const std::size_t L = s.lobes, C = s.channels;
  const std::size_t bins_per_lobe = static_cast<std::size_t>(s.n_theta) * s.n_phi;
  if (t.count.size() != L * bins_per_lobe || t.weight_sum.size() != L * bins_per_lobe * C ||
      t.weight_sq_sum.size() != t.weight_sum.size() || t.exited.size() != L * C ||
      t.absorbed.size() != C || t.truncated.size() != C || t.lost.size() != C ||
      t.roulette.size() != C)
    return "its arrays do not have the tally's shape";
  unsigned __int128 counted = 0;
  std::vector<Word> bin_s1(L * C, 0);
  for (std::size_t b = 0; b < L * bins_per_lobe; ++b) {
    const std::uint64_t n = t.count[b];
    if (n > t.photons)
      return fmt::format("bin {} counts {} photons, more than the {} launched", b, n, t.photons);
    counted += n;
    for (std::size_t c = 0; c < C; ++c) {
      const Word s1 = t.weight_sum[b * C + c], s2 = t.weight_sq_sum[b * C + c];
      bin_s1[(b / bins_per_lobe) * C + c] += s1;
      // With expected-value scoring a photon's total in a bin is at most 1
      // plus what Russian roulette created for it: not bounded by 1.
      if (!one_exit_per_photon) continue;
      if (s1 > static_cast<Word>(n) * kOne)
        return fmt::format("bin {} channel {}: weight_sum {} exceeds its count {} (an exit "
                           "weighs at most 1)", b, c, as_double(s1), n);
      if (s2 > s1)
        return fmt::format("bin {} channel {}: weight_sq_sum {} exceeds weight_sum {}", b, c,
                           as_double(s2), as_double(s1));
    }
  }
  if (one_exit_per_photon && counted > t.photons)
    return fmt::format("its bins count {} exits, more than the {} photons launched",
                       static_cast<double>(counted), t.photons);
  for (std::size_t i = 0; i < L * C; ++i)
    if (bin_s1[i] != t.exited[i])
      return fmt::format("lobe {} channel {}: the ledger's exited {} is not the sum of the "
                         "lobe's bins {}", i / C, i % C, as_double(t.exited[i]),
                         as_double(bin_s1[i]));
  const Word launched = static_cast<Word>(t.photons) * kOne;
  for (std::size_t c = 0; c < C; ++c) {
    if (one_exit_per_photon && t.roulette[c] != 0)
      return fmt::format("channel {}: the ledger's roulette is not 0 (the analog estimator "
                         "plays no Russian roulette)", c);
    // Wraps modulo 2^128 (roulette is signed, two's complement): exact.
    const Word total_with_roulette = t.absorbed[c] + t.truncated[c] + t.lost[c] - t.roulette[c];
    Word total = t.absorbed[c];
    bool overflow = false;
    for (Word part : {t.truncated[c], t.lost[c]}) {
      overflow |= total + part < total;
      total += part;
    }
    for (std::size_t l = 0; l < L; ++l) {
      overflow |= total + t.exited[l * C + c] < total;
      total += t.exited[l * C + c];
    }
    if (t.roulette[c] != 0) {
      Word sum = total_with_roulette;
      for (std::size_t l = 0; l < L; ++l) sum += t.exited[l * C + c];
      if (sum != launched)
        return fmt::format("channel {}: the ledger does not balance (exited + absorbed + "
                           "truncated + lost - roulette must equal the {} photons launched "
                           "exactly)", c, t.photons);
      continue;
    }
    if (overflow || total != launched)
      return fmt::format("channel {}: the ledger does not balance (exited + absorbed + "
                         "truncated + lost = {}, must equal the {} photons launched exactly)",
                         c, overflow ? -1.0 : as_double(total), t.photons);
  }
  return "";
}

}  // namespace fiberlab::sim
