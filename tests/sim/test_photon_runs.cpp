// PhotonRuns (sim/life/photon_runs.h): per slot, a photon's bins in its
// current lobe and its total in each, which the scorer grows S2 from.
// Oracle: a plain map per slot fed the same entries; every bin must be
// found with its totals, and no bin the map lacks, including after the
// flat arrays grew past their first 32 entries per slot (exit splitting
// with 32 normals puts 32 rows in one run, and the last lobe collects rows
// of many events) and after a run was restarted.
// Mutations caught: grow() copying only slot 0's entries (slot 3's bins
// lost); find() reading the last vector of entries unmasked (a stale bin of
// the restarted run found).
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <vector>

#include "sim/life/photon_runs.h"

namespace fiberlab::sim {
namespace {

constexpr std::size_t kChannels = 3;

void expect_runs_match(PhotonRuns& runs, const std::vector<std::map<std::size_t, double>>& want,
                       std::size_t probe_bins) {
  for (std::uint32_t slot = 0; slot < want.size(); ++slot)
    for (std::size_t bin = 0; bin < probe_bins; ++bin) {
      const double* total = runs.find(slot, bin);
      const auto it = want[slot].find(bin);
      if (it == want[slot].end()) {
        EXPECT_EQ(total, nullptr) << "slot " << slot << " bin " << bin;
        continue;
      }
      ASSERT_NE(total, nullptr) << "slot " << slot << " bin " << bin;
      for (std::size_t c = 0; c < kChannels; ++c)
        EXPECT_EQ(total[c], it->second * static_cast<double>(c + 1)) << "slot " << slot << " bin " << bin;
    }
}

TEST(PhotonRuns, FindsWhatWasAppendedAcrossGrowthAndRestarts) {
  PhotonRuns runs(kChannels);
  runs.reserve(5);
  std::vector<std::map<std::size_t, double>> want(5);
  auto append = [&](std::uint32_t slot, std::size_t bin, double w) {
    const double weight[kChannels] = {w, 2.0 * w, 3.0 * w};
    runs.append(slot, bin, weight, 1);
    want[slot][bin] = w;
  };
  for (std::uint32_t slot = 0; slot < 5; ++slot) runs.start(slot, 0);
  // Slot 3 fills past the first capacity (32) and a second growth (64),
  // the others a few entries each, interleaved as the scorer's rows are.
  for (int i = 0; i < 100; ++i) {
    append(3, static_cast<std::size_t>(7 * i + 1), 0.5 + i);
    if (i % 10 == 0) append(static_cast<std::uint32_t>(i / 10 % 5 == 3 ? 4 : i / 10 % 5), 1000 + i, 0.25 * i);
  }
  expect_runs_match(runs, want, 1200);
  // A restarted run holds nothing of its old entries, found or not.
  runs.start(3, 1);
  want[3].clear();
  append(3, 8, 9.0);
  expect_runs_match(runs, want, 1200);
  EXPECT_EQ(runs.lobe(3), 1);
  EXPECT_EQ(runs.lobe(0), 0);
}

}  // namespace
}  // namespace fiberlab::sim
