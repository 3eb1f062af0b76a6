#include "app/atlas.h"

#include <fmt/core.h>

#include <omp.h>

#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>

#include "app/on_all_ranks.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "compare/atlas_file.h"
#include "compare/atlas_report.h"
#include "sim/run/memory_budget.h"
#include "sim/run/rank_agreement.h"
#include "sim/run/settings.h"
#include "sim/store/checkpoint.h"
#include "sim/store/exact_tally.h"

namespace fiberlab::app {

namespace {

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

// What one invocation runs: a new atlas, or the rest of a checkpoint's.
struct AtlasJob {
  compare::AtlasRunSetup setup;
  compare::AtlasConfig config;
  std::vector<compare::AtlasFiberResult> fibers;  // finished (from the checkpoint when resuming)
  std::string output, report, checkpoint;
  std::vector<std::string> inputs;                // files read: never overwritten
  bool resumed = false;
};

AtlasJob new_job(const AtlasRequest& o, const sim::ProcessGroup& group) {
  if (o.config.empty()) throw Error("atlas: give a CONFIG file, or --resume CHECKPOINT");
  if (o.output.empty()) throw Error("atlas: give the output file with -o OUT.h5");
  AtlasJob job;
  job.config = compare::load_atlas_config(o.config);
  if (!o.photons.empty()) compare::override_photons(job.config, o.photons);
  job.output = o.output;
  job.report = o.report.empty() ? default_report_dir(o.output) : o.report;
  job.checkpoint = sim::checkpoint_path(o.output);
  job.inputs = {o.config};
  if (group.is_root() && std::filesystem::exists(job.checkpoint))
    throw Error(fmt::format("{} exists (an interrupted atlas of this output): resume it with "
                            "`fiberlab atlas --resume {}`, or delete it", job.checkpoint, job.checkpoint));
  job.setup = {o.config, job.config.yaml, o.photons, std::filesystem::path(o.output).filename().string(),
               o.report.empty() ? "" : std::filesystem::absolute(o.report).string(), o.command};
  return job;
}

// The checkpoint holds the config, the flags and OUT (in its own folder):
// only --threads and --quiet may be given; CONFIG, if given, must be the same.
AtlasJob resumed_job(const AtlasRequest& o) {
  if (!o.output.empty() || !o.report.empty() || !o.photons.empty())
    throw Error("--resume: -o, --report and --photons are the checkpoint's and cannot be changed "
                "(only --threads and --quiet; CONFIG, if given, must be the checkpoint's)");
  compare::AtlasCheckpoint c = compare::read_atlas_checkpoint(o.resume);
  if (!o.config.empty()) compare::check_same_atlas_config(c, compare::load_atlas_config(o.config), o.resume);
  AtlasJob job;
  job.setup = std::move(c.setup);
  job.config = std::move(c.config);
  job.fibers = std::move(c.fibers);
  job.output = (std::filesystem::path(o.resume).parent_path() / job.setup.output_name).string();
  job.report = job.setup.report_dir.empty() ? default_report_dir(job.output) : job.setup.report_dir;
  job.checkpoint = o.resume;
  job.inputs = {o.resume};
  if (!o.config.empty()) job.inputs.push_back(o.config);
  job.resumed = true;
  return job;
}

// Rank r's fiber bytes into rank 0: each rank's segment of a zeroed buffer,
// summed exactly (the other ranks add zeros). Returns, on rank 0, every
// rank's bytes (empty for a rank without a fiber this round).
std::vector<std::vector<std::uint8_t>> gather_to_root(const sim::ProcessGroup& group,
                                                      const std::vector<std::uint8_t>& mine) {
  using Word = sim::ExactTally::Word;
  const std::size_t ranks = static_cast<std::size_t>(group.size()), per_word = sizeof(Word);
  std::vector<std::int64_t> sizes(ranks, 0);
  sizes[group.rank()] = static_cast<std::int64_t>(mine.size());
  group.max(sizes);
  std::vector<std::size_t> first(ranks + 1, 0);
  for (std::size_t r = 0; r < ranks; ++r) first[r + 1] = first[r] + (static_cast<std::size_t>(sizes[r]) + per_word - 1) / per_word;
  std::vector<Word> words(first[ranks], 0);
  std::memcpy(words.data() + first[group.rank()], mine.data(), mine.size());
  group.sum_to_root(words);
  std::vector<std::vector<std::uint8_t>> out(ranks);
  if (!group.is_root()) return out;
  for (std::size_t r = 0; r < ranks; ++r) {
    out[r].resize(static_cast<std::size_t>(sizes[r]));
    std::memcpy(out[r].data(), words.data() + first[r], out[r].size());
  }
  return out;
}

// Under an MPI launcher: fiber i of each round of N runs on rank i mod N;
// rank 0 gathers the round and saves the checkpoint. Returns the signal that
// stopped the atlas (0 when every fiber is done; the finished rounds kept in
// the checkpoint).
int run_fibers_on_ranks(const sim::ProcessGroup& group, AtlasJob& job, const compare::AtlasControl& control) {
  const std::size_t n = job.config.fibers.size(), ranks = static_cast<std::size_t>(group.size());
  const std::string scratch =
      (std::filesystem::temp_directory_path() / fmt::format("fiberlab_atlas_{}_{}.h5", ::getpid(), group.rank()))
          .string();
  while (job.fibers.size() < n) {
    const std::size_t mine = job.fibers.size() + static_cast<std::size_t>(group.rank());
    std::vector<std::uint8_t> bytes;
    std::vector<std::int64_t> stopped{0};
    on_all_ranks(group, [&] {
      try {
        if (mine < n) bytes = compare::pack_atlas_fiber(job.config, mine, compare::run_atlas_fiber(job.config, mine, control),
                                                        scratch);
      } catch (const compare::AtlasInterrupted& s) {
        stopped[0] = s.signal;
      }
    });
    group.max(stopped);
    if (stopped[0] != 0) return static_cast<int>(stopped[0]);
    const auto received = gather_to_root(group, bytes);
    on_all_ranks(group, [&] {
      const std::size_t round = job.fibers.size();
      for (std::size_t r = 0; r < ranks && round + r < n; ++r) {
        if (group.is_root())
          job.fibers.push_back(compare::unpack_atlas_fiber(job.config, round + r, received[r], scratch));
        else
          job.fibers.emplace_back();  // rank 0 keeps the results; the others only count them
      }
      if (group.is_root()) compare::write_atlas_checkpoint(job.checkpoint, job.setup, job.config, job.fibers);
    });
  }
  return 0;
}

// One process: the fibers in order, the checkpoint after each. Returns the
// signal that stopped it (0 when every fiber is done).
int run_fibers_here(AtlasJob& job, const compare::AtlasControl& control) {
  try {
    while (job.fibers.size() < job.config.fibers.size()) {
      job.fibers.push_back(compare::run_atlas_fiber(job.config, job.fibers.size(), control));
      compare::write_atlas_checkpoint(job.checkpoint, job.setup, job.config, job.fibers);
    }
  } catch (const compare::AtlasInterrupted& s) {
    return s.signal;
  }
  return 0;
}

// Every rank reads CONFIG (or the checkpoint) and the flags; rank 0 checks
// the output paths.
AtlasJob set_up(const AtlasRequest& o, const sim::ProcessGroup& group, compare::AtlasControl& control) {
  AtlasJob job = o.resume.empty() ? new_job(o, group) : resumed_job(o);
  if (!o.threads.empty()) {
    control.threads = static_cast<int>(sim::parse_integer_flag("--threads", o.threads, 1, sim::kMaxThreads));
    omp_set_num_threads(control.threads);
  }
  if (group.is_root()) {
    check_output_target(job.output, job.inputs);
    // The checkpoint is rewritten in place when resuming; never over CONFIG.
    check_output_target(job.checkpoint, o.config.empty() ? std::vector<std::string>{} : std::vector{o.config});
    remove_stale_temporaries(job.checkpoint);  // of an atlas killed while writing it
    check_report_dir(job.report);
  }
  return job;
}

}  // namespace

AtlasRun run_atlas(const sim::ProcessGroup& group, const AtlasRequest& o,
                   const std::function<void(const std::string&)>& progress) {
  AtlasRun run;
  run.root = group.is_root();
  run.ranks = group.size();
  try {
    AtlasJob job;
    compare::AtlasControl control;
    on_all_ranks(group, [&] { job = set_up(o, group, control); });
    // Under an MPI launcher every rank must run the same config from the same fiber.
    if (group.size() > 1)
      on_all_ranks(group, [&] {
        const std::string text = fmt::format("{}fibers done: {}\n", compare::atlas_config_identity(job.config),
                                             job.fibers.size());
        if (const auto disagreement = sim::ranks_disagree(group, text)) throw Error(*disagreement);
      });
    if (progress && group.is_root()) control.progress = progress;

    install_interrupt_handlers();
    const std::size_t n = job.config.fibers.size();
    if (job.resumed && control.progress)
      control.progress(fmt::format("resuming: {} of {} fibers from {}", job.fibers.size(), n, job.checkpoint));
    run.interrupted_by = group.size() > 1 ? run_fibers_on_ranks(group, job, control) : run_fibers_here(job, control);
    run.resumed = job.resumed;
    run.fibers_total = n;
    run.output = job.output;
    run.report = job.report;
    run.checkpoint = job.checkpoint;
    if (run.interrupted_by == 0 && group.is_root()) {
      compare::write_atlas_file(job.output, job.config, job.fibers);
      run.headline = compare::atlas_headline_markdown(job.config, job.fibers);
    }
    run.setup = std::move(job.setup);
    run.config = std::move(job.config);
    run.fibers = std::move(job.fibers);
  } catch (const sim::FailedElsewhere&) {
    run.failed_elsewhere = true;  // rank 0 reports
  }
  return run;
}

AtlasReportOutcome write_atlas_report(const AtlasRun& run) {
  AtlasReportOutcome out;
  out.line = compare::write_atlas_report(run.report, run.output, run.config, run.fibers, run.setup.command);
  if (interrupt_requested()) {  // during the report (its plots run in a child process the signal reached too)
    out.interrupted_by = interrupt_signal();
    return out;
  }
  std::error_code ec;
  if (!std::filesystem::remove(run.checkpoint, ec) && ec) out.checkpoint_left = ec.message();
  return out;
}

}  // namespace fiberlab::app
