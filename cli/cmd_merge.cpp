// `fiberlab merge A.h5 B.h5 ... -o C.h5`: adds runs of one config made with
// different seeds (how users scale out over machines).
#include <fmt/core.h>

#include <memory>

#include "cli/commands.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "sim/result_file.h"

namespace fiberlab::cli {

namespace {

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string output;
};

void merge(const MergeOptions& o) {
  if (o.inputs.size() < 2) throw Error("merge: give at least two result files");
  check_output_target(o.output, o.inputs);  // before reading: not onto an input, a FIFO, ...
  std::vector<sim::ResultFile> parts;
  for (const std::string& p : o.inputs) parts.push_back(sim::read_result(p));
  const sim::ResultFile merged = sim::merge_results(parts, o.inputs);
  sim::write_result(merged, o.output, o.inputs);
  fmt::print("merged {} files ({} photons per incident direction) into {}\n", parts.size(),
             merged.photons.front(), o.output);
}

}  // namespace

void add_merge_command(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* cmd = app.add_subcommand("merge", "Add result files of one config run with different seeds");
  cmd->add_option("inputs", o->inputs, "Result files to add")->required();
  cmd->add_option("-o,--output", o->output, "Merged result file")->required();
  cmd->callback([o] { merge(*o); });
}

}  // namespace fiberlab::cli
