#pragma once
// How much memory a run needs, counted from what it really allocates, and
// the check that refuses a run the machine cannot hold before anything is
// allocated (a failed allocation inside an OpenMP region cannot be reported
// cleanly; a refusal can).
#include <cstdint>

#include "sim/run/settings.h"

namespace fiberlab::sim {

// The most worker threads a run may ask for (documented in configs/README.md).
// Each thread holds its own tally; beyond this, libgomp's thread stacks and
// the tallies exhaust memory long before any speed is gained.
inline constexpr int kMaxThreads = 1024;

struct MemoryFootprint {
  std::uint64_t per_tally;     // one Tally: (2C + 1) int128 per bin, ledger
  std::uint64_t thread_tallies;  // one per thread
  std::uint64_t result_tallies;  // one per incident configuration, kept to the end
  std::uint64_t float_copies;  // the result file's float64 / uint64 arrays
  std::uint64_t total;         // sum of the above (saturating at 2^64 - 1)
};

// The bytes a `fiberlab run` of `settings` with `threads` worker threads
// allocates for its tallies and its result (sim/store/tally.h, sim/store/result_file.h).
MemoryFootprint run_footprint(const Settings& settings, int threads);

// The memory this process may use: the smallest of physical memory, the
// cgroup limit (memory.max) and RLIMIT_AS / RLIMIT_DATA.
std::uint64_t memory_available();

// Throws fiberlab::Error (one line: the footprint, its parts and the limit)
// when run_footprint(settings, threads).total exceeds memory_available().
void check_memory_budget(const Settings& settings, int threads);

}  // namespace fiberlab::sim
