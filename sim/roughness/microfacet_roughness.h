#pragma once
// The microfacet roughness models `beckmann` and `ggx` at an interface event
// (SPEC section 3's roughness models, extended):
//
// - The mean normal of the event is the tilted normal n_f facing the photon.
//   In the rare case that the tilt makes n_f face away (d.n_f >= 0) no
//   microfacet about n_f is visible from d, and the untilted facing normal is
//   the mean normal for that event (the `smooth` model's fallback).
// - m is drawn from the distribution of visible normals (VNDF) seen from -d
//   about the mean normal, exactly (sim/roughness/microfacet_distribution.h: Heitz 2018
//   for GGX, Heitz and d'Eon 2014 for Beckmann; no rejection, no cap).
//   alpha_long is the roughness along the fiber axis projected onto the
//   tangent plane, alpha_azim about the axis.
// - Without masking the event conserves energy: the consistency rule (SPEC
//   section 3) draws another event at the same point whenever the scattered
//   direction does not leave on the photon's side.
// - `masking: smith_g1` is the ground truth of Huang et al. 2022 ("A
//   Microfacet-based Hair Scattering Model", EGSR): the usual single-scattering
//   microfacet BSDF sampled through its VNDF, whose sampling weight is
//   F G2 / G1(wi) = F G1(wo) for Smith's uncorrelated G2 = G1(wi) G1(wo)
//   (Heitz 2014, "Understanding the Masking-Shadowing Function", section 6;
//   F is chosen stochastically here, so the weight is G1(wo)). A scattered
//   direction on the wrong side of the mean surface has G1 = 0: the path is
//   killed. The removed weight is the ledger's `lost`: the light a
//   single-scattering microfacet surface does not account for (it would
//   scatter again among the facets).
#include <optional>

#include "common/fiber_frame.h"
#include "sim/roughness/microfacet_distribution.h"
#include "sim/roughness/microfacet_normal.h"
#include "sim/life/random.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

class MicrofacetRoughness {
 public:
  // r.model beckmann or ggx (throws fiberlab::Error otherwise).
  explicit MicrofacetRoughness(const RoughnessSettings& r);

  bool masks() const { return masking_ == Masking::SmithG1; }

  // The mean normal of an event for a photon along d (see the top of this file).
  static Vec3 mean_normal(const Vec3& d, const BoundaryNormals& n) {
    return d.dot(n.facing) < 0.0 ? n.facing : n.untilted_facing;
  }

  // A normal m with d.m < 0 drawn from the VNDF seen from -d about `mean`
  // (two uniforms of rng). Nothing when d does not meet the front of the mean
  // surface (d.mean >= 0, which mean_normal() rules out up to rounding): the
  // caller truncates the photon.
  std::optional<Vec3> sample_normal(const Vec3& d, const Vec3& mean, PhotonRandom& rng) const;

  // Smith's G1 of the scattered direction d_out about `mean`: d_out must leave
  // on the mean normal's side after a reflection, on the other side after a
  // refraction; 0 when it does not (the path is killed).
  double masking_factor(const Vec3& mean, const Vec3& d_out, bool refracted) const;

 private:
  MicrofacetFrame frame(const Vec3& mean) const { return MicrofacetFrame::about(mean, Vec3::UnitX()); }
  MicrofacetDistribution distribution_;
  Masking masking_;
};

}  // namespace fiberlab::sim
