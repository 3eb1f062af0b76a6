#include "app/run.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <new>
#include <optional>

#include "app/on_all_ranks.h"
#include "app/threads.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "sim/run/memory_budget.h"
#include "sim/run/process_group.h"
#include "sim/run/rank_agreement.h"
#include "sim/store/checkpoint.h"
#include "sim/store/result_stream.h"

namespace fiberlab::app {

namespace {

// --photons, --seed and -o override the config; each is checked like the
// config's own key (exact integers, no silent clamping, no empty path).
void apply_run_flags(const RunRequest& o, sim::Settings& settings) {
  constexpr std::uint64_t kU64Max = ~std::uint64_t{0};
  if (o.photons_given)
    settings.photons = sim::parse_integer_flag("--photons", o.photons, 1, kU64Max);
  if (o.seed_given) settings.seed = sim::parse_integer_flag("--seed", o.seed, 0, kU64Max);
  if (o.output_given) {
    if (o.output.empty()) throw Error("command line: -o is empty (must be a file name)");
    check_output_name(o.output);
    settings.output = o.output;
  }
  check_total_photons(settings, "command line: --photons");
}

// --threads: 1 to sim::kMaxThreads; absent means every core.
int thread_count(bool given, const std::string& text) {
  if (!given) return run_threads(0);
  return static_cast<int>(sim::parse_integer_flag("--threads", text, 1, sim::kMaxThreads));
}

// Every rank's setup (config or checkpoint, flags, output path): a failure on
// any rank stops all, rank 0 saying why.
struct Job {
  sim::Settings settings;
  double target_error = 0.0;
  sim::RunProgress state;
  bool resumed = false;
};

Job set_up(const RunRequest& o, const sim::ProcessGroup& group) {
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


}  // namespace

RunReport run(const sim::ProcessGroup& group, const RunRequest& o,
              const std::function<sim::ProgressCallback()>& progress) {
  install_interrupt_handlers();
  RunReport report;
  report.root = group.is_root();
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
    report.checkpoint = checkpoint;
    report.output = job.settings.output;
    report.target_error = job.target_error;
    sim::RunControl control;
    control.threads = threads;
    if (progress && group.is_root()) control.progress = progress();
    control.checkpoint_every = o.checkpoint_every;
    control.checkpoint = [&](const sim::RunProgress& state) {
      sim::write_checkpoint(checkpoint, *simulation, state, job.target_error);
    };
    control.target_error = job.target_error;
    control.group = &group;
    if (simulation->run(job.state, control, &report.stats) == sim::RunOutcome::Interrupted) {
      report.interrupted_by = interrupt_signal();
      return report;
    }
    const auto write_start = std::chrono::steady_clock::now();
    on_all_ranks(group, [&] {
      if (group.is_root()) write_output(*simulation, job, threads);
    });
    report.write_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
    if (group.is_root() && o.summary) {
      report.result = sim::make_result(simulation->settings(), simulation->grid(), job.state.tallies);
      if (job.target_error > 0)
        for (const sim::Tally& t : job.state.tallies)
          report.reached_error.push_back(sim::Simulation::largest_relative_error(t.exact()));
    }
  } catch (const sim::FailedElsewhere&) {
    report.failed_elsewhere = true;  // rank 0 reports
  }
  return report;
}

void check_total_photons(const sim::Settings& settings, const std::string& what) {
  constexpr std::uint64_t kU64Max = ~std::uint64_t{0};
  const std::uint64_t k = settings.incidences().size();
  if (settings.photons > kU64Max / k)
    throw Error(fmt::format("{} = {} x {} incident configurations exceeds 2^64 - 1 photons in total", what,
                            settings.photons, k));
}

std::optional<sim::ResultFile> simulate(const sim::Settings& settings, int threads,
                                        const sim::ProgressCallback& progress) {
  sim::check_memory_budget(settings, threads);
  const sim::Simulation simulation(settings);
  sim::RunProgress state = simulation.start();
  sim::RunControl control;
  control.threads = threads;
  control.progress = progress;
  if (simulation.run(state, control) == sim::RunOutcome::Interrupted) return std::nullopt;
  return sim::make_result(simulation.settings(), simulation.grid(), state.tallies);
}

}  // namespace fiberlab::app
