#pragma once
// `fiberlab run`: a configuration simulated into its result file, on every
// MPI rank, with checkpoints and --resume; and the in-memory run of
// fiberlab.run() and `fiberlab energy --run`.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sim/run/process_group.h"
#include "sim/run/simulation.h"
#include "sim/store/result_file.h"

namespace fiberlab::app {

// The flags of `fiberlab run`, as given: the numbers still as text, checked
// here in the order the command states them (sim::parse_integer_flag).
struct RunRequest {
  std::string config, output, resume;
  std::string photons, seed, threads;
  bool output_given = false, photons_given = false, seed_given = false, threads_given = false;
  double checkpoint_every = 300.0;
  double target_error = 0.0;
  bool summary = true;  // false (--quiet): no result is assembled for a summary
};

// What a run did, for rank 0 to print (other ranks print nothing).
struct RunReport {
  bool root = true;
  bool failed_elsewhere = false;  // another rank failed; rank 0 says why
  int interrupted_by = 0;         // a signal stopped the run, its progress is in `checkpoint`
  std::string checkpoint, output;
  double target_error = 0.0;
  std::optional<sim::ResultFile> result;  // rank 0, when the request asked for a summary
  std::vector<double> reached_error;      // per direction, with a target error
  sim::RunStatistics stats;
  double write_seconds = 0.0;
};

// This rank's part of the run in `group` (every rank of an MPI launch; the
// caller keeps the group, and so MPI, alive until it has printed the
// report). `progress`, when given, makes rank 0's progress callback once the
// run is set up. Throws fiberlab::Error on bad input (on rank 0 with the
// failing rank's message).
RunReport run(const sim::ProcessGroup& group, const RunRequest& request,
              const std::function<sim::ProgressCallback()>& progress = {});

// photons x incident configurations must fit in uint64 (sim/run/settings.cpp
// checks a config; a --photons flag or fiberlab.run's photons can raise
// photons past it): otherwise fiberlab::Error, `what` naming the override.
void check_total_photons(const sim::Settings& settings, const std::string& what);

// One process's in-memory run of `settings` on `threads` threads (after the
// memory budget, sim/run/memory_budget.h). No result when a signal stopped it.
std::optional<sim::ResultFile> simulate(const sim::Settings& settings, int threads,
                                        const sim::ProgressCallback& progress = {});

}  // namespace fiberlab::app
