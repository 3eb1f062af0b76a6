#pragma once
// Where a tracer's photons come from: runs of consecutive photon indices,
// handed out one at a time. The batched tracer asks for the next run whenever
// its pool of lanes has room, so its pool drains once per call (when the feed
// is empty), not once per run: draining leaves vectors part empty while a few
// light-guided photons finish. A photon's path depends on its index only
// (its stream and impact parameter, sim/life/source.h), so how the indices are cut
// into runs, and which thread traces which run, changes no bit of the sums.
#include <cstdint>
#include <functional>
#include <utility>

namespace fiberlab::sim {

// Photons [first, first + n); n = 0: the feed is empty.
struct PhotonRun {
  std::uint64_t first = 0, n = 0;
};

// The next run, or an empty one when there is no more (and for ever after).
using PhotonFeed = std::function<PhotonRun()>;

// A feed of one run.
inline PhotonFeed single_run(std::uint64_t first, std::uint64_t n) {
  return [run = PhotonRun{first, n}]() mutable { return std::exchange(run, PhotonRun{}); };
}

}  // namespace fiberlab::sim
