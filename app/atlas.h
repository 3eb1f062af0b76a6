#pragma once
// `fiberlab atlas`: a sweep of physical fibers simulated and every model
// judged on each, before and after its fit (compare/atlas.h), with the
// checkpoint saved after each fiber (compare/atlas_checkpoint.h), --resume,
// and under `mpirun -np N` the fibers spread over the ranks, rank 0 alone
// writing (docs/ATLAS.md "Many processes"). Two steps, so that the caller
// can print what is written before the report (its plots take a while) is
// made: run_atlas (the fibers and OUT), then write_atlas_report (the report
// folder; the checkpoint removed).
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "compare/atlas.h"
#include "compare/atlas_checkpoint.h"
#include "compare/atlas_config.h"
#include "sim/run/process_group.h"

namespace fiberlab::app {

// The flags of `fiberlab atlas`, as given (the numbers still as text).
struct AtlasRequest {
  std::string config, output, report, threads, photons, resume;
  std::string command;  // the command line the report shows
};

// What an atlas ran and wrote, for rank 0 to print (other ranks print nothing).
struct AtlasRun {
  bool root = true;
  bool failed_elsewhere = false;  // another rank failed; rank 0 says why
  int ranks = 1;                  // processes the fibers were spread over
  // A signal stopped the sweep: the fibers finished before it (`fibers`) are
  // in `checkpoint`, OUT is not written.
  int interrupted_by = 0;
  bool resumed = false;
  std::size_t fibers_total = 0;
  compare::AtlasRunSetup setup;
  compare::AtlasConfig config;
  std::vector<compare::AtlasFiberResult> fibers;  // rank 0: every finished fiber
  std::string output, report, checkpoint;         // OUT, the report folder, OUT.checkpoint.h5
  std::string headline;                           // rank 0, OUT written: compare::atlas_headline_markdown
  bool written() const { return root && !failed_elsewhere && interrupted_by == 0; }
};

// This rank's part of the atlas in `group` (the caller keeps the group, and
// so MPI, alive until it has printed). `progress` (rank 0 only; may be
// empty) gets one line at a time for stderr. Throws fiberlab::Error on bad
// input (on rank 0 with the failing rank's message); nothing is written then.
AtlasRun run_atlas(const sim::ProcessGroup& group, const AtlasRequest& request,
                   const std::function<void(const std::string&)>& progress = {});

// The report folder of a written atlas (compare::write_atlas_report), then
// the checkpoint removed (it has served).
struct AtlasReportOutcome {
  std::string line;         // what the report writer says ("report: DIR/report.md ...")
  int interrupted_by = 0;   // a signal arrived while the report was made: the checkpoint is kept
  std::string checkpoint_left;  // why the checkpoint could not be removed ("" when it was)
};
AtlasReportOutcome write_atlas_report(const AtlasRun& run);

}  // namespace fiberlab::app
