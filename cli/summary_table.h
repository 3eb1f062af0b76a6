#pragma once
// The short per-direction table that `run` prints at the end and `info` prints
// for a file: lobe energies per channel with standard errors, absorbed and
// truncated fractions.
#include <cstdio>

#include "sim/store/result_file.h"

namespace fiberlab::cli {

void print_summary(std::FILE* out, const sim::ResultFile& r);

}  // namespace fiberlab::cli
