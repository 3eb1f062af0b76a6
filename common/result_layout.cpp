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

std::int64_t read_format_version(const h5::File& f, const std::string& path) {
  if (!f.has_attr("/", "format_version"))
    throw Error(fmt::format("{}: root attribute format_version is missing", path));
  const std::int64_t v = f.attr_int("/", "format_version");
  if (v < 1 || v > kFormatVersion)
    throw Error(fmt::format("{}: format_version = {} is not supported (this fiberlab reads 1 to {})",
                            path, v, kFormatVersion));
  return v;
}

bool is_hdf5_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path));
  char magic[8] = {};
  in.read(magic, 8);
  return in.gcount() == 8 && std::string(magic, 8) == std::string("\x89HDF\r\n\x1a\n", 8);
}

std::string file_format(const std::string& path) {
  if (!is_hdf5_file(path)) throw Error(fmt::format("{}: not an HDF5 file (fiberlab files are HDF5)", path));
  const h5::File f = h5::File::open_read(path);
  return f.has_attr("/", "format") ? f.attr_string("/", "format") : std::string();
}

void write_bins(h5::File& f, const BinGrid& grid) {
  if (!f.exists("/bins")) f.create_group("/bins");
  f.write("/bins/theta_edges", {grid.theta_edges.size()}, grid.theta_edges);
  f.write("/bins/phi_edges", {grid.phi_edges.size()}, grid.phi_edges);
  std::vector<double> omega;
  omega.reserve(static_cast<std::size_t>(grid.n_theta()) * grid.n_phi());
  for (int i = 0; i < grid.n_theta(); ++i) {
    const double band = grid.theta_band(i);  // solid_angle(i, j), its band once a row
    for (int j = 0; j < grid.n_phi(); ++j) omega.push_back(band * grid.phi_width(j));
  }
  f.write("/bins/solid_angle",
          {static_cast<hsize_t>(grid.n_theta()), static_cast<hsize_t>(grid.n_phi())}, omega);
  f.set_attr("/bins", "theta_bins", to_string(grid.theta_binning));
}

namespace {

constexpr hsize_t kMaxEdges = (hsize_t{1} << 24) + 1;

void check_edges(const h5::File& f, const std::string& name, const std::vector<double>& edges,
                 double lo, double hi, const char* range) {
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const double e = edges[i];
    if (!std::isfinite(e) || e < lo - 1e-12 || e > hi + 1e-12)
      throw Error(fmt::format("{}: {}[{}] = {} (edges must be finite and in {} radians)", f.path(),
                              name, i, e, range));
    if (i > 0 && !(e > edges[i - 1]))
      throw Error(fmt::format("{}: {}[{}] = {} is not above the previous edge {} (edges must "
                              "increase strictly)", f.path(), name, i, e, edges[i - 1]));
  }
}

std::vector<double> read_edges(const h5::File& f, const std::string& name, hsize_t expected,
                               const std::string& meaning) {
  if (expected > 0) return f.read_doubles(name, {expected}, meaning);
  const h5::Dims dims = f.shape(name);
  if (dims.size() != 1 || dims[0] < 2 || dims[0] > kMaxEdges)
    throw Error(fmt::format("{}: {} must be a one-dimensional array of 2 to {} edges", f.path(),
                            name, kMaxEdges));
  return f.read_doubles(name, dims, "");
}

BinGrid read_checked_bins(const h5::File& f, hsize_t theta_edges, hsize_t phi_edges,
                          const std::string& meaning) {
  BinGrid g;
  g.theta_edges = read_edges(f, "/bins/theta_edges", theta_edges, meaning);
  g.phi_edges = read_edges(f, "/bins/phi_edges", phi_edges, meaning);
  check_edges(f, "/bins/theta_edges", g.theta_edges, -M_PI / 2, M_PI / 2, "[-pi/2, pi/2]");
  check_edges(f, "/bins/phi_edges", g.phi_edges, -M_PI, M_PI, "[-pi, pi]");
  g.theta_binning = ThetaBinning::Uniform;
  if (f.has_attr("/bins", "theta_bins")) {
    const std::string b = f.attr_string("/bins", "theta_bins");
    if (b == "equal_area") g.theta_binning = ThetaBinning::EqualArea;
    else if (b != "uniform")
      throw Error(fmt::format("{}: /bins@theta_bins = \"{}\" (must be uniform or equal_area)",
                              f.path(), b));
  }
  return g;
}

}  // namespace

BinGrid read_bins(const h5::File& f) { return read_checked_bins(f, 0, 0, ""); }

BinGrid read_bins(const h5::File& f, int n_theta, int n_phi, const std::string& meaning) {
  return read_checked_bins(f, static_cast<hsize_t>(n_theta) + 1, static_cast<hsize_t>(n_phi) + 1,
                           meaning);
}

void write_incidences(h5::File& f, const std::vector<double>& theta_i,
                      const std::vector<double>& phi_i) {
  if (!f.exists("/source")) f.create_group("/source");
  f.write("/source/theta_i", {theta_i.size()}, theta_i);
  f.write("/source/phi_i", {phi_i.size()}, phi_i);
}

}  // namespace fiberlab
