// `fiberlab merge A.h5 B.h5 ... -o C.h5`: adds runs of one config made with
// different seeds and joins runs of different incident directions (how a run
// is split over machines or a job array); see sim/store/merge.h for the rules.
#include <fmt/core.h>

#include <memory>

#include "cli/commands.h"
#include "common/atomic_output.h"
#include "sim/store/merge.h"

namespace fiberlab::cli {

namespace {

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string output;
};

void merge(const MergeOptions& o) {
  check_output_target(o.output, o.inputs);  // before reading: not onto an input, a FIFO, ...
  const sim::MergeSummary m = sim::merge_result_files(o.inputs, o.output);
  fmt::print("merged {} files into {}: {} incident directions, {} of them summed over seeds\n",
             o.inputs.size(), o.output, m.directions, m.summed_directions);
}

}  // namespace

void add_merge_command(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Add result files of one config run with different seeds, or join runs of "
               "different incident directions");
  cmd->add_option("inputs", o->inputs, "Result files to merge")->required();
  cmd->add_option("-o,--output", o->output, "Merged result file")->required();
  cmd->callback([o] { merge(*o); });
}

}  // namespace fiberlab::cli
