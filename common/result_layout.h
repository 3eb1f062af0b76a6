#pragma once
// Writers and readers for the groups that every fiberlab HDF5 file shares
// (SPEC section 9): /bins and /source. Used by the simulation's result file
// and by `fiberlab predict`.
#include <string>
#include <vector>

#include "common/bin_grid.h"
#include "common/h5_file.h"

namespace fiberlab {

// 2: a result file's exact bin sums are residuals against the float64 sums
// (sim/store/result_stream.h); 1 stored them as (high, low) pairs.
inline constexpr int kFormatVersion = 2;

// The current time as ISO 8601 UTC, e.g. 2026-11-22T10:30:00Z.
std::string utc_timestamp();

// The root attributes every fiberlab file carries: format (the file type,
// e.g. "fiber-histogram"), format_version, software_version, created_utc.
void write_file_identity(h5::File& f, const std::string& format, const std::string& created_utc);
// The file's format_version, 1 to kFormatVersion; throws fiberlab::Error
// naming `path` when it is missing or another.
std::int64_t read_format_version(const h5::File& f, const std::string& path);

// Whether `path` starts with the HDF5 signature. Throws fiberlab::Error when
// it cannot be read.
bool is_hdf5_file(const std::string& path);

// The root attribute `format` of an HDF5 file (the kind, docs/FILE_FORMAT.md),
// "" when it has none. Throws fiberlab::Error naming `path` when it is not
// an HDF5 file or cannot be read.
std::string file_format(const std::string& path);

// /bins/theta_edges, /bins/phi_edges, /bins/solid_angle, and the attribute
// /bins@theta_bins ("uniform" | "equal_area").
void write_bins(h5::File& f, const BinGrid& grid);
// Checked before use: each edge array one-dimensional with 2 to 2^24 + 1
// values (shape read before the data), finite, strictly increasing, theta
// within [-pi/2, pi/2] and phi within [-pi, pi]; theta_bins, when present,
// "uniform" or "equal_area". Errors name the file and the dataset.
BinGrid read_bins(const h5::File& f);
// The same, with the edge counts required to be n_theta + 1 and n_phi + 1.
BinGrid read_bins(const h5::File& f, int n_theta, int n_phi, const std::string& meaning);

// /source/theta_i and /source/phi_i (radians; phi_i NaN where uniform).
void write_incidences(h5::File& f, const std::vector<double>& theta_i,
                      const std::vector<double>& phi_i);

}  // namespace fiberlab
