#pragma once
// The reference tracer: one photon's life (sim/life/photon_life.h) at a time, the
// scalar instantiation of the same steps the batched tracer runs on SIMD
// vectors of photons (sim/life/batch_tracer.h).
#include <concepts>
#include <vector>

#include "common/fiber_frame.h"
#include "sim/life/exit_splitting.h"
#include "sim/life/photon_life.h"
#include "sim/life/random.h"
#include "sim/roughness/roughness_models.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

// Lost: a roughness model ended the path (its weight is booked as lost).
// Ended: Russian roulette ended the path (expected-value scoring; the
// weight it had is booked in the ledger's roulette term).
enum class PhotonFate { Exited, Truncated, Lost, Ended };

// An exit scored by expected value (Settings::estimator) before the
// photon's life ended: it left along `direction` after `segments` segments
// and `path_length` inside, with throughput `weight` (before absorption).
struct ScoredExitOutcome {
  Vec3 direction;
  int segments;
  double path_length, weight;
  double medulla_path = 0.0;  // with a medulla: the length inside it so far
  bool scattered = false;     // scattered in the medulla so far (lobe `scattered`)
  // Weight Russian roulette created (> 0) or destroyed (< 0) at this point,
  // before absorption; a row with weight 0 carries only this.
  double roulette = 0.0;
};

struct PhotonOutcome {
  PhotonFate fate = PhotonFate::Exited;
  Vec3 direction = Vec3::Zero();  // exit direction wr (when Exited)
  int segments = 0;               // internal straight segments: the lobe index p
  double path_length = 0.0;       // total 3D length inside, in units of R
  double theta = 0.0, phi = 0.0;  // inclination and azimuth of `direction` (when Exited)
  // The throughput before absorption: the product of the masking factors (1
  // without masking, 0 when Lost). Channel c carries weight exp(-sigma_a[c] l).
  double weight = 1.0;
  std::vector<WeightLoss> losses;  // what masking removed, in order (empty without masking)
  // Exits scored by expected value along the way, in order (empty with the
  // analog estimator); `fate` and `weight` are then what is left at the end.
  std::vector<ScoredExitOutcome> scored;
  // With a medulla (sim/life/medulla.h): the 3D length inside it (absorbed
  // with the medulla's sigma_a; path_length is the cortex's), and whether the
  // photon scattered there (then it is tallied in the lobe `scattered`).
  double medulla_path = 0.0;
  bool scattered = false;
};

// Work counters, for benchmarks and notes.
struct TracerCounters {
  long events = 0;          // interface events
  long normal_draws = 0;    // candidate microfacet normals drawn
  long sampler_caps = 0;    // photons truncated because no visible normal was drawn in
                            // kMaxNormalTries candidates (SPEC section 3: should be none)
  void add(const TracerCounters& o) {
    events += o.events;
    normal_draws += o.normal_draws;
    sampler_caps += o.sampler_caps;
  }
  void add(const life::LifeCounts<double>& c) {
    events += static_cast<long>(c.events);
    normal_draws += static_cast<long>(c.normal_draws);
    sampler_caps += static_cast<long>(c.sampler_caps);
  }
};

// The fate of a photon whose life ended with `code` (life::LaneCode).
inline PhotonFate fate_of(int code) {
  return code == life::kExited      ? PhotonFate::Exited
         : code == life::kTruncated ? PhotonFate::Truncated
         : code == life::kEnded     ? PhotonFate::Ended
                                    : PhotonFate::Lost;
}

// A roughness model with an exit hook (exit_blur): the direction a photon
// leaves along is drawn from its own stream when it exits.
template <class Model>
concept HasExitHook = requires(const Model& m, const Vec3& d, int segments, PhotonRandom& rng) {
  { m.exit_direction(d, segments, rng) } -> std::same_as<Vec3>;
};

// The direction of a photon that exited along d after `segments` segments.
template <class Model>
Vec3 exit_direction_of(const Model& model, const Vec3& d, int segments, PhotonRandom& rng) {
  if constexpr (HasExitHook<Model>) return model.exit_direction(d, segments, rng);
  else return d;
}

// The stream an exit scored by expected value draws its exit direction
// from (exit_blur): derived from the photon's stream state after the step
// that scored it, so that the photon's own stream, and with it its path, is
// the same whether or not its exits are blurred; both tracers derive it so.
inline PhotonRandom scored_exit_stream(std::uint64_t w0, std::uint64_t w1, std::uint64_t w2,
                                       std::uint64_t w3) {
  return PhotonRandom(life::splitmix(w0 ^ life::splitmix(w1 ^ life::splitmix(w2))), w3);
}

// The outcome of a photon whose life ended with `code`.
template <class Model>
PhotonOutcome finished_outcome(const Model& model, int code, const Vec3& d, int segments,
                               double path, double weight, PhotonRandom& rng) {
  PhotonOutcome out;
  out.fate = fate_of(code);
  out.segments = segments;
  out.path_length = path;
  out.weight = weight;
  if (out.fate == PhotonFate::Exited) out.direction = exit_direction_of(model, d, segments, rng);
  return out;
}

class Tracer {
 public:
  explicit Tracer(const Settings& settings);

  // Traces one photon arriving along -wi. h in (-1, 1) is its impact
  // parameter across the projected width.
  PhotonOutcome trace(const Vec3& wi, double h, PhotonRandom& rng,
                      TracerCounters* counters = nullptr) const;

  // Cap on candidate normals per event (SPEC section 3: at least 10,000).
  static constexpr int kMaxNormalTries = life::kMaxNormalTries;

 private:
  template <class Light, class Model>
  PhotonOutcome trace_with(const Model& model, const Vec3& wi, double h, PhotonRandom& rng,
                           TracerCounters* counters) const;

  life::LifeConfig config_;
  AnyRoughness roughness_;
  Polarization polarization_;
};

}  // namespace fiberlab::sim
