// `fiberlab run CONFIG [-o OUT.h5] [--photons N] [--seed S] [--threads T] [--quiet]`
#include <fmt/core.h>

#include <chrono>
#include <memory>

#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "sim/result_file.h"
#include "sim/simulation.h"

namespace fiberlab::cli {

namespace {

struct RunOptions {
  std::string config, output;
  long long photons = -1, seed = -1;
  int threads = 0;
  bool quiet = false;
};

// Progress on stderr, shown only once a run has lasted a second.
sim::ProgressCallback progress_printer(bool quiet) {
  if (quiet) return {};
  const auto start = std::chrono::steady_clock::now();
  return [start](std::uint64_t done, std::uint64_t total) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t < 1.0) return;
    const double rate = done / t;
    const double eta = rate > 0 ? (total - done) / rate : 0.0;
    fmt::print(stderr, "\r{:>14} / {} photons  {:8.3f} M/s  ETA {:6.0f} s", done, total,
               rate * 1e-6, eta);
    if (done == total) fmt::print(stderr, "\n");
  };
}

void run(const RunOptions& o) {
  sim::Settings settings = sim::load_settings(o.config);
  if (o.photons == 0 || o.photons < -1)
    throw Error(fmt::format("--photons = {} is out of range (must be an integer >= 1)", o.photons));
  if (o.seed < -1) throw Error(fmt::format("--seed = {} is out of range (must be >= 0)", o.seed));
  if (o.threads < 0) throw Error(fmt::format("--threads = {} is out of range (must be >= 1)", o.threads));
  if (o.photons > 0) settings.photons = static_cast<std::uint64_t>(o.photons);
  if (o.seed >= 0) settings.seed = static_cast<std::uint64_t>(o.seed);
  if (!o.output.empty()) settings.output = o.output;
  // Check the output path before spending time on photons.
  { AtomicOutput probe(settings.output); }

  const sim::Simulation simulation(settings);
  sim::RunStatistics stats;
  const std::vector<sim::Tally> tallies = simulation.run(o.threads, progress_printer(o.quiet), &stats);
  const sim::ResultFile result = sim::make_result(simulation.settings(), simulation.grid(), tallies);
  sim::write_result(result, settings.output);
  if (!o.quiet) {
    print_summary(stdout, result);
    const double total = static_cast<double>(settings.photons) * result.configs();
    fmt::print("{:.0f} photons in {:.2f} s on {} threads: {:.3f} M photons/s ({:.3f} M/s per thread)\n",
               total, stats.seconds, stats.threads, total / stats.seconds * 1e-6,
               total / stats.seconds / stats.threads * 1e-6);
    fmt::print("wrote {}\n", settings.output);
  }
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Simulate a fiber config into an HDF5 result file");
  cmd->add_option("config", o->config, "YAML config (see configs/README.md)")->required();
  cmd->add_option("-o,--output", o->output, "Result file (overrides `output` in the config)");
  cmd->add_option("--photons", o->photons, "Photons per incident direction (overrides the config)");
  cmd->add_option("--seed", o->seed, "Random seed (overrides the config)");
  cmd->add_option("--threads", o->threads, "OpenMP threads (default: all cores)");
  cmd->add_flag("--quiet", o->quiet, "No progress and no summary table");
  cmd->callback([o] { run(*o); });
}

}  // namespace fiberlab::cli
