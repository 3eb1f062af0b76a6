#pragma once
// Runs a whole configuration: every incident direction, every photon, in
// parallel with OpenMP, into one Tally per incident configuration.
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/settings.h"
#include "sim/tally.h"
#include "sim/batch_tracer.h"
#include "sim/tracer.h"

namespace fiberlab::sim {

// Called from one thread now and then: photons traced so far over all
// incident configurations, and the total to trace.
using ProgressCallback = std::function<void(std::uint64_t done, std::uint64_t total)>;

struct RunStatistics {
  double seconds = 0.0;
  int threads = 1;
  TracerCounters counters;
};

class Simulation {
 public:
  explicit Simulation(Settings settings);

  const Settings& settings() const { return settings_; }
  const BinGrid& grid() const { return grid_; }

  // threads <= 0: OpenMP's default. Results do not depend on `threads`.
  std::vector<Tally> run(int threads, const ProgressCallback& progress = {},
                         RunStatistics* stats = nullptr) const;

  // Traces photons [first, first + n) of incident configuration k into `tally`
  // (with the batched tracer for scalar light, the reference tracer otherwise).
  void trace_photons(std::size_t k, std::uint64_t first, std::uint64_t n, Tally& tally,
                     TracerCounters& counters) const;

 private:
  Settings settings_;
  BinGrid grid_;
  Tracer tracer_;            // the reference tracer; serves polarization: stokes
  BatchTracer batch_tracer_; // the vectorised tracer for unpolarised light
  bool use_batch_tracer_;
  std::vector<Settings::Incidence> incidences_;
};

}  // namespace fiberlab::sim
