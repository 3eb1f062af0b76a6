#include "common/result_layout.h"

#include <fmt/core.h>

#include <cmath>
#include <ctime>
#include <fstream>

#include "common/error.h"

namespace fiberlab {

std::string utc_timestamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void write_file_identity(h5::File& f, const std::string& format, const std::string& created_utc) {
  f.set_attr("/", "format", format);
  f.set_attr("/", "format_version", static_cast<std::int64_t>(kFormatVersion));
  f.set_attr("/", "software_version", std::string(FIBERLAB_VERSION));
  f.set_attr("/", "created_utc", created_utc);
}

bool is_hdf5_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path));
  char magic[8] = {};
  in.read(magic, 8);
  return in.gcount() == 8 && std::string(magic, 8) == std::string("\x89HDF\r\n\x1a\n", 8);
}

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
