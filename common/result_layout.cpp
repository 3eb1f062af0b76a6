#include "common/result_layout.h"

#include <cmath>

#include "common/error.h"

namespace fiberlab {

void write_bins(h5::File& f, const BinGrid& grid) {
  if (!f.exists("/bins")) f.create_group("/bins");
  f.write("/bins/theta_edges", {grid.theta_edges.size()}, grid.theta_edges);
  f.write("/bins/phi_edges", {grid.phi_edges.size()}, grid.phi_edges);
  std::vector<double> omega;
  omega.reserve(static_cast<std::size_t>(grid.n_theta()) * grid.n_phi());
  for (int i = 0; i < grid.n_theta(); ++i)
    for (int j = 0; j < grid.n_phi(); ++j) omega.push_back(grid.solid_angle(i, j));
  f.write("/bins/solid_angle",
          {static_cast<hsize_t>(grid.n_theta()), static_cast<hsize_t>(grid.n_phi())}, omega);
  f.set_attr("/bins", "theta_bins", to_string(grid.theta_binning));
}

BinGrid read_bins(const h5::File& f) {
  BinGrid g;
  g.theta_edges = f.read_doubles("/bins/theta_edges");
  g.phi_edges = f.read_doubles("/bins/phi_edges");
  if (g.theta_edges.size() < 2 || g.phi_edges.size() < 2)
    throw Error(f.path() + ": /bins holds fewer than two edges");
  g.theta_binning = ThetaBinning::Uniform;
  if (f.has_attr("/bins", "theta_bins") && f.attr_string("/bins", "theta_bins") == "equal_area")
    g.theta_binning = ThetaBinning::EqualArea;
  return g;
}

void write_incidences(h5::File& f, const std::vector<double>& theta_i,
                      const std::vector<double>& phi_i) {
  if (!f.exists("/source")) f.create_group("/source");
  f.write("/source/theta_i", {theta_i.size()}, theta_i);
  f.write("/source/phi_i", {phi_i.size()}, phi_i);
}

}  // namespace fiberlab
