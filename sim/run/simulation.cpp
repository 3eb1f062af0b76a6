#include "sim/run/simulation.h"

#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <utility>
#include <optional>
#include <thread>

#include "common/error.h"
#include "common/interrupt.h"
#include "common/units.h"
#include "sim/life/exit_scoring.h"
#include "sim/store/result_file.h"
#include "sim/life/source.h"

namespace fiberlab::sim {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Calls `progress` about twice a second from its own thread while alive.
class ProgressTicker {
 public:
  ProgressTicker(ProgressCallback progress, const std::atomic<std::uint64_t>& done,
                 std::uint64_t total)
      : progress_(std::move(progress)), done_(done), total_(total) {
    if (progress_) thread_ = std::thread([this] { loop(); });
  }
  ~ProgressTicker() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void loop() {
    auto last = Clock::now();
    while (!stop_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (seconds_since(last) < 0.5) continue;
      last = Clock::now();
      progress_(std::min(done_.load(), total_), total_);
    }
  }
  ProgressCallback progress_;
  const std::atomic<std::uint64_t>& done_;
  std::uint64_t total_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace

// One call of Simulation::run(state, control): the rounds of every direction.
class Simulation::Runner {
 public:
  Runner(const Simulation& sim, RunProgress& state, const RunControl& control)
      : sim_(sim), state_(state), control_(control),
        group_(control.group ? *control.group : ProcessGroup::single()),
        threads_(control.threads > 0 ? control.threads : omp_get_max_threads()),
        cap_(sim.settings_.photons) {}

  RunOutcome run(RunStatistics* stats);

 private:
  std::uint64_t trace_round(std::size_t k, std::uint64_t first, std::uint64_t end);
  void flush(std::size_t k);
  bool target_reached(std::size_t k);
  void check_errors();
  std::uint64_t photons_done() const;

  const Simulation& sim_;
  RunProgress& state_;
  const RunControl& control_;
  const ProcessGroup& group_;
  int threads_;
  std::uint64_t cap_;  // photons per direction
  // This rank's sums not yet flushed, one per thread, each allocated by its
  // own thread: small arrays allocated together by one thread share cache
  // lines, and threads scoring into them would slow each other down.
  std::vector<std::unique_ptr<Tally>> thread_tallies_;
  TracerCounters counters_;
  std::atomic<std::uint64_t> progress_done_{0};
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

std::uint64_t Simulation::Runner::photons_done() const {
  std::uint64_t n = 0;
  for (std::size_t k = 0; k < state_.next_photon.size(); ++k)
    n += state_.done[k] ? cap_ : state_.next_photon[k];
  return n;
}

// Traces this rank's chunks of photons [first, end) of direction k: rank r
// takes a contiguous share of the round's chunks, and its threads take runs
// of consecutive chunks from it in order (guided: long runs first, single
// chunks at the end, so threads finish together). Each thread makes one call
// of the tracer for the round, which takes the runs as its pool has room
// (sim/life/photon_feed.h), so the pool drains once per thread and round (the
// drain, where a few light-guided photons hold a vector for up to
// max_segments steps, would be most of a chunk's vector iterations if each
// chunk were a call). Which thread or rank traces a photon changes no bit of
// the sums. A lone process stops early on a signal, after a prefix of the
// round's chunks (every run taken is traced in full); returns the end of
// what was traced.
std::uint64_t Simulation::Runner::trace_round(std::size_t k, std::uint64_t first, std::uint64_t end) {
  const std::uint64_t chunks = (end - first) / kChunk + ((end - first) % kChunk != 0);
  const std::uint64_t rank = group_.rank(), size = group_.size();
  const std::uint64_t c0 = chunks * rank / size, mine = chunks * (rank + 1) / size - c0;
  const bool may_stop_early = size == 1;
  const std::uint64_t threads = static_cast<std::uint64_t>(threads_);
  std::atomic<std::uint64_t> next{0};
  std::atomic<bool> failed{false};
  // The next run of chunks [i, i + n) of this rank's share (n = 0: none left).
  auto take_run = [&](std::uint64_t& n) {
    std::uint64_t i = next.load();
    do {
      if (i >= mine) {
        n = 0;
        return i;
      }
      n = std::clamp<std::uint64_t>((mine - i) / (2 * threads), 1, kMaxRunChunks);
    } while (!next.compare_exchange_weak(i, i + n));
    return i;
  };
#pragma omp parallel num_threads(threads_)
  {
    TracerCounters counters;
    try {
      std::unique_ptr<Tally>& mine_tally = thread_tallies_[omp_get_thread_num()];
      const TallyShape s = sim_.tally_shape();
      if (!mine_tally) mine_tally = std::make_unique<Tally>(s.lobes, s.n_theta, s.n_phi, s.channels);
      Tally& tally = *mine_tally;
      // This thread's next run: none once a thread failed or (a lone
      // process) a signal came.
      auto feed = [&]() -> PhotonRun {
        if (failed.load(std::memory_order_relaxed) || (may_stop_early && interrupt_requested()))
          return {};
        std::uint64_t n_chunks = 0;
        const std::uint64_t i = take_run(n_chunks);
        if (n_chunks == 0) return {};
        const std::uint64_t a = first + (c0 + i) * kChunk;
        return {a, std::min(n_chunks * kChunk, end - a)};
      };
      sim_.trace_photons(k, feed, tally, counters, &progress_done_, size);
    } catch (...) {
      failed = true;
      std::lock_guard<std::mutex> lock(error_mutex_);
      if (!error_) error_ = std::current_exception();
    }
#pragma omp critical
    {
      counters_.add(counters);
    }
  }
  if (!may_stop_early) return end;
  return std::min(end, first + std::min(next.load(), mine) * kChunk);
}

// Adds every rank's unflushed sums of direction k into rank 0's state. Into
// a state that holds nothing yet, a thread's tally is swapped instead (exact:
// the sum of it and zero): the state's pages were never touched, and
// touching fresh memory costs time per page, whereas the zero tally the
// thread gets back costs nothing until that thread writes to it.
// A lone process adds the other threads' tallies on every thread and frees
// them rather than clearing them on this one: a flush is rare (the last
// round, checkpoints, target-error judgements), and a thread that traces
// again faults its fresh tally in itself, in parallel with the others,
// rather than this thread clearing every tally serially before the file is
// written.
void Simulation::Runner::flush(std::size_t k) {
  if (group_.size() == 1) {
    for (std::unique_ptr<Tally>& t : thread_tallies_)
      if (t) {
        if (state_.tallies[k].is_zero()) {
          std::swap(state_.tallies[k], *t);
        } else {
          state_.tallies[k].add(*t, threads_);
          t.reset();
        }
      }
    return;
  }
  const TallyShape shape = sim_.tally_shape();
  Tally sum(shape.lobes, shape.n_theta, shape.n_phi, shape.channels);
  for (std::unique_ptr<Tally>& t : thread_tallies_)
    if (t) {
      sum.add(*t);
      t->clear();
    }
  std::vector<ExactTally::Word> words = sum.exact().words();
  group_.sum_to_root(words);
  if (group_.is_root()) {
    ExactTally e(shape);
    e.from_words(words);
    state_.tallies[k].add(e);
  }
}

bool Simulation::Runner::target_reached(std::size_t k) {
  std::vector<std::int64_t> reached{
      group_.is_root() &&
      largest_relative_error(state_.tallies[k].exact()) < control_.target_error};
  group_.max(reached);
  return reached[0] != 0;
}

// After a round: when any rank failed, every rank stops with rank 0 saying why.
void Simulation::Runner::check_errors() {
  std::optional<std::string> mine;
  if (error_) {
    try {
      std::rethrow_exception(error_);
    } catch (const std::bad_alloc&) {
      mine = "out of memory while tracing (fewer --threads, or a smaller tally)";
    } catch (const std::exception& e) {
      mine = e.what();
    }
  }
  std::vector<std::int64_t> any{mine.has_value()};
  group_.max(any);
  if (!any[0]) return;
  const std::optional<std::string> message = group_.agree_on_error(mine);
  if (!group_.is_root()) throw FailedElsewhere{};
  if (group_.size() == 1) std::rethrow_exception(error_);
  throw Error(*message);
}

RunOutcome Simulation::Runner::run(RunStatistics* stats) {
  const auto start = Clock::now();
  thread_tallies_.resize(threads_);
  const std::size_t K = state_.next_photon.size();
  const std::uint64_t total = cap_ * K;
  std::uint64_t traced = 0;
  // The first round's size must be the same on every rank (each takes its
  // share of the same photons), and ranks may run different --threads: the
  // largest, agreed. Later sizes are rank 0's proposals, agreed likewise.
  std::vector<std::int64_t> most_threads{threads_};
  group_.max(most_threads);
  std::uint64_t round_chunks = static_cast<std::uint64_t>(most_threads[0]) * group_.size();
  auto last_checkpoint = Clock::now();
  std::uint64_t finished = photons_done();  // photons_done(), kept up to date
  progress_done_ = finished;
  RunOutcome outcome = RunOutcome::Finished;
  {
    ProgressTicker ticker(group_.is_root() ? control_.progress : ProgressCallback{},
                          progress_done_, total);
    for (std::size_t k = 0; k < K && outcome == RunOutcome::Finished; ++k) {
      while (!state_.done[k]) {
        const std::uint64_t first = state_.next_photon[k];
        // (Written so that nothing wraps for photon counts near 2^64.)
        std::uint64_t span = std::min(cap_ - first, round_chunks * kChunk);
        if (control_.target_error > 0) span = std::min(span, kTargetBatch - first % kTargetBatch);
        const std::uint64_t end = first + span;
        const auto round_start = Clock::now();
        const std::uint64_t reached = trace_round(k, first, end);
        // Rank 0 proposes the next round's size and whether a checkpoint is
        // due; every rank contributes its signal. Rounds last 0.2-0.8 s on
        // several ranks (a signal waits for the round's end, and mpirun kills
        // ranks a few seconds after forwarding one), 1-4 s alone (a signal
        // stops a lone process within a chunk; fewer round ends, where
        // threads wait for the slowest chunk).
        const double took = seconds_since(round_start);
        const double shortest = group_.size() == 1 ? 1.0 : 0.2;
        std::uint64_t proposal = round_chunks;
        if (took < shortest) proposal = std::min<std::uint64_t>(round_chunks * 2, 1u << 20);
        if (took > 4 * shortest) proposal = std::max<std::uint64_t>(round_chunks / 2, threads_);
        const bool due = control_.checkpoint && control_.checkpoint_every > 0 &&
                         seconds_since(last_checkpoint) >= control_.checkpoint_every;
        check_errors();
        std::vector<std::int64_t> agreed{interrupt_signal(), group_.is_root() && due,
                                         group_.is_root() ? static_cast<std::int64_t>(proposal) : 0};
        group_.max(agreed);
        const bool signalled = agreed[0] != 0, checkpoint = agreed[1] != 0 || signalled;
        round_chunks = static_cast<std::uint64_t>(agreed[2]);

        traced += reached - first;
        state_.next_photon[k] = reached;
        const bool last = reached == cap_;
        const bool judged = control_.target_error > 0 && reached > first &&
                            (reached % kTargetBatch == 0 || last);
        if (last || judged || checkpoint) flush(k);
        if (last) state_.done[k] = 1;
        else if (judged && target_reached(k)) state_.done[k] = 1;
        // Only direction k changed: its share, updated in O(1) (the sum over
        // every direction at each round made a run of K directions, each at
        // least one round, take time quadratic in K).
        finished += (state_.done[k] ? cap_ : reached) - first;
        progress_done_ = finished;
        if (checkpoint) {
          if (group_.is_root() && control_.checkpoint) control_.checkpoint(state_);
          last_checkpoint = Clock::now();
        }
        if (signalled) {
          outcome = RunOutcome::Interrupted;
          break;
        }
      }
    }
  }
  if (outcome == RunOutcome::Finished && group_.is_root() && control_.progress)
    control_.progress(total, total);
  if (stats) {
    stats->seconds = seconds_since(start);
    stats->threads = threads_;
    stats->ranks = group_.size();
    stats->photons = traced;
    stats->counters = counters_;
  }
  return outcome;
}

Simulation::Simulation(Settings settings)
    : settings_(std::move(settings)),
      grid_(BinGrid::make(settings_.tally.n_theta, settings_.tally.n_phi,
                          settings_.tally.theta_bins)),
      tracer_(settings_),
      batch_tracer_(settings_),
      // The model's type decides (sim/roughness/roughness_model.h, RunsBatched).
      use_batch_tracer_(runs_batched(make_roughness(settings_))),
      incidences_(settings_.incidences()) {}

TallyShape Simulation::tally_shape() const {
  return {settings_.tally_lobes(), settings_.tally.n_theta, settings_.tally.n_phi,
          static_cast<int>(settings_.fiber.sigma_a.size())};
}

void Simulation::trace_photons(std::size_t k, const PhotonFeed& feed, Tally& tally,
                               TracerCounters& counters, std::atomic<std::uint64_t>* traced,
                               std::uint64_t per_photon) const {
  const Settings::Incidence inc = incidences_[k];
  ExitScorer scorer(grid_, settings_.fiber.sigma_a, settings_.tally.lobes,
                    settings_.fiber.medulla ? settings_.fiber.medulla->sigma_a : std::vector<double>{},
                    settings_.estimator == Estimator::ExpectedValue);
  auto score = [&](const FinishedPhotons& f) { scorer.score(f, tally); };
  // Every run handed out is launched and traced in full, so it counts as
  // launched here, and as progress: a counter the threads share, touched a
  // run (up to Simulation::kMaxRunChunks chunks) at a time, because each
  // touch moves its cache line between the cores.
  auto counted_feed = [&] {
    const PhotonRun run = feed();
    tally.add_launched(run.n);
    if (traced) traced->fetch_add(run.n * per_photon, std::memory_order_relaxed);
    return run;
  };
  if (use_batch_tracer_) {
    batch_tracer_.trace(inc.theta_i, inc.phi_i, counted_feed, score, counters);
    return;
  }
  const Source source(settings_, inc.theta_i, inc.phi_i);
  auto done = std::make_unique<FinishedPhotons>();
  for (PhotonRun run = counted_feed(); run.n != 0; run = counted_feed()) {
    for (std::uint64_t i = run.first; i < run.first + run.n; ++i) {
      LaunchedPhoton p = source.launch(i);
      const PhotonOutcome o = tracer_.trace(p.wi, p.h, p.rng, &counters);
      for (const ScoredExitOutcome& e : o.scored) {
        done->add_scored(i, p.phi_i, e);
        if (done->full()) {
          score(*done);
          done->n = 0;
        }
      }
      done->add(i, p.phi_i, o);
      if (done->full()) {
        score(*done);
        done->n = 0;
      }
    }
  }
  if (done->n > 0) score(*done);
}

RunProgress Simulation::start() const {
  RunProgress p;
  const TallyShape s = tally_shape();
  p.tallies.assign(incidences_.size(), Tally(s.lobes, s.n_theta, s.n_phi, s.channels));
  p.next_photon.assign(incidences_.size(), 0);
  p.done.assign(incidences_.size(), 0);
  return p;
}

RunOutcome Simulation::run(RunProgress& state, const RunControl& control,
                           RunStatistics* stats) const {
  if (state.next_photon.size() != incidences_.size() || state.done.size() != incidences_.size())
    throw Error("internal error: run state for another number of incident directions");
  Runner runner(*this, state, control);
  return runner.run(stats);
}

std::vector<Tally> Simulation::run(int threads, const ProgressCallback& progress,
                                   RunStatistics* stats) const {
  RunProgress state = start();
  RunControl control;
  control.threads = threads;
  control.progress = progress;
  if (run(state, control, stats) == RunOutcome::Interrupted)
    throw Error(fmt::format("interrupted by signal {}", interrupt_signal()));
  return std::move(state.tallies);
}

double Simulation::largest_relative_error(const ExactTally& t) {
  const std::size_t LC = static_cast<std::size_t>(t.shape.lobes) * t.shape.channels;
  const std::vector<double> m = ExactTally::to_double(t.lobe_moments());
  double worst = 0.0;
  for (std::size_t i = 0; i < LC; ++i) {
    if (m[i] <= 0.0) continue;
    const Estimate e = bin_estimate(m[i], m[LC + i], t.photons);
    worst = std::max(worst, e.std_error / e.mean);
  }
  return worst;
}

}  // namespace fiberlab::sim
