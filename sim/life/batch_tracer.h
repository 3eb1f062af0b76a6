#pragma once
// The photon life of sim/life/photon_life.h traced for many photons at once:
// photons live in a pool of lanes kept in structure-of-arrays form, and each
// step (an interface event and the next segment) runs on a SIMD vector of
// lanes (xsimd: 8 doubles with AVX-512). After each step the finished
// photons of a vector are packed into a block for the sink and the others to
// the front of the pool, which is then refilled with new photons from the
// Source, so the few light-guided photons that run to max_segments do not
// hold up the rest. New photons come from a PhotonFeed (sim/life/photon_feed.h),
// asked for its next run whenever the pool has room: the pool drains (its
// vectors part empty) once per call, not once per run.
// This file only manages lanes; the physics is the life's, shared with the
// reference Tracer, for every roughness model and for scalar and Stokes light.
#include <cstdint>
#include <functional>

#include "sim/life/finished_photons.h"
#include "sim/life/photon_feed.h"
#include "sim/life/photon_life.h"
#include "sim/roughness/roughness_models.h"
#include "sim/run/settings.h"
#include "sim/life/tracer.h"

namespace fiberlab::sim {

class BatchTracer {
 public:
  explicit BatchTracer(const Settings& settings);

  // Receives the finished photons a block at a time (each with its index,
  // incident azimuth and fate).
  using Sink = std::function<void(const FinishedPhotons&)>;

  // Traces the photons of every run the feed hands out, until it is empty,
  // of the incident direction (theta_i, phi_i) (seed and streams as in
  // launch_photon), in no particular order.
  void trace(double theta_i, double phi_i, const PhotonFeed& feed, const Sink& sink,
             TracerCounters& counters) const;
  // Photons [first, first + n): a feed of one run.
  void trace(double theta_i, double phi_i, std::uint64_t first, std::uint64_t n,
             const Sink& sink, TracerCounters& counters) const {
    trace(theta_i, phi_i, single_run(first, n), sink, counters);
  }

 private:
  // kExpectedValue: config_.expected_value, fixed at compile time so that
  // the analog loop carries no code of the other estimator.
  template <class Light, bool kExpectedValue, class Model>
  void trace_with(const Model& model, double theta_i, double phi_i, const PhotonFeed& feed,
                  const Sink& sink, TracerCounters& counters) const;

  const Settings settings_;
  life::LifeConfig config_;
  AnyRoughness roughness_;
};

}  // namespace fiberlab::sim
