// `fiberlab atlas CONFIG -o OUT.h5 [--report DIR] [--threads T] [--photons N] [--quiet]`
// `fiberlab atlas --resume OUT.checkpoint.h5 [CONFIG] [--threads T] [--quiet]`
// How wrong is each model for each physical fiber of a sweep, per lobe,
// before and after fitting its free parameters? The workflow (checkpoint,
// resume, the fibers spread over MPI ranks): app/atlas.h; here the flags
// and what is printed.
// Exit status 0 when written, 2 on bad input (nothing written), 128 + signal
// when interrupted (the finished fibers kept in the checkpoint, no OUT).
#include <fmt/core.h>

#include <memory>

#include "app/atlas.h"
#include "cli/commands.h"
#include "common/interrupt.h"
#include "sim/run/process_group.h"

namespace fiberlab::cli {

namespace {

struct AtlasOptions {
  app::AtlasRequest request;
  bool quiet = false;
};

void print_interrupted(const app::AtlasRun& r) {
  const char* signal = signal_name(r.interrupted_by);
  if (r.fibers.empty())
    fmt::print(stderr, "fiberlab: atlas interrupted by {} before its first {} finished; nothing written\n", signal,
               r.ranks > 1 ? "fibers were" : "fiber was");
  else
    fmt::print(stderr, "fiberlab: atlas interrupted by {}: {} of {} fibers saved in {}; resume with: "
               "fiberlab atlas --resume {}\n", signal, r.fibers.size(), r.fibers_total, r.checkpoint, r.checkpoint);
}

void atlas_command(const AtlasOptions& o) {
  // The group (MPI) lives until this rank has printed.
  const sim::ProcessGroup group;
  const auto progress = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };
  const app::AtlasRun r =
      app::run_atlas(group, o.request, o.quiet ? std::function<void(const std::string&)>{} : progress);
  if (r.failed_elsewhere) {
    exit_code = 2;  // rank 0 reports
    return;
  }
  if (r.interrupted_by != 0) {
    if (r.root) print_interrupted(r);
    exit_code = 128 + r.interrupted_by;
    return;
  }
  if (!r.written()) return;
  fmt::print("wrote {}\n", r.output);
  fmt::print("\n{}", r.headline);
  const app::AtlasReportOutcome report = app::write_atlas_report(r);
  fmt::print("{}", report.line);
  if (report.interrupted_by != 0) {
    fmt::print(stderr, "fiberlab: atlas interrupted by {} while making its report: {} is written, the report may "
               "be incomplete; both are written again by: fiberlab atlas --resume {}\n",
               signal_name(report.interrupted_by), r.output, r.checkpoint);
    exit_code = 128 + report.interrupted_by;
    return;
  }
  if (!report.checkpoint_left.empty())
    fmt::print(stderr, "fiberlab: warning: could not remove the checkpoint {}: {}\n", r.checkpoint,
               report.checkpoint_left);
}

}  // namespace

void add_atlas_command(CLI::App& app) {
  auto o = std::make_shared<AtlasOptions>();
  app::AtlasRequest& q = o->request;
  CLI::App* cmd = app.add_subcommand(
      "atlas",
      "Simulate a sweep of physical fibers and judge every registered model on each, before and after "
      "fitting its free parameters (configs/atlas_small.yaml; docs/ATLAS.md)");
  cmd->add_option("config", q.config, "Atlas config (.yaml); with --resume, checked against the checkpoint's");
  cmd->add_option("-o,--output", q.output, "Output file (.h5, format fiber-atlas)");
  cmd->add_option("--report", q.report, "Report folder (default: OUT without .h5, plus _report)");
  cmd->add_option("--threads", q.threads, "OpenMP threads (default: all cores)");
  cmd->add_option("--photons", q.photons, "Photons per fiber and incident direction (overrides the config)");
  cmd->add_option("--resume", q.resume,
                  "Finish the atlas saved in this checkpoint (OUT.checkpoint.h5, written after each fiber)");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o] {
    app::AtlasRequest& q = o->request;
    q.command = "fiberlab atlas " + q.config + " -o " + q.output;
    if (!q.report.empty()) q.command += " --report " + q.report;
    if (!q.photons.empty()) q.command += " --photons " + q.photons;
    atlas_command(*o);
  });
}

}  // namespace fiberlab::cli
