#pragma once
// The microfacet roughness models `beckmann` and `ggx` at an interface event
// (SPEC section 3's roughness models, extended), for one photon or a vector
// of photons (sim/simd/lanes.h number types):
//
// - The mean normal of the event is the tilted normal n_f facing the photon.
//   In the rare case that the tilt makes n_f face away (d.n_f >= 0) no
//   microfacet about n_f is visible from d, and the untilted facing normal is
//   the mean normal for that event (the `smooth` model's fallback).
// - m is drawn from the distribution of visible normals (VNDF) seen from -d
//   about the mean normal, exactly (sim/roughness/microfacet_lanes.h: Heitz 2018
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
#include "sim/roughness/microfacet_lanes.h"
#include "sim/roughness/microfacet_normal.h"
#include "sim/life/random.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {

class MicrofacetRoughness {
 public:
  MicrofacetRoughness(MicrofacetModel model, const roughness::MicrofacetAlpha& r);

  bool masks() const { return masking_ == Masking::SmithG1; }

  // The mean normal of an event for photons along d (see the top of this file).
  template <class T>
  static life::Vec3Of<T> mean_normal(const life::Vec3Of<T>& d, const life::Vec3Of<T>& facing,
                                     const life::Vec3Of<T>& untilted_facing) {
    return select(d.dot(facing) < T(0.0), facing, untilted_facing);
  }

  // A normal m drawn from the VNDF seen from -d about `mean` from the
  // uniforms (u1, u2), in the lanes of `live`. `ok`: the lanes where d meets
  // the front of the mean surface (d.mean < 0, which mean_normal() gives up
  // to rounding) and m has d.m < 0 (d.m = 0, a facet seen exactly edge-on,
  // has probability zero up to rounding); the caller truncates the others.
  template <class T>
  life::Vec3Of<T> sample_normal(const life::Vec3Of<T>& d, const life::Vec3Of<T>& mean, const T& u1,
                                const T& u2, const life::MaskOf<T>& live,
                                life::MaskOf<T>& ok) const {
    const auto frame = life::MicrofacetFrameOf<T>::about(mean);
    const life::Vec3Of<T> w = frame.to_local(-d);
    const life::MaskOf<T> front = live & (w.z > T(0.0));
    const life::Vec3Of<T> m = frame.to_world(life::microfacet_visible_normal(
        distribution_.model(), w, distribution_.alpha_long(), distribution_.alpha_azim(), u1, u2,
        front));
    ok = front & (d.dot(m) < T(0.0));
    return m;
  }

  // Smith's G1 of the scattered direction d_out about `mean`: d_out must leave
  // on the mean normal's side after a reflection, on the other side after a
  // refraction; 0 when it does not (the path is killed). A refracted
  // direction is judged from the other side of the mean surface, as -d_out
  // (Lambda depends on w_x, w_y only through their squares).
  template <class T>
  T masking_factor(const life::Vec3Of<T>& mean, const life::Vec3Of<T>& d_out,
                   const life::MaskOf<T>& refracted) const {
    const auto frame = life::MicrofacetFrameOf<T>::about(mean);
    return life::microfacet_g1(distribution_.model(), frame.to_local(select(refracted, -d_out, d_out)),
                               distribution_.alpha_long(), distribution_.alpha_azim());
  }

  // One photon in Eigen vectors (tests): the same, with two uniforms of rng.
  static Vec3 mean_normal(const Vec3& d, const BoundaryNormals& n);
  std::optional<Vec3> sample_normal(const Vec3& d, const Vec3& mean, PhotonRandom& rng) const;
  double masking_factor(const Vec3& mean, const Vec3& d_out, bool refracted) const;

 private:
  MicrofacetDistribution distribution_;
  Masking masking_;
};

}  // namespace fiberlab::sim
