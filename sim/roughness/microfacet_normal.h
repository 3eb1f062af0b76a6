#pragma once
// The macro normals of a boundary point as one photon sees them, in Eigen
// vectors: the one-photon convenience forms of the microfacet roughness
// models (sim/roughness/microfacet_roughness.h) take them. The tracers use
// life::BoundaryFrame (sim/roughness/roughness_model.h).
#include "common/fiber_frame.h"

namespace fiberlab::sim {

struct BoundaryNormals {
  Vec3 facing;           // n_f: the tilted normal facing the photon's side
  Vec3 untilted_facing;  // n0 (or -n0 inside)
};

}  // namespace fiberlab::sim
