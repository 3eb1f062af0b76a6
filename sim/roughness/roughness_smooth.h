#pragma once
// Roughness model `smooth` (SPEC section 3): m = n_f, or the untilted normal
// when the tilt makes n_f face away from the photon (d.n_f >= 0). Also the
// gaussian model with beta_long = beta_azim = 0 (make_roughness in sim/roughness/roughness_models.h).
#include "sim/roughness/roughness_model.h"
#include "sim/run/settings.h"

namespace fiberlab::sim::life {

struct SmoothRoughness {
  SmoothRoughness() = default;

  template <class T>
  FacetDraw<T> draw_normal(const Vec3Of<T>& d, const BoundaryFrame<T>& frame,
                           const MaskOf<T>& live, LaneRandom<T>& /*rng*/, T& /*tries*/,
                           LifeCounts<T>& /*counts*/, int /*rounds*/) const {
    return {select(d.dot(frame.facing) < T(0.0), frame.facing, frame.untilted_facing), live,
            MaskOf<T>(false)};
  }
};

}  // namespace fiberlab::sim::life
