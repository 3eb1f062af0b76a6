#pragma once
// Photons that a tracer has finished, handed to the scorer a block at a time
// (structure of arrays), so that weights are computed vectorised and the
// tally's cells fetched ahead, instead of one call per photon.
#include <cstdint>

#include "sim/tracer.h"

namespace fiberlab::sim {

struct FinishedPhotons {
  static constexpr int kCapacity = 256;  // a multiple of every SIMD width
  int n = 0;
  alignas(64) double path[kCapacity] = {};  // internal 3D path length
  alignas(64) double theta[kCapacity], phi[kCapacity], phi_i[kCapacity];
  alignas(64) double dx[kCapacity] = {}, dy[kCapacity] = {}, dz[kCapacity] = {};  // exit direction
  std::uint64_t photon[kCapacity];
  alignas(64) double weight[kCapacity];  // the roughness model's throughput factor (1 by default)
  int segments[kCapacity];
  bool exited[kCapacity];
  bool lost[kCapacity];  // fate Lost (not exited, not truncated)

  bool full() const { return n == kCapacity; }
  void add(std::uint64_t index, double incident_phi, const PhotonOutcome& o) {
    photon[n] = index;
    phi_i[n] = incident_phi;
    path[n] = o.path_length;
    segments[n] = o.segments;
    exited[n] = o.fate == PhotonFate::Exited;
    lost[n] = o.fate == PhotonFate::Lost;
    weight[n] = o.weight;
    theta[n] = o.theta;
    phi[n] = o.phi;
    dx[n] = o.direction.x();
    dy[n] = o.direction.y();
    dz[n] = o.direction.z();
    ++n;
  }
  PhotonOutcome outcome(int i) const {
    PhotonOutcome o;
    o.fate = exited[i] ? PhotonFate::Exited : lost[i] ? PhotonFate::Lost : PhotonFate::Truncated;
    o.weight = weight[i];
    o.direction = Vec3(dx[i], dy[i], dz[i]);
    o.segments = segments[i];
    o.path_length = path[i];
    o.theta = theta[i];
    o.phi = phi[i];
    return o;
  }
};

}  // namespace fiberlab::sim
