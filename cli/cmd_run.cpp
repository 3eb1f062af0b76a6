// `fiberlab run CONFIG [-o OUT.h5] [--photons N] [--seed S] [--threads T]
//                [--checkpoint-every SECONDS] [--target-error R] [--quiet]`
// `fiberlab run --resume OUT.checkpoint.h5 [CONFIG] [--threads T] [--quiet]`
// Under mpirun/srun every rank runs this; rank 0 alone prints and writes.
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "sim/store/checkpoint.h"
#include "sim/run/memory_budget.h"
#include "sim/run/process_group.h"
#include "sim/run/rank_agreement.h"
#include "sim/store/result_file.h"
#include "sim/store/result_stream.h"
#include "sim/run/simulation.h"

namespace fiberlab::cli {

namespace {

struct RunOptions {
  std::string config, output, resume;
  std::string photons, seed, threads;  // checked by sim::parse_integer_flag
  bool output_given = false, photons_given = false, seed_given = false, threads_given = false;
  double checkpoint_every = 300.0;
  double target_error = 0.0;
  bool quiet = false;
};

// --photons, --seed and -o override the config; each is checked like the
// config's own key (exact integers, no silent clamping, no empty path).
void apply_run_flags(const RunOptions& o, sim::Settings& settings) {
  constexpr std::uint64_t kU64Max = ~std::uint64_t{0};
  if (o.photons_given)
    settings.photons = sim::parse_integer_flag("--photons", o.photons, 1, kU64Max);
  if (o.seed_given) settings.seed = sim::parse_integer_flag("--seed", o.seed, 0, kU64Max);
  if (o.output_given) {
    if (o.output.empty()) throw Error("command line: -o is empty (must be a file name)");
    check_output_name(o.output);
    settings.output = o.output;
  }
  // photons x incident configurations must fit in uint64 (sim/run/settings.cpp
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

// Every rank's setup (config or checkpoint, flags, output path): a failure on
// any rank stops all, rank 0 saying why.
struct Job {
  sim::Settings settings;
  double target_error = 0.0;
  sim::RunProgress state;
  bool resumed = false;
};

Job set_up(const RunOptions& o, const sim::ProcessGroup& group) {
  Job job;
  if (!(o.checkpoint_every > 0) || !std::isfinite(o.checkpoint_every))
    throw Error(fmt::format("--checkpoint-every = {} is out of range (seconds, > 0)", o.checkpoint_every));
  if (!o.resume.empty()) {
    if (o.photons_given || o.seed_given || o.output_given || o.target_error != 0.0)
      throw Error("--resume: --photons, --seed, -o and --target-error are the checkpoint's and "
                  "cannot be changed (only --threads, --checkpoint-every and --quiet)");
    sim::Checkpoint c = sim::read_checkpoint(o.resume, group.is_root());
    if (!o.config.empty()) {
      sim::Settings given = sim::load_settings(o.config);
      given.output = c.settings.output;
      sim::check_same_config(c, given, o.resume);
    }
    job.settings = c.settings;
    job.target_error = c.target_error;
    job.state = std::move(c.state);
    job.resumed = true;
    return job;
  }
  if (o.config.empty()) throw Error("run: give a CONFIG file, or --resume CHECKPOINT");
  job.settings = sim::load_settings(o.config);
  if (!(o.target_error >= 0.0 && o.target_error < 1.0))
    throw Error(fmt::format("--target-error = {} is out of range (a relative error in (0, 1))",
                            o.target_error));
  apply_run_flags(o, job.settings);
  job.target_error = o.target_error;
  const std::string checkpoint = sim::checkpoint_path(job.settings.output);
  if (group.is_root() && std::filesystem::exists(checkpoint))
    throw Error(fmt::format("{} exists (an interrupted run of this output): resume it with "
                            "`fiberlab run --resume {}`, or delete it", checkpoint, checkpoint));
  return job;
}

// The finished run: OUT.h5 written atomically, the checkpoint removed.
void write_output(const sim::Simulation& simulation, const Job& job, int threads) {
  const sim::Settings& s = simulation.settings();
  sim::ResultWriter w(s.output, sim::result_header(s, simulation.grid()));
  w.set_compression_threads(threads);
  for (std::size_t k = 0; k < job.state.tallies.size(); ++k) w.write(k, job.state.tallies[k]);
  if (job.target_error > 0) w.file().set_attr("/", "target_error", job.target_error);
  w.commit();
  std::filesystem::remove(sim::checkpoint_path(s.output));
}

void report(const RunOptions& o, const Job& job, const sim::Simulation& simulation,
            const sim::RunStatistics& stats, double write_seconds) {
  if (o.quiet) return;
  const sim::ResultFile result = sim::make_result(simulation.settings(), simulation.grid(), job.state.tallies);
  print_summary(stdout, result);
  if (job.target_error > 0) {
    for (std::size_t k = 0; k < job.state.tallies.size(); ++k) {
      const double reached = sim::Simulation::largest_relative_error(job.state.tallies[k].exact());
      fmt::print("target error {}: direction {} stopped after {} photons, largest relative lobe "
                 "error {:.3g} ({})\n", job.target_error, k, result.photons[k], reached,
                 reached < job.target_error ? "reached" : "NOT reached: photon limit");
    }
  }
  const double n = static_cast<double>(stats.photons), t = stats.seconds;
  fmt::print("{:.0f} photons in {:.2f} s on {} rank(s) x {} threads: {:.3f} M photons/s "
             "({:.3f} M/s per thread)\n", n, t, stats.ranks, stats.threads, n / t * 1e-6,
             n / t / (stats.threads * stats.ranks) * 1e-6);
  fmt::print("wrote {} in {:.2f} s\n", job.settings.output, write_seconds);
}

// Runs `step` on every rank; when it fails anywhere, every rank stops, rank 0
// with the (first failing rank's) message, the others quietly.
template <typename Step>
void on_all_ranks(const sim::ProcessGroup& group, Step&& step) {
  std::optional<std::string> error;
  try {
    step();
  } catch (const Error& e) {
    error = e.what();
  } catch (const std::bad_alloc&) {
    error = "out of memory";
  } catch (const std::exception& e) {
    error = std::string("internal error: ") + e.what();
  }
  if (const auto message = group.agree_on_error(error)) {
    if (!group.is_root()) throw sim::FailedElsewhere{};
    throw Error(*message);
  }
}

void run(const RunOptions& o) {
  sim::ProcessGroup group;
  install_interrupt_handlers();
  try {
    Job job;
    int threads = 1;
    on_all_ranks(group, [&] {
      threads = thread_count(o.threads_given, o.threads);
      job = set_up(o, group);
    });
    // Every rank the same config and flags, before any tally is allocated.
    on_all_ranks(group, [&] {
      const std::string text = sim::run_agreement_text(job.settings, job.target_error,
                                                       job.resumed ? &job.state : nullptr);
      if (const auto disagreement = sim::ranks_disagree(group, text)) throw Error(*disagreement);
    });
    std::optional<sim::Simulation> simulation;
    on_all_ranks(group, [&] {
      // The output paths (OUT and OUT.checkpoint.h5) and the memory, before
      // any tally is allocated.
      std::vector<std::string> inputs;
      for (const std::string& in : {o.config, o.resume})
        if (!in.empty()) inputs.push_back(in);
      if (group.is_root()) {
        check_output_target(job.settings.output, inputs);
        check_output_name(sim::checkpoint_path(job.settings.output));
        // Temporaries of an earlier run killed while writing (SIGKILL): this
        // run may never write a checkpoint, whose writer would remove them.
        remove_stale_temporaries(sim::checkpoint_path(job.settings.output));
      }
      sim::check_memory_budget(job.settings, threads);
      simulation.emplace(job.settings);
      if (!job.resumed) job.state = simulation->start();
      if (!group.is_root()) job.state.tallies.clear();  // sums are kept on rank 0 only
    });
    const std::string checkpoint = sim::checkpoint_path(job.settings.output);
    sim::RunControl control;
    control.threads = threads;
    control.progress = progress_printer(o.quiet || !group.is_root());
    control.checkpoint_every = o.checkpoint_every;
    control.checkpoint = [&](const sim::RunProgress& state) {
      sim::write_checkpoint(checkpoint, *simulation, state, job.target_error);
    };
    control.target_error = job.target_error;
    control.group = &group;
    sim::RunStatistics stats;
    if (simulation->run(job.state, control, &stats) == sim::RunOutcome::Interrupted) {
      const int sig = interrupt_signal();
      if (group.is_root())
        fmt::print(stderr, "\nfiberlab: interrupted by {}: progress saved in {}; resume with: "
                   "fiberlab run --resume {}\n", signal_name(sig), checkpoint, checkpoint);
      exit_code = 128 + sig;
      return;
    }
    const auto write_start = std::chrono::steady_clock::now();
    on_all_ranks(group, [&] {
      if (group.is_root()) write_output(*simulation, job, threads);
    });
    const double write_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
    if (group.is_root()) report(o, job, *simulation, stats, write_seconds);
  } catch (const sim::FailedElsewhere&) {
    exit_code = 2;  // rank 0 reports
  }
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
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
