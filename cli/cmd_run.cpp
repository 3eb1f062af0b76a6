// `fiberlab run CONFIG [-o OUT.h5] [--photons N] [--seed S] [--threads T] [--quiet]`
#include <fmt/core.h>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "sim/memory_budget.h"
#include "sim/result_file.h"
#include "sim/simulation.h"

namespace fiberlab::cli {

namespace {

struct RunOptions {
  std::string config, output;
  std::string photons, seed, threads;  // checked by sim::parse_integer_flag
  bool output_given = false, photons_given = false, seed_given = false, threads_given = false;
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

// --photons, --seed and -o override the config; each is checked like the
// config's own key (exact integers, no silent clamping, no empty path).
void apply_run_flags(const RunOptions& o, sim::Settings& settings) {
  constexpr std::uint64_t kU64Max = ~std::uint64_t{0};
  if (o.photons_given)
    settings.photons = sim::parse_integer_flag("--photons", o.photons, 1, kU64Max);
  if (o.seed_given) settings.seed = sim::parse_integer_flag("--seed", o.seed, 0, kU64Max);
  if (o.output_given) {
    if (o.output.empty()) throw Error("command line: -o is empty (must be a file name)");
    settings.output = o.output;
  }
  // photons x incident configurations must fit in uint64 (sim/settings.cpp
  // checks the config; a flag can raise photons past it).
  const std::uint64_t k = settings.incidences().size();
  if (settings.photons > kU64Max / k)
    throw Error(fmt::format("command line: --photons = {} x {} incident configurations exceeds "
                            "2^64 - 1 photons in total", settings.photons, k));
}

// --threads: 1 to sim::kMaxThreads; absent means every core.
int thread_count(bool given, const std::string& text) {
  if (!given) return std::min(omp_get_max_threads(), sim::kMaxThreads);
  return static_cast<int>(sim::parse_integer_flag("--threads", text, 1, sim::kMaxThreads));
}

void run(const RunOptions& o) {
  sim::Settings settings = sim::load_settings(o.config);
  apply_run_flags(o, settings);
  const int threads = thread_count(o.threads_given, o.threads);
  // Check the output path and the memory before spending time on photons.
  check_output_target(settings.output, {o.config});
  sim::check_memory_budget(settings, threads);

  const sim::Simulation simulation(settings);
  sim::RunStatistics stats;
  const std::vector<sim::Tally> tallies = simulation.run(threads, progress_printer(o.quiet), &stats);
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
  CLI::Option* out =
      cmd->add_option("-o,--output", o->output, "Result file (overrides `output` in the config)");
  CLI::Option* photons = cmd->add_option(
      "--photons", o->photons, "Photons per incident direction, integer >= 1, e.g. 1e6 (overrides the config)");
  CLI::Option* seed = cmd->add_option("--seed", o->seed, "Random seed in [0, 2^64 - 1] (overrides the config)");
  CLI::Option* threads = cmd->add_option("--threads", o->threads,
                  fmt::format("OpenMP threads, 1 to {} (default: all cores)", sim::kMaxThreads));
  cmd->add_flag("--quiet", o->quiet, "No progress and no summary table");
  cmd->callback([o, out, photons, seed, threads] {
    o->threads_given = threads->count() > 0;
    o->output_given = out->count() > 0;
    o->photons_given = photons->count() > 0;
    o->seed_given = seed->count() > 0;
    run(*o);
  });
}

}  // namespace fiberlab::cli
