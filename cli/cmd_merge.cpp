// `fiberlab merge A.h5 B.h5 ... -o C.h5`: adds runs of one config made with
// different seeds and joins runs of different incident directions; the
// workflow: app/merge.h.
#include <fmt/core.h>

#include <memory>

#include "app/merge.h"
#include "cli/commands.h"

namespace fiberlab::cli {

namespace {

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string output;
};

}  // namespace

void add_merge_command(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Add result files of one config run with different seeds, or join runs of "
               "different incident directions");
  cmd->add_option("inputs", o->inputs, "Result files to merge")->required();
  cmd->add_option("-o,--output", o->output, "Merged result file")->required();
  cmd->callback([o] {
    const sim::MergeSummary m = app::merge(o->inputs, o->output);
    fmt::print("merged {} files into {}: {} incident directions, {} of them summed over seeds\n",
               o->inputs.size(), o->output, m.directions, m.summed_directions);
  });
}

}  // namespace fiberlab::cli
