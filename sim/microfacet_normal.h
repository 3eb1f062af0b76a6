#pragma once
// Drawing the normal m that an interface event reflects or refracts about
// (SPEC section 3, roughness models `smooth` and `gaussian`).
#include <optional>

#include "common/fiber_frame.h"
#include "sim/random.h"

namespace fiberlab::sim {

// The macro normal of the boundary point as the photon sees it.
struct BoundaryNormals {
  Vec3 facing;          // n_f: the tilted normal facing the photon's side
  Vec3 untilted_facing; // n0 (or -n0 inside): the fallback of the smooth model
};

// `smooth`: m = n_f, or the untilted normal when the tilt makes n_f face away
// from the photon (d.n_f >= 0).
Vec3 smooth_normal(const Vec3& d, const BoundaryNormals& n);

// `gaussian`: n_f rotated by dl ~ N(0, beta_long^2) towards +u in the plane of
// n_f and u, then by da ~ N(0, beta_azim^2) about u; a candidate is accepted
// with probability max(0, -d.m) (visible normals), drawing until accepted.
// Returns nothing when `max_tries` candidates were all rejected (the caller
// tallies the photon as truncated). `tries` counts the candidates drawn.
// beta_long = beta_azim = 0 is not handled here: it is the `smooth` model
// (SPEC section 3), which the tracers use instead.
std::optional<Vec3> gaussian_normal(const Vec3& d, const Vec3& n_facing, double beta_long,
                                    double beta_azim, PhotonRandom& rng, int max_tries,
                                    long& tries);

// When the tilted normal faces away from the photon by an angle eps =
// asin(d.n_f) of at least kFarTailSigmas times the larger beta, every visible
// normal lies in the far tail of the Gaussian and gaussian_normal switches to
// a sampler of that tail (see microfacet_normal.cpp). far_tail_threshold(b)
// is the d.n_f from which it does: sin(kFarTailSigmas b), or 2 (never) when
// that angle reaches pi/2.
inline constexpr double kFarTailSigmas = 1.0;
double far_tail_threshold(double beta_max);

}  // namespace fiberlab::sim
