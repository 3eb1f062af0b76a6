#pragma once
// How many OpenMP threads a simulation gets: the rule of `fiberlab run
// --threads` and of fiberlab.run(threads=...).
namespace fiberlab::app {

// requested <= 0: every core, at most sim::kMaxThreads (sim/run/memory_budget.h);
// 1 to kMaxThreads: as requested; more is refused (fiberlab::Error naming
// `threads`, the Python argument; the command line checks --threads itself).
int run_threads(int requested);

}  // namespace fiberlab::app
