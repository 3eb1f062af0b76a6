#include "sim/tracer.h"

#include <cmath>

#include "sim/exit_blur.h"
#include "sim/interface_event.h"
#include "sim/microfacet_normal.h"

namespace fiberlab::sim {

namespace {
template <typename Light>
Light make_light(const Vec3& d) {
  if constexpr (Light::kPolarized) return Light(d);  // unpolarised, axis perpendicular to d
  else return Light{};
}
}  // namespace

Tracer::Tracer(const Settings& s)
    : ellipse_(s.fiber.eccentricity),
      model_(effective_model(s.roughness)),
      polarization_(s.polarization),
      eta_(s.fiber.eta),
      cos_tilt_(std::cos(s.fiber.scale_tilt)),
      sin_tilt_(std::sin(s.fiber.scale_tilt)),
      beta_long_(s.roughness.beta_long.front()),
      beta_azim_(s.roughness.beta_azim.front()),
      exit_blur_(s.roughness),
      microfacet_(s.roughness.microfacet() ? std::optional<MicrofacetRoughness>(s.roughness)
                                           : std::nullopt),
      max_segments_(s.max_segments),
      max_events_(s.max_events_per_point) {}

RoughnessModel Tracer::effective_model(const RoughnessSettings& r) {
  if (r.model == RoughnessModel::Gaussian && r.beta_long.front() == 0.0 &&
      r.beta_azim.front() == 0.0)
    return RoughnessModel::Smooth;
  return r.model;
}

// Returns false when the photon must be truncated (too many events at this
// point, or no visible normal found) or was killed by masking, with out.fate
// set. On return d is the new direction and `inside` the photon's new side,
// consistent with the untilted normal.
template <typename Light>
bool Tracer::scatter_at_boundary(const Point2& p, Vec3& d, bool& inside, Light& light,
                                 PhotonRandom& rng, TracerCounters& counters,
                                 PhotonOutcome& out) const {
  out.fate = PhotonFate::Truncated;  // unless an event below decides otherwise
  const Vec3 n0 = ellipse_.normal(p);
  // Cuticle tilt towards the root, on both sides (SPEC section 2).
  const Vec3 n_s = cos_tilt_ * n0 - sin_tilt_ * Vec3::UnitX();
  for (int k = 0; k < max_events_; ++k) {
    ++counters.events;
    const BoundaryNormals normals{inside ? Vec3(-n_s) : n_s, inside ? Vec3(-n0) : n0};
    Vec3 m, mean;
    if (microfacet_) {
      ++counters.normal_draws;
      mean = MicrofacetRoughness::mean_normal(d, normals);
      const std::optional<Vec3> drawn = microfacet_->sample_normal(d, mean, rng);
      if (!drawn) {
        ++counters.sampler_caps;
        return false;
      }
      m = *drawn;
    } else if (model_ == RoughnessModel::Gaussian) {
      auto drawn = gaussian_normal(d, normals.facing, beta_long_, beta_azim_, rng,
                                   kMaxNormalTries, counters.normal_draws);
      if (!drawn) {
        ++counters.sampler_caps;
        return false;
      }
      m = *drawn;
    } else {
      m = smooth_normal(d, normals);
    }
    const double eta_rel = inside ? 1.0 / eta_ : eta_;  // n_t / n_i
    const EventResult r = light.interact(d, m, eta_rel, rng);
    d = r.direction;
    if (r.refracted) inside = !inside;
    if (microfacet_ && microfacet_->masks() && !apply_masking(mean, d, r.refracted, out)) return false;
    // Consistency rule (SPEC section 3): the new direction must leave the
    // boundary on the photon's side, judged with the untilted normal.
    const double dn = d.dot(n0);
    if (inside ? dn < 0.0 : dn > 0.0) return true;
  }
  return false;
}

bool Tracer::apply_masking(const Vec3& mean, const Vec3& d, bool refracted,
                           PhotonOutcome& out) const {
  const double g1 = microfacet_->masking_factor(mean, d, refracted);
  if (g1 < 1.0) out.losses.push_back({out.weight * (1.0 - g1), out.path_length});
  out.weight *= g1;
  if (g1 > 0.0) return true;
  out.weight = 0.0;
  out.fate = PhotonFate::Lost;
  return false;
}

PhotonOutcome Tracer::trace(const Vec3& wi, double h, PhotonRandom& rng,
                            TracerCounters* counters_out) const {
  TracerCounters counters;
  const PhotonOutcome out = polarization_ == Polarization::Stokes
                                ? trace_with<StokesLight>(wi, h, rng, counters)
                                : trace_with<ScalarLight>(wi, h, rng, counters);
  if (counters_out) counters_out->add(counters);
  return out;
}

template <typename Light>
PhotonOutcome Tracer::trace_with(const Vec3& wi, double h, PhotonRandom& rng,
                                 TracerCounters& counters) const {
  PhotonOutcome out;
  Vec3 d = -wi;
  Light light = make_light<Light>(d);
  Point2 p = ellipse_.entry_point(d, h);
  bool inside = false;
  while (true) {
    if (!scatter_at_boundary(p, d, inside, light, rng, counters, out)) break;  // truncated or lost
    if (!inside) {  // left the fiber
      out.fate = PhotonFate::Exited;
      if (model_ == RoughnessModel::ExitBlur) {
        d = exit_blur_.apply(d, out.segments, rng);
      }
      out.direction = d;
      out.theta = inclination(d);
      out.phi = azimuth(d);
      break;
    }
    if (out.segments == max_segments_) {  // the photon did not leave at the last boundary
      out.fate = PhotonFate::Truncated;
      break;
    }
    const double t = ellipse_.distance_to_boundary(p, d);
    if (!std::isfinite(t)) {  // running exactly along the axis: guided for ever
      out.fate = PhotonFate::Truncated;
      break;
    }
    p = ellipse_.advance(p, d, t);
    out.path_length += t;
    ++out.segments;
  }
  return out;
}

}  // namespace fiberlab::sim
