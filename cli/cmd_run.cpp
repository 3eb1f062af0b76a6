// `fiberlab run CONFIG [-o OUT.h5] [--photons N] [--seed S] [--threads T]
//                [--checkpoint-every SECONDS] [--target-error R] [--quiet]`
// `fiberlab run --resume OUT.checkpoint.h5 [CONFIG] [--threads T] [--quiet]`
// Under mpirun/srun every rank runs this; rank 0 alone prints and writes.
// The run itself (setup, MPI agreement, checkpoints, output): app/run.h.
#include <fmt/core.h>

#include <chrono>
#include <memory>
#include <string>

#include "app/run.h"
#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/interrupt.h"
#include "sim/run/memory_budget.h"
#include "sim/run/process_group.h"

namespace fiberlab::cli {

namespace {

// Progress on stderr, shown only once a run has lasted a second.
sim::ProgressCallback progress_printer(bool quiet) {
  if (quiet) return {};
  const auto start = std::chrono::steady_clock::now();
  auto finished = std::make_shared<bool>(false);
  return [start, finished](std::uint64_t done, std::uint64_t total) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t < 1.0 || *finished) return;
    *finished = done == total;
    const double rate = done / t;
    const std::string eta = rate > 0 ? fmt::format("{:6.0f} s", (total - done) / rate) : "     ? s";
    fmt::print(stderr, "\r{:>14} / {} photons  {:9.4g} photons/s  {:7.0f} s elapsed  ETA {}",
               done, total, rate, t, eta);
    if (done == total) fmt::print(stderr, "\n");
  };
}

void print_report(const app::RunReport& r) {
  const sim::ResultFile& result = *r.result;
  print_summary(stdout, result);
  for (std::size_t k = 0; k < r.reached_error.size(); ++k) {
    const double reached = r.reached_error[k];
    fmt::print("target error {}: direction {} stopped after {} photons, largest relative lobe "
               "error {:.3g} ({})\n", r.target_error, k, result.photons[k], reached,
               reached < r.target_error ? "reached" : "NOT reached: photon limit");
  }
  const sim::RunStatistics& stats = r.stats;
  const double n = static_cast<double>(stats.photons), t = stats.seconds;
  fmt::print("{:.0f} photons in {:.2f} s on {} rank(s) x {} threads: {:.3f} M photons/s "
             "({:.3f} M/s per thread)\n", n, t, stats.ranks, stats.threads, n / t * 1e-6,
             n / t / (stats.threads * stats.ranks) * 1e-6);
  fmt::print("wrote {} in {:.2f} s\n", r.output, r.write_seconds);
}

void run(const app::RunRequest& o, bool quiet) {
  // The group (MPI) lives until this rank has printed.
  const sim::ProcessGroup group;
  const app::RunReport r = app::run(group, o, [quiet] { return progress_printer(quiet); });
  if (r.failed_elsewhere) {
    exit_code = 2;  // rank 0 reports
    return;
  }
  if (r.interrupted_by != 0) {
    if (r.root)
      fmt::print(stderr, "\nfiberlab: interrupted by {}: progress saved in {}; resume with: "
                 "fiberlab run --resume {}\n", signal_name(r.interrupted_by), r.checkpoint, r.checkpoint);
    exit_code = 128 + r.interrupted_by;
    return;
  }
  if (r.root && !quiet) print_report(r);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<fiberlab::app::RunRequest>();
  auto quiet = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("run", "Simulate a fiber config into an HDF5 result file");
  cmd->add_option("config", o->config, "YAML config (see configs/README.md)");
  CLI::Option* out =
      cmd->add_option("-o,--output", o->output, "Result file (overrides `output` in the config)");
  CLI::Option* photons = cmd->add_option(
      "--photons", o->photons, "Photons per incident direction, integer >= 1, e.g. 1e6 (overrides the config)");
  CLI::Option* seed = cmd->add_option("--seed", o->seed, "Random seed in [0, 2^64 - 1] (overrides the config)");
  CLI::Option* threads = cmd->add_option("--threads", o->threads,
                  fmt::format("OpenMP threads per process, 1 to {} (default: all cores)", sim::kMaxThreads));
  cmd->add_option("--checkpoint-every", o->checkpoint_every,
                  "Seconds between checkpoints OUT.checkpoint.h5 (default 300; one is also "
                  "written on SIGINT/SIGTERM/SIGHUP)");
  cmd->add_option("--resume", o->resume, "Finish the run saved in this checkpoint");
  cmd->add_option("--target-error", o->target_error,
                  "Stop each incident direction once every lobe energy's relative standard "
                  "error is below this (checked every 65536 photons; photons is the limit)");
  cmd->add_flag("--quiet", *quiet, "No progress and no summary table");
  cmd->callback([o, quiet, out, photons, seed, threads] {
    o->threads_given = threads->count() > 0;
    o->output_given = out->count() > 0;
    o->photons_given = photons->count() > 0;
    o->seed_given = seed->count() > 0;
    o->summary = !*quiet;
    run(*o, *quiet);
  });
}

}  // namespace fiberlab::cli
