// `fiberlab atlas CONFIG -o OUT.h5 [--report DIR] [--threads T] [--photons N] [--quiet]`
// How wrong is each model for each physical fiber of a sweep, per lobe,
// before and after fitting its free parameters? The sweep and the
// judgement: compare/atlas.h; the config: compare/atlas_config.h; the file:
// compare/atlas_file.h; the report: compare/atlas_report.h.
// Exit status 0 when written, 2 on bad input (nothing written), 128 + signal
// when interrupted (nothing written).
#include <fmt/core.h>

#include <omp.h>

#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "compare/atlas.h"
#include "compare/atlas_config.h"
#include "compare/atlas_file.h"
#include "compare/atlas_report.h"
#include "sim/memory_budget.h"
#include "sim/settings.h"

namespace fiberlab::cli {

namespace {

struct AtlasOptions {
  std::string config, output, report, threads, photons;
  bool quiet = false;
};

std::string default_report_dir(const std::string& output) {
  std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "_report")).string();
}

// The report folder is made at the end; here only whether it can be.
void check_report_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw Error(fmt::format("--report {}: exists and is not a folder", dir));
    return;
  }
  const fs::path parent = fs::path(dir).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw Error(fmt::format("--report {}: its parent folder {} does not exist", dir, parent.string()));
}

void atlas_command(const AtlasOptions& o, const std::string& command) {
  compare::AtlasConfig config = compare::load_atlas_config(o.config);
  if (!o.photons.empty()) {
    const std::uint64_t n = sim::parse_integer_flag("--photons", o.photons, 1, 1000000000000ULL);
    for (auto& f : config.fibers) f.settings.photons = n;
  }
  compare::AtlasControl control;
  if (!o.threads.empty()) {
    control.threads = static_cast<int>(sim::parse_integer_flag("--threads", o.threads, 1, sim::kMaxThreads));
    omp_set_num_threads(control.threads);
  }
  if (o.output.empty()) throw Error("atlas: give the output file with -o OUT.h5");
  const std::string report = o.report.empty() ? default_report_dir(o.output) : o.report;
  check_output_target(o.output, {o.config});
  check_report_dir(report);
  if (!o.quiet) control.progress = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };

  install_interrupt_handlers();
  std::vector<compare::AtlasFiberResult> results;
  try {
    for (std::size_t i = 0; i < config.fibers.size(); ++i) results.push_back(compare::run_atlas_fiber(config, i, control));
  } catch (const compare::AtlasInterrupted& s) {
    fmt::print(stderr, "\nfiberlab: atlas interrupted by signal {}; nothing written\n", s.signal);
    exit_code = 128 + s.signal;
    return;
  }
  compare::write_atlas_file(o.output, config, results);
  fmt::print("wrote {}\n", o.output);
  fmt::print("\n{}", compare::atlas_headline_markdown(config, results));
  fmt::print("{}", compare::write_atlas_report(report, o.output, config, results, command));
}

}  // namespace

void add_atlas_command(CLI::App& app) {
  auto o = std::make_shared<AtlasOptions>();
  CLI::App* cmd = app.add_subcommand(
      "atlas",
      "Simulate a sweep of physical fibers and judge every registered model on each, before and after "
      "fitting its free parameters (configs/atlas_small.yaml; docs/ATLAS.md)");
  cmd->add_option("config", o->config, "Atlas config (.yaml)")->required();
  cmd->add_option("-o,--output", o->output, "Output file (.h5, format fiber-atlas)")->required();
  cmd->add_option("--report", o->report, "Report folder (default: OUT without .h5, plus _report)");
  cmd->add_option("--threads", o->threads, "OpenMP threads (default: all cores)");
  cmd->add_option("--photons", o->photons, "Photons per fiber and incident direction (overrides the config)");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o] {
    std::string command = "fiberlab atlas " + o->config + " -o " + o->output;
    if (!o->report.empty()) command += " --report " + o->report;
    if (!o->photons.empty()) command += " --photons " + o->photons;
    atlas_command(*o, command);
  });
}

}  // namespace fiberlab::cli
