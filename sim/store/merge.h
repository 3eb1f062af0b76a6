#pragma once
// `fiberlab merge`: result files of one fiber, bins and settings, run with
// different seeds and/or different incident directions, into one file.
//
// - Directions are matched by value (theta_i, phi_i). The output holds every
//   direction of the inputs, listed by increasing theta_i, then phi_i; they
//   must form a theta_i x phi_i grid (as a config's lists do).
// - A direction present in several inputs is their sum; the seeds that went
//   into it must all differ (the same seed is the same photons: refused).
// - Sums are exact (the /exact integers, sim/store/exact_tally.h), so the result does
//   not depend on the order of the inputs, and a sweep split by direction and
//   merged is bit-identical to the whole sweep run at once.
// - One direction at a time is read from each input and written out.
#include <string>
#include <vector>

namespace fiberlab::sim {

struct MergeSummary {
  std::size_t directions = 0;       // in the output
  std::size_t summed_directions = 0;  // of those, how many came from more than one input
};

// Throws fiberlab::Error naming the first offending input; writes nothing then.
MergeSummary merge_result_files(const std::vector<std::string>& inputs, const std::string& output);

}  // namespace fiberlab::sim
