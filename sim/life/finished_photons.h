#pragma once
// Photons that a tracer has finished, handed to the scorer a block at a time
// (structure of arrays), so that weights are computed vectorised and the
// tally's cells fetched ahead, instead of one call per photon.
//
// A row is a photon's end (exited, truncated, lost or ended; `last`), or,
// with expected-value scoring (Settings::estimator), a point on its way
// (not `last`) where it scored an exit (`exited`, weight > 0), or Russian
// roulette created or destroyed weight (`roulette` != 0), or both. A
// photon that Russian roulette ended (`ended`) may end on such a row (the
// batched tracer's) or on a row of its own (the reference tracer's, through
// add). A photon's rows come in the order it made them,
// its end last, and carry the tracer's `slot` for the photon: no other
// photon uses that slot until the photon's last row, so the scorer can add
// up a photon's exits per bin (SPEC section 6: S2 holds the square of a
// photon's total in a bin). A photon's rows may span blocks.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "sim/life/tracer.h"

namespace fiberlab::sim {

struct FinishedPhotons {
  static constexpr int kCapacity = 1024;  // a multiple of every SIMD width
  static_assert(kCapacity % kBatchWidth == 0);
  int n = 0;
  alignas(64) double path[kCapacity] = {};  // internal 3D path length
  alignas(64) double weight[kCapacity] = {};  // throughput before absorption (PhotonOutcome::weight)
  alignas(64) double theta[kCapacity], phi[kCapacity], phi_i[kCapacity];
  alignas(64) double dx[kCapacity] = {}, dy[kCapacity] = {}, dz[kCapacity] = {};  // exit direction
  alignas(64) double medulla_path[kCapacity] = {};  // 3D length inside the medulla (0 without one)
  bool scattered[kCapacity] = {};  // scattered in the medulla: the lobe `scattered`
  std::uint64_t photon[kCapacity];
  int segments[kCapacity];
  bool exited[kCapacity];
  bool lost[kCapacity];  // killed by masking (its weight is in `losses`)
  bool ended[kCapacity];  // ended by Russian roulette (its weight is in an earlier row's `roulette`)
  bool last[kCapacity];  // the photon's end (false: a point on its way)
  double roulette[kCapacity];  // not `last`: Russian roulette's signed weight there, before absorption
  std::uint32_t slot[kCapacity];  // the photon's slot in its tracer
  // Weight removed by masking from the block's photons (empty
  // without masking): photon slot, weight, path length at the removal.
  struct Loss {
    int slot;
    WeightLoss loss;
  };
  std::vector<Loss> losses;

  bool full() const { return n == kCapacity; }
  // Zeroes the numbers of slots [n, the end of n's SIMD vector): the scorer's
  // vectorised loops read a whole vector, and a batched tracer appends whole
  // vectors, whose lanes past its photons hold scratch (any bits, possibly a
  // value that would overflow a conversion to an integer).
  void clear_tail() {
    const int end = (n + kBatchWidth - 1) / kBatchWidth * kBatchWidth;
    for (double* column : {path, weight, phi_i, dx, dy, dz, medulla_path})
      std::fill(column + n, column + end, 0.0);
  }
  // A point on photon `index`'s way (an exit it scored by expected value,
  // Russian roulette; one photon at a time: slot 0).
  void add_scored(std::uint64_t index, double incident_phi, const ScoredExitOutcome& e) {
    if (n == 0) losses.clear();  // a new block (callers reset n after scoring)
    weight[n] = e.weight;
    roulette[n] = e.roulette;
    ended[n] = false;
    lost[n] = false;
    last[n] = false;
    slot[n] = 0;
    photon[n] = index;
    phi_i[n] = incident_phi;
    path[n] = e.path_length;
    medulla_path[n] = e.medulla_path;
    scattered[n] = e.scattered;
    segments[n] = e.segments;
    exited[n] = e.weight > 0.0;
    theta[n] = inclination(e.direction);
    phi[n] = azimuth(e.direction);
    dx[n] = e.direction.x();
    dy[n] = e.direction.y();
    dz[n] = e.direction.z();
    ++n;
  }
  // Photon `index`'s end (its scored exits added before it).
  void add(std::uint64_t index, double incident_phi, const PhotonOutcome& o) {
    if (n == 0) losses.clear();  // a new block (callers reset n after scoring)
    for (const WeightLoss& l : o.losses) losses.push_back({n, l});
    last[n] = true;
    slot[n] = 0;
    weight[n] = o.weight;
    roulette[n] = 0.0;
    lost[n] = o.fate == PhotonFate::Lost;
    ended[n] = o.fate == PhotonFate::Ended;
    photon[n] = index;
    phi_i[n] = incident_phi;
    path[n] = o.path_length;
    medulla_path[n] = o.medulla_path;
    scattered[n] = o.scattered;
    segments[n] = o.segments;
    exited[n] = o.fate == PhotonFate::Exited;
    theta[n] = o.theta;
    phi[n] = o.phi;
    dx[n] = o.direction.x();
    dy[n] = o.direction.y();
    dz[n] = o.direction.z();
    ++n;
  }
  PhotonOutcome outcome(int i) const {
    PhotonOutcome o;
    // (An ended photon's last row may also hold an exit it scored there:
    // that is not its fate, and it ends with nothing.)
    o.fate = ended[i]    ? PhotonFate::Ended
             : exited[i] ? PhotonFate::Exited
             : lost[i]   ? PhotonFate::Lost
                         : PhotonFate::Truncated;
    o.weight = ended[i] ? 0.0 : weight[i];
    for (const Loss& l : losses)
      if (l.slot == i) o.losses.push_back(l.loss);
    o.direction = ended[i] ? Vec3(0.0, 0.0, 0.0) : Vec3(dx[i], dy[i], dz[i]);
    o.segments = segments[i];
    o.path_length = path[i];
    o.medulla_path = medulla_path[i];
    o.scattered = scattered[i];
    o.theta = theta[i];
    o.phi = phi[i];
    return o;
  }
};

}  // namespace fiberlab::sim
