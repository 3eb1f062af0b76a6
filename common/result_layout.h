#pragma once
// Writers and readers for the groups that every fiberlab HDF5 file shares
// (SPEC section 9): /bins and /source. Used by the simulation's result file
// and by `fiberlab predict`.
#include <vector>

#include "common/bin_grid.h"
#include "common/h5_file.h"

namespace fiberlab {

inline constexpr int kFormatVersion = 1;

// /bins/theta_edges, /bins/phi_edges, /bins/solid_angle, and the attribute
// /bins@theta_bins ("uniform" | "equal_area").
void write_bins(h5::File& f, const BinGrid& grid);
BinGrid read_bins(const h5::File& f);

// /source/theta_i and /source/phi_i (radians; phi_i NaN where uniform).
void write_incidences(h5::File& f, const std::vector<double>& theta_i,
                      const std::vector<double>& phi_i);

}  // namespace fiberlab
