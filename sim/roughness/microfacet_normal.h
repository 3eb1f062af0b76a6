#pragma once
// The macro normals of a boundary point as one photon sees them (scalar), for
// the microfacet roughness models (sim/roughness/microfacet_roughness.h). The gaussian
// and smooth models, written for both number types, are in
// sim/roughness/roughness_gaussian.h and sim/roughness/roughness_smooth.h.
#include "common/fiber_frame.h"

namespace fiberlab::sim {

struct BoundaryNormals {
  Vec3 facing;           // n_f: the tilted normal facing the photon's side
  Vec3 untilted_facing;  // n0 (or -n0 inside)
};

}  // namespace fiberlab::sim
