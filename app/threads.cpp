#include "app/threads.h"

#include <omp.h>

#include <algorithm>
#include <string>

#include "common/error.h"
#include "sim/run/memory_budget.h"

namespace fiberlab::app {

int run_threads(int requested) {
  if (requested > sim::kMaxThreads)
    throw Error("threads = " + std::to_string(requested) + ": must be an integer from 1 to " +
                std::to_string(sim::kMaxThreads) + " (as fiberlab run --threads)");
  if (requested <= 0) return std::min(omp_get_max_threads(), sim::kMaxThreads);
  return requested;
}

}  // namespace fiberlab::app
