#include "sim/simulation.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>

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
  const std::uint64_t chunks = (photons + kChunk - 1) / kChunk;
  const std::uint64_t total = photons * incidences_.size();
  std::atomic<std::uint64_t> done{0};
  TracerCounters all_counters;

  std::vector<Tally> results;
  for (std::size_t k = 0; k < incidences_.size(); ++k) {
    Tally result(ts.lobes, ts.n_theta, ts.n_phi, channels);
#pragma omp parallel num_threads(threads)
    {
      Tally local(ts.lobes, ts.n_theta, ts.n_phi, channels);
      TracerCounters counters;
      auto last_report = Clock::now();
#pragma omp for schedule(dynamic, 1)
      for (std::uint64_t c = 0; c < chunks; ++c) {
        const std::uint64_t first = c * kChunk;
        const std::uint64_t n = std::min(kChunk, photons - first);
        trace_photons(k, first, n, local, counters);
        const std::uint64_t now_done = done.fetch_add(n) + n;
        if (progress && omp_get_thread_num() == 0 &&
            Clock::now() - last_report > std::chrono::milliseconds(250)) {
          last_report = Clock::now();
          progress(now_done, total);
        }
      }
#pragma omp critical
      {
        result.add(local);  // integer sums: the order does not matter
        all_counters.add(counters);
      }
    }
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
