#pragma once
// The atlas's HDF5 file (format "fiber-atlas", docs/FILE_FORMAT.md): one
// row per fiber, per model a group with the comparison before and after the
// fit and the fitted parameters. Written atomically (common/atomic_output.h).
#include <string>
#include <vector>

#include "compare/atlas.h"

namespace fiberlab::compare {

// F fibers, K = theta_i, L lobes, C = the largest channel count of any
// fiber (fibers with fewer channels are NaN-padded), P = the model's fit keys.
void write_atlas_file(const std::string& path, const AtlasConfig& config,
                      const std::vector<AtlasFiberResult>& fibers);

}  // namespace fiberlab::compare
