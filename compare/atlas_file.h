#pragma once
// The atlas's HDF5 file (format "fiber-atlas", docs/FILE_FORMAT.md): one
// row per fiber, per model a group with the comparison before and after the
// fit and the fitted parameters (with fit.per_lobe, also each lobe's own fit
// and the comparison after it). Written atomically (common/atomic_output.h).
#include <string>
#include <vector>

#include "common/h5_file.h"
#include "compare/atlas.h"

namespace fiberlab::compare {

// Root lobe_names and channel_names of an atlas file or checkpoint
// (docs/FILE_FORMAT.md): the config's lobes, and as many channels as the
// fiber with the most (R, G, B when every fiber's absorption came from
// melanin concentrations, else c0, c1, ...).
void write_atlas_axis_names(h5::File& f, const AtlasConfig& config);

// F fibers, K = theta_i, L lobes, C = the largest channel count of any
// fiber (fibers with fewer channels are NaN-padded), P = the model's fit keys.
void write_atlas_file(const std::string& path, const AtlasConfig& config,
                      const std::vector<AtlasFiberResult>& fibers);

// What `fiberlab info` prints for an atlas file (or the report_data.h5 of
// `atlas --report`, its copy): fibers, incident directions, lobes, channels,
// and per model how many fibers it applied to, was fitted to, converged on.
std::string describe_atlas_file(const std::string& path);

}  // namespace fiberlab::compare
