#pragma once
// The same photon life as Tracer (sim/tracer.h), for unpolarised light,
// traced for many photons at once: photons live in a pool of lanes kept in
// structure-of-arrays form, and each interface event and each internal
// segment is computed for a SIMD vector of lanes (xsimd: 8 doubles with
// AVX-512). Lanes whose photon has left are refilled with new photons, so the
// few light-guided photons that run to max_segments do not hold up the rest.
//
// Each photon draws from its own random stream in the same order as in
// Tracer, so a photon's path is the same in both up to the last bits of the
// vectorised sin/cos/log (tests/sim/test_batch_tracer.cpp checks photon by
// photon). Tracer stays the readable reference and serves polarization: stokes.
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/finished_photons.h"
#include "sim/settings.h"
#include "sim/source.h"
#include "sim/tracer.h"

namespace fiberlab::sim {

class BatchTracer {
 public:
  explicit BatchTracer(const Settings& settings);

  // Receives the finished photons a block at a time (each with its index,
  // incident azimuth and fate).
  using Sink = std::function<void(const FinishedPhotons&)>;

  // Traces photons [first, first + n) of the incident direction (theta_i,
  // phi_i) (seed and streams as in launch_photon), in no particular order.
  void trace(double theta_i, double phi_i, std::uint64_t first, std::uint64_t n,
             const Sink& sink, TracerCounters& counters) const;

  struct Lanes;  // the photons in flight (defined in batch_tracer.cpp)

 private:
  void launch(Lanes& lanes, int lane, const Source& source, const Eigen::Vector2d& beam,
              std::uint64_t photon) const;
  void launch_group(Lanes& lanes, int first_lane, int n, std::uint64_t first_photon,
                    const Source& source, const Vec3& d, const Eigen::Vector2d& beam,
                    double phi_i) const;
  void interface_events(Lanes& lanes, int n_active) const;
  void travel(Lanes& lanes, int n_active) const;

  const Settings settings_;
  RoughnessModel model_;  // Tracer::effective_model
  EllipseCrossSection ellipse_;
  double cos_tilt_, sin_tilt_;
};

}  // namespace fiberlab::sim
