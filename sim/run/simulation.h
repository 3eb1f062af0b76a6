#pragma once
// Runs a whole configuration: every incident direction, every photon, in
// parallel with OpenMP threads and, when started by mpirun/srun, MPI ranks,
// into one Tally per incident direction.
//
// Work is cut into chunks of kChunk consecutive photon indices and chunks into
// rounds (a few tenths of a second of work). Rounds end at the same photon on
// every rank; at a round's end the ranks agree on what to do next (go on,
// save a checkpoint, stop on a signal, stop a direction at its target error).
// Each photon's random stream depends only on (seed, incident direction,
// photon index), and sums are exact integers, so neither threads, ranks,
// round sizes nor checkpoints change a bit of the result.
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/life/batch_tracer.h"
#include "sim/life/photon_feed.h"
#include "sim/run/process_group.h"
#include "sim/run/settings.h"
#include "sim/store/tally.h"
#include "sim/life/tracer.h"

namespace fiberlab::sim {

// Called now and then (about twice a second, from a helper thread, on rank 0
// only): photons traced so far over all incident directions (an estimate
// within a round), and the total to trace.
using ProgressCallback = std::function<void(std::uint64_t done, std::uint64_t total)>;

struct RunStatistics {
  double seconds = 0.0;
  int threads = 1;
  int ranks = 1;
  std::uint64_t photons = 0;  // traced in this call (a resumed run: since the resume)
  TracerCounters counters;    // this rank's
};

// How far a run got: what a checkpoint stores and a resumed run starts from.
struct RunProgress {
  std::vector<Tally> tallies;          // K; rank 0: photons [0, next_photon[k]); other ranks: empty
  std::vector<std::uint64_t> next_photon;  // K, a multiple of kChunk unless the direction is done
  std::vector<std::uint8_t> done;      // K: every photon traced, or the target error reached
};

struct RunControl {
  int threads = 0;                 // <= 0: OpenMP's default
  ProgressCallback progress;
  double checkpoint_every = 0.0;   // seconds between checkpoints; <= 0: none but on signals
  std::function<void(const RunProgress&)> checkpoint;  // rank 0: save it (atomically)
  double target_error = 0.0;       // > 0: --target-error (see Simulation::kTargetBatch)
  const ProcessGroup* group = nullptr;  // nullptr: this process alone
};

enum class RunOutcome { Finished, Interrupted };

class Simulation {
 public:
  // Photons handed to a thread at a time (the unit of a round's prefix when
  // a signal stops it). The batched tracer waits for the slowest
  // (light-guided) photon of each call, so runs of chunks are fed to one call
  // per thread and round rather than a call per chunk (256-photon chunks, a
  // call each, run at half the speed). Progress is counted per photon.
  static constexpr std::uint64_t kChunk = 4096;
  // A thread takes up to kMaxRunChunks consecutive chunks at a time (a
  // signal waits for the runs a thread has taken: 64 Ki photons, a few
  // hundredths of a second).
  static constexpr std::uint64_t kMaxRunChunks = 16;
  // --target-error is judged after every kTargetBatch photons of a direction
  // (and at its last photon): a fixed schedule, so the stopping point depends
  // only on the seed and config, never on timing, threads or ranks.
  static constexpr std::uint64_t kTargetBatch = 65536;

  explicit Simulation(Settings settings);

  const Settings& settings() const { return settings_; }
  const BinGrid& grid() const { return grid_; }
  TallyShape tally_shape() const;

  // threads <= 0: OpenMP's default. Results do not depend on `threads`.
  std::vector<Tally> run(int threads, const ProgressCallback& progress = {},
                         RunStatistics* stats = nullptr) const;

  // A run that can stop and go on: starts from `state` (start() for a fresh
  // one) and advances it. Returns Interrupted after SIGINT/SIGTERM, once the
  // checkpoint callback has saved the state; throws fiberlab::Error when a
  // rank failed (FailedElsewhere on ranks other than 0).
  RunProgress start() const;
  RunOutcome run(RunProgress& state, const RunControl& control, RunStatistics* stats = nullptr) const;

  // Traces the photons of every run the feed hands out (sim/life/photon_feed.h)
  // of incident configuration k into `tally` (with the batched tracer where
  // it runs the roughness model, runs_batched in
  // sim/roughness/roughness_models.h; otherwise the reference tracer). `traced`, when given, grows by `per_photon` for each photon of
  // a run as the run is taken (progress: every run taken is traced in full).
  void trace_photons(std::size_t k, const PhotonFeed& feed, Tally& tally,
                     TracerCounters& counters, std::atomic<std::uint64_t>* traced = nullptr,
                     std::uint64_t per_photon = 1) const;
  // Photons [first, first + n).
  void trace_photons(std::size_t k, std::uint64_t first, std::uint64_t n, Tally& tally,
                     TracerCounters& counters, std::atomic<std::uint64_t>* traced = nullptr,
                     std::uint64_t per_photon = 1) const {
    trace_photons(k, single_run(first, n), tally, counters, traced, per_photon);
  }

  // Largest relative standard error of any lobe energy in any channel (lobes
  // with zero energy are skipped: no relative error exists for them); what
  // --target-error compares with its target.
  static double largest_relative_error(const ExactTally& t);

 private:
  class Runner;

  Settings settings_;
  BinGrid grid_;
  Tracer tracer_;            // the reference tracer: a model the batched one does not run
  BatchTracer batch_tracer_; // the vectorised tracer
  bool use_batch_tracer_;
  std::vector<Settings::Incidence> incidences_;
};

}  // namespace fiberlab::sim
