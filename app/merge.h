#pragma once
// `fiberlab merge A.h5 B.h5 ... -o C.h5`: adds runs of one config made with
// different seeds and joins runs of different incident directions (how a run
// is split over machines or a job array); the rules: sim/store/merge.h.
#include <string>
#include <vector>

#include "sim/store/merge.h"

namespace fiberlab::app {

// Checks the output path first (not onto an input, a FIFO, ...), then
// merges. Throws fiberlab::Error naming the file at fault.
sim::MergeSummary merge(const std::vector<std::string>& inputs, const std::string& output);

}  // namespace fiberlab::app
