#include "sim/simulation.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <optional>

#include "common/units.h"
#include "sim/exit_scoring.h"
#include "sim/source.h"

namespace fiberlab::sim {

namespace {
// Photons handed to a thread at a time: large, because a chunk ends with its
// few light-guided photons alone in the batch tracer's lanes (-4% CPU on case
// b from 4096 to 32768), but at least 8 chunks per thread when there are
// photons enough, for the load balance. Results do not depend on it.
std::uint64_t chunk_size(std::uint64_t photons, int threads) {
  return std::clamp<std::uint64_t>(photons / (8 * static_cast<std::uint64_t>(threads)), 4096,
                                   32768);
}
}

Simulation::Simulation(Settings settings)
    : settings_(std::move(settings)),
      grid_(BinGrid::make(settings_.tally.n_theta, settings_.tally.n_phi,
                          settings_.tally.theta_bins)),
      tracer_(settings_),
      batch_tracer_(settings_),
      use_batch_tracer_(settings_.polarization == Polarization::Scalar),
      incidences_(settings_.incidences()) {}

void Simulation::trace_photons(std::size_t k, std::uint64_t first, std::uint64_t n,
                               Tally& tally, TracerCounters& counters) const {
  const Settings::Incidence inc = incidences_[k];
  ExitScorer scorer(grid_, settings_.fiber.sigma_a, tally.lobes());
  auto score = [&](const FinishedPhotons& f) { scorer.score(f, tally); };
  if (use_batch_tracer_) {
    batch_tracer_.trace(inc.theta_i, inc.phi_i, first, n, score, counters);
  } else {
    const Source source(settings_.seed, inc.theta_i, inc.phi_i, settings_.source.phi_i_uniform);
    auto done = std::make_unique<FinishedPhotons>();
    for (std::uint64_t i = first; i < first + n; ++i) {
      LaunchedPhoton p = source.launch(i);
      done->add(i, p.phi_i, tracer_.trace(p.wi, p.h, p.rng, &counters));
      if (done->full() || i + 1 == first + n) {
        score(*done);
        done->n = 0;
      }
    }
  }
  tally.add_launched(n);
}

std::vector<Tally> Simulation::run(int threads, const ProgressCallback& progress,
                                   RunStatistics* stats) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (threads <= 0) threads = omp_get_max_threads();
  const TallySettings& ts = settings_.tally;
  const int channels = static_cast<int>(settings_.fiber.sigma_a.size());
  const std::uint64_t photons = settings_.photons;
  const std::uint64_t kChunk = chunk_size(photons, threads);
  // (photons + kChunk - 1) / kChunk would wrap for photons near 2^64.
  const std::uint64_t chunks = photons / kChunk + (photons % kChunk != 0);
  const std::uint64_t total = photons * incidences_.size();
  std::atomic<std::uint64_t> done{0};
  TracerCounters all_counters;

  std::vector<Tally> results;
  for (std::size_t k = 0; k < incidences_.size(); ++k) {
    Tally result(ts.lobes, ts.n_theta, ts.n_phi, channels);
    // An exception must not leave an OpenMP region (std::terminate, SIGABRT):
    // the first one (e.g. std::bad_alloc) is kept, the other threads skip
    // their remaining chunks, and it is rethrown after the region.
    std::exception_ptr failure;
    std::atomic<bool> failed{false};
    auto keep_failure = [&] {
#pragma omp critical(fiberlab_run_failure)
      if (!failure) failure = std::current_exception();
      failed = true;
    };
#pragma omp parallel num_threads(threads)
    {
      std::optional<Tally> local;
      try {
        local.emplace(ts.lobes, ts.n_theta, ts.n_phi, channels);
      } catch (...) {
        keep_failure();
      }
      TracerCounters counters;
      auto last_report = Clock::now();
#pragma omp for schedule(dynamic, 1)
      for (std::uint64_t c = 0; c < chunks; ++c) {
        if (failed) continue;
        try {
          const std::uint64_t first = c * kChunk;
          const std::uint64_t n = std::min(kChunk, photons - first);
          trace_photons(k, first, n, *local, counters);
          const std::uint64_t now_done = done.fetch_add(n) + n;
          if (progress && omp_get_thread_num() == 0 &&
              Clock::now() - last_report > std::chrono::milliseconds(250)) {
            last_report = Clock::now();
            progress(now_done, total);
          }
        } catch (...) {
          keep_failure();
        }
      }
#pragma omp critical
      if (local && !failed) {
        result.add(*local);  // integer sums: the order does not matter
        all_counters.add(counters);
      }
    }
    if (failure) std::rethrow_exception(failure);
    results.push_back(std::move(result));
  }
  if (progress) progress(total, total);
  if (stats) {
    stats->seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stats->threads = threads;
    stats->counters = all_counters;
  }
  return results;
}

}  // namespace fiberlab::sim
