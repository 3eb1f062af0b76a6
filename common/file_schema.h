#pragma once
// The self-describing part of fiberlab's HDF5 files (docs/FILE_FORMAT.md):
// what each dataset's axes are, its unit and meaning, and the names of the
// lobes and colour channels. Descriptive attributes only, added beside the
// data every reader already uses; a reader may ignore them.
#include <string>
#include <vector>

#include "common/h5_file.h"

namespace fiberlab {

// Tally lobe names (SPEC s6): lobes 0..L-2 by their paths (R, TT, TRT, TRRT,
// ...), the last one collecting every larger p ("p>=3" for L = 4). With
// `scattered` (a fiber with a medulla, docs/FUR.md) the last of the `lobes`
// is "scattered" and the others are named as for lobes - 1. Called by the
// owners of a lobe axis (sim::ResultFile::lobe_names(), a prediction's, an
// atlas's), which every writer of `lobe_names` and every table takes its
// names from.
std::vector<std::string> lobe_names(int lobes, bool scattered = false);

// Channel names: "R", "G", "B" for a fiber whose sigma_a came from melanin
// (three channels, d'Eon et al. 2011 s6.1), else "c0", "c1", ...
std::vector<std::string> channel_names(int channels, bool from_melanin);

// Comma-separated, as stored in the attributes below; split_names reads
// them back.
std::string join_names(const std::vector<std::string>& names);
std::vector<std::string> split_names(const std::string& joined);

// Dimension labels of a histogram dataset ((K, L, n_theta, n_phi, C) and its
// sub-shapes), as the attribute `dimensions` holds them.
inline constexpr const char* kHistogramDims = "incidence,lobe,theta,phi,channel";
// The per-lobe arrays of a fiber-atlas file (compare/atlas_file.h).
inline constexpr const char* kAtlasDims = "fiber,incidence,lobe,channel";

// Attributes `dimensions` (comma-separated axis names), `units` and
// `description` on the dataset or group `path`.
void describe(h5::File& f, const std::string& path, const std::string& dimensions, const std::string& units,
              const std::string& description);

// A dataset written and described in one place (h5::File::write, then describe).
template <class T>
void write_described(h5::File& f, const std::string& path, const h5::Dims& dims, const std::vector<T>& data,
                     const std::string& dimensions, const std::string& units, const std::string& description) {
  f.write(path, dims, data);
  describe(f, path, dimensions, units, description);
}

// Root attributes `lobe_names` (the axis owner's names, above) and
// `channel_names` (comma-separated).
void write_axis_names(h5::File& f, const std::vector<std::string>& lobe_names, int channels, bool from_melanin);

// Where the bin edges, solid angles and incident directions are: in a
// result or prediction file /bins/... and /source/... (common/result_layout.h
// writes them), in report data at the root (compare/report.h).
struct AxisPaths {
  std::string bins = "/bins/", source = "/source/";
};

// The dimension labels, units and descriptions of theta_edges, phi_edges,
// solid_angle, theta_i and phi_i.
void describe_bins_and_source(h5::File& f, const AxisPaths& at = {});

// Dimension labels, units and descriptions of a result file's /tally and
// /ledger datasets (sim/store/result_file.h writes them), but /tally/photons:
// describe_tally_photons, since the streaming writer (sim/store/result_stream.h)
// describes the others when it creates them and writes the photons last.
void describe_result_datasets(h5::File& f);
void describe_tally_photons(h5::File& f);

// The same for its exact sums, /exact (sim/store/result_stream.h writes them): the
// trailing axis `word` of the 128-bit sums holds (high, low).
void describe_exact_datasets(h5::File& f);

}  // namespace fiberlab
