#pragma once
// A photon's life (SPEC sections 3-5): enter the fiber at an impact parameter,
// meet the boundary, reflect or refract about a drawn normal, run straight
// segments inside, until it leaves or is truncated. The path does not depend
// on the colour channel, so the tracer returns the total internal path length
// and the caller turns it into a Beer-Lambert weight per channel.
#include <optional>
#include <vector>

#include "common/fiber_frame.h"
#include "sim/ellipse_cross_section.h"
#include "sim/exit_blur.h"
#include "sim/microfacet_roughness.h"
#include "sim/random.h"
#include "sim/settings.h"

namespace fiberlab::sim {

// Lost: killed by masking (roughness.masking: smith_g1), its weight booked as lost.
enum class PhotonFate { Exited, Truncated, Lost };

// Weight removed from a photon by masking, and the internal path length it had
// travelled then: channel c lost weight * exp(-sigma_a[c] * path_length).
struct WeightLoss {
  double weight, path_length;
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
};

class Tracer {
 public:
  explicit Tracer(const Settings& settings);

  // The roughness model the tracers apply: gaussian with beta_long = beta_azim
  // = 0 is the smooth model, fallback included (SPEC section 3).
  static RoughnessModel effective_model(const RoughnessSettings& r);

  // Traces one photon arriving along -wi. h in (-1, 1) is its impact
  // parameter across the projected width.
  PhotonOutcome trace(const Vec3& wi, double h, PhotonRandom& rng,
                      TracerCounters* counters = nullptr) const;

  // Cap on candidate normals per event (SPEC section 3: at least 10,000).
  static constexpr int kMaxNormalTries = 100000;

 private:
  // The photon's life for one kind of light (ScalarLight or StokesLight).
  template <typename Light>
  PhotonOutcome trace_with(const Vec3& wi, double h, PhotonRandom& rng,
                           TracerCounters& counters) const;
  // Interface events at one boundary point until the consistency rule holds.
  // False when the photon's life ends there (out.fate says how).
  template <typename Light>
  bool scatter_at_boundary(const Point2& p, Vec3& d, bool& inside, Light& light,
                           PhotonRandom& rng, TracerCounters& counters, PhotonOutcome& out) const;
  // masking: smith_g1: the weight times G1 of the scattered direction d, the
  // rest booked as lost; false (fate Lost) when d is on the wrong side.
  bool apply_masking(const Vec3& mean, const Vec3& d, bool refracted, PhotonOutcome& out) const;

  EllipseCrossSection ellipse_;
  RoughnessModel model_;
  Polarization polarization_;
  double eta_;
  double cos_tilt_, sin_tilt_;
  double beta_long_, beta_azim_;          // gaussian
  ExitBlur exit_blur_;
  std::optional<MicrofacetRoughness> microfacet_;  // beckmann / ggx
  int max_segments_, max_events_;
};

}  // namespace fiberlab::sim
