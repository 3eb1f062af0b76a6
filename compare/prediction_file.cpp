#include "compare/prediction_file.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "analytic/model_registry.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/comparison.h"
#include "compare/verdict_tables.h"

namespace fiberlab::compare {

namespace {

constexpr double kAngleTolerance = 1e-9;  // radians: edges and directions written as float64

void require(const h5::File& f, const std::string& name) {
  if (!f.exists(name))
    throw Error(fmt::format("{}: prediction file without {} (see docs/FILE_FORMAT.md, fiber-prediction)", f.path(),
                            name));
}

bool same_angle(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= kAngleTolerance;
}

void check_edges(const std::string& name, const std::vector<double>& e, const std::string& path) {
  if (e.size() < 2) throw Error(fmt::format("{}: {} holds fewer than two edges", path, name));
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!std::isfinite(e[i])) throw Error(fmt::format("{}: {}[{}] is not finite", path, name, i));
    if (i > 0 && !(e[i] > e[i - 1]))
      throw Error(fmt::format("{}: {} is not strictly increasing at index {}", path, name, i));
  }
}

std::string split_lines_joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += "  - " + l + "\n";
  return s;
}

}  // namespace

void write_prediction(const std::string& path, const PredictionFile& p, const sim::Settings& settings,
                      const analytic::ModelParameters& params, const std::vector<std::string>& inputs) {
  AtomicOutput out(path, inputs);
  {
    h5::File f = h5::File::create(out.temp_path(), out.target());
    write_file_identity(f, "fiber-prediction", utc_timestamp());
    f.set_attr("/", "config_yaml", sim::to_yaml(settings));
    write_axis_names(f, p.lobe_names(), p.channels, settings.fiber.eumelanin.has_value());
    write_bins(f, p.grid);
    write_incidences(f, p.theta_i, p.phi_i);
    describe_bins_and_source(f);
    f.create_group("/prediction");
    const auto h = [](auto n) { return static_cast<hsize_t>(n); };
    f.write_finite("/prediction/probability",
                   {h(p.configs()), h(p.lobes), h(p.grid.n_theta()), h(p.grid.n_phi()), h(p.channels)},
                   p.probability);
    describe(f, "/prediction/probability", kHistogramDims, "probability",
             "the model's probability of each bin (its density integrated over the bin)");
    f.set_attr("/prediction", "model", p.model);
    std::string approx;
    for (const std::string& a : analytic::approximations(p.model, params)) approx += a + "\n";
    f.set_attr("/prediction", "approximations", approx);
    // Only this model's parameters (its table), angles in radians.
    for (const analytic::ParamAttribute& a : analytic::param_attributes(p.model, params)) {
      if (a.is_text) f.set_attr("/prediction", a.name, a.text);
      else if (a.numbers.size() == 1) f.set_attr("/prediction", a.name, a.numbers[0]);
      else f.set_attr("/prediction", a.name, a.numbers);
    }
    f.close();
  }
  out.commit();
}

bool is_prediction_file(const std::string& path) {
  try {
    if (!is_hdf5_file(path)) return false;
    const h5::File f = h5::File::open_read(path);
    return f.has_attr("/", "format") && f.attr_string("/", "format") == "fiber-prediction";
  } catch (const std::exception&) {
    return false;
  }
}

namespace {

// Everything but the probabilities, whose shape is taken from the dataset's
// declaration (nothing allocated for it yet).
PredictionFile read_header(const h5::File& f, const std::string& path, h5::Dims& dims) {
  if (!f.has_attr("/", "format") || f.attr_string("/", "format") != "fiber-prediction")
    throw Error(fmt::format("{}: not a prediction file (root attribute format is not \"fiber-prediction\")", path));
  for (const char* name : {"/bins/theta_edges", "/bins/phi_edges", "/source/theta_i", "/source/phi_i",
                           "/prediction/probability"})
    require(f, name);
  PredictionFile p;
  p.path = path;
  if (f.has_attr("/prediction", "model")) p.model = f.attr_string("/prediction", "model");
  if (f.has_attr("/", "format_version")) p.format_version = std::to_string(f.attr_int("/", "format_version"));
  if (f.has_attr("/prediction", "approximations")) {
    const std::string text = f.attr_string("/prediction", "approximations");
    std::size_t start = 0;
    while (start < text.size()) {
      const auto nl = text.find('\n', start);
      const std::string line = text.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
      if (!line.empty()) p.approximations.push_back(line);
      if (nl == std::string::npos) break;
      start = nl + 1;
    }
  }
  p.grid.theta_edges = f.read_doubles("/bins/theta_edges");
  p.grid.phi_edges = f.read_doubles("/bins/phi_edges");
  check_edges("/bins/theta_edges", p.grid.theta_edges, path);
  check_edges("/bins/phi_edges", p.grid.phi_edges, path);
  p.theta_i = f.read_doubles("/source/theta_i");
  p.phi_i = f.read_doubles("/source/phi_i");
  if (p.theta_i.empty()) throw Error(fmt::format("{}: /source/theta_i is empty", path));
  if (p.phi_i.size() != p.theta_i.size())
    throw Error(fmt::format("{}: /source/phi_i has {} entries, /source/theta_i {}", path, p.phi_i.size(),
                            p.theta_i.size()));
  dims = f.shape("/prediction/probability");
  if (dims.size() != 5)
    throw Error(fmt::format("{}: /prediction/probability has {} dimensions; expected 5 "
                            "(K x lobes x n_theta x n_phi x channels)", path, dims.size()));
  const std::size_t nt = p.grid.theta_edges.size() - 1, np = p.grid.phi_edges.size() - 1;
  if (dims[0] != p.theta_i.size() || dims[2] != nt || dims[3] != np || dims[1] < 1 || dims[4] < 1 ||
      dims[1] > 1000000 || dims[4] > 1000000)
    throw Error(fmt::format("{}: /prediction/probability is {} x {} x {} x {} x {}; expected {} (incident "
                            "directions) x lobes x {} x {} (bins) x channels",
                            path, dims[0], dims[1], dims[2], dims[3], dims[4], p.theta_i.size(), nt, np));
  p.lobes = static_cast<int>(dims[1]);
  p.channels = static_cast<int>(dims[4]);
  // A medullated fiber's prediction names its zero last lobe `scattered` (write_prediction).
  if (f.has_attr("/", "lobe_names")) {
    const std::string names = f.attr_string("/", "lobe_names");
    const std::string last = "scattered";
    p.scattered = p.lobes > 1 && names.size() >= last.size() &&
                  names.compare(names.size() - last.size(), last.size(), last) == 0;
  }
  return p;
}

void read_probabilities(const h5::File& f, PredictionFile& p, const h5::Dims& dims) {
  p.probability = f.read_doubles("/prediction/probability", dims, "the file's own bins, directions, lobes and channels");
  check_probabilities(p.probability.data(), p.probability.size(), p.path + ": /prediction/probability");
}

// The result's bins, incident directions, lobes and channels, or the first mismatch.
void check_matches(const PredictionFile& p, const sim::ResultFile& r, const std::string& result_path) {
  auto mismatch = [&](const std::string& what) {
    return Error(fmt::format("{} does not match {}: {}", p.path, result_path, what));
  };
  if (p.grid.n_theta() != r.grid.n_theta())
    throw mismatch(fmt::format("{} theta bins, the result has {}", p.grid.n_theta(), r.grid.n_theta()));
  if (p.grid.n_phi() != r.grid.n_phi())
    throw mismatch(fmt::format("{} phi bins, the result has {}", p.grid.n_phi(), r.grid.n_phi()));
  for (std::size_t i = 0; i < p.grid.theta_edges.size(); ++i)
    if (!same_angle(p.grid.theta_edges[i], r.grid.theta_edges[i]))
      throw mismatch(fmt::format("/bins/theta_edges[{}] = {:.9g}, the result's is {:.9g}", i,
                                 p.grid.theta_edges[i], r.grid.theta_edges[i]));
  for (std::size_t i = 0; i < p.grid.phi_edges.size(); ++i)
    if (!same_angle(p.grid.phi_edges[i], r.grid.phi_edges[i]))
      throw mismatch(fmt::format("/bins/phi_edges[{}] = {:.9g}, the result's is {:.9g}", i,
                                 p.grid.phi_edges[i], r.grid.phi_edges[i]));
  if (p.configs() != r.configs())
    throw mismatch(fmt::format("{} incident directions, the result has {}", p.configs(), r.configs()));
  for (std::size_t k = 0; k < p.configs(); ++k)
    if (!same_angle(p.theta_i[k], r.theta_i[k]) || !same_angle(p.phi_i[k], r.phi_i[k]))
      throw mismatch(fmt::format("incident direction {} is ({}), the result's is ({})", k,
                                 incidence_label(p.theta_i[k], p.phi_i[k]),
                                 incidence_label(r.theta_i[k], r.phi_i[k])));
  if (p.lobes != r.lobes) throw mismatch(fmt::format("{} lobes, the result has {}", p.lobes, r.lobes));
  if (p.channels != r.channels)
    throw mismatch(fmt::format("{} channels, the result has {}", p.channels, r.channels));
}

}  // namespace

void check_probabilities(const double* p, std::size_t n, const std::string& origin) {
  for (std::size_t i = 0; i < n; ++i)
    if (!(p[i] >= -kProbabilityRounding) || !std::isfinite(p[i]))
      throw Error(fmt::format("{} holds {} at flat index {} (probabilities must be finite and >= 0; "
                              "down to -{:g} is taken as rounding)",
                              origin, p[i], i, kProbabilityRounding));
}

PredictionFile read_prediction(const std::string& path) {
  if (!is_hdf5_file(path)) throw Error(fmt::format("{}: not an HDF5 file", path));
  const h5::File f = h5::File::open_read(path);
  h5::Dims dims;
  PredictionFile p = read_header(f, path, dims);
  read_probabilities(f, p, dims);
  return p;
}

PredictionFile read_prediction_for(const std::string& path, const sim::ResultFile& result,
                                   const std::string& result_path) {
  if (!is_hdf5_file(path)) throw Error(fmt::format("{}: not an HDF5 file", path));
  const h5::File f = h5::File::open_read(path);
  h5::Dims dims;
  PredictionFile p = read_header(f, path, dims);
  check_matches(p, result, result_path);
  read_probabilities(f, p, dims);
  return p;
}

std::vector<std::vector<double>> prediction_bins_for(const PredictionFile& p, const sim::ResultFile& r,
                                                     const std::string& result_path) {
  check_matches(p, r, result_path);
  std::vector<std::vector<double>> out(p.configs());
  const std::size_t n = p.per_config();
  for (std::size_t k = 0; k < p.configs(); ++k)
    out[k].assign(p.probability.begin() + static_cast<std::ptrdiff_t>(k * n),
                  p.probability.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
  return out;
}

std::string describe_prediction(const PredictionFile& p) {
  std::string s = fmt::format("{}: fiberlab prediction, model {}{}\n", p.path, p.model.empty() ? "(not named)" : p.model,
                              p.format_version.empty() ? "" : ", format_version " + p.format_version);
  s += fmt::format("bins: {} x {} (theta x phi), {} lobes, {} channel(s), {} incident direction(s)\n",
                   p.grid.n_theta(), p.grid.n_phi(), p.lobes, p.channels, p.configs());
  if (!p.approximations.empty()) s += "approximations in effect:\n" + split_lines_joined(p.approximations);
  const std::vector<std::string> lobe_names = p.lobe_names();
  for (std::size_t k = 0; k < p.configs(); ++k) {
    s += incidence_label(p.theta_i[k], p.phi_i[k]) + ":";
    for (int l = 0; l < p.lobes; ++l) {
      s += fmt::format("  {}", lobe_names.at(static_cast<std::size_t>(l)));
      for (int c = 0; c < p.channels; ++c) {
        double e = 0.0;
        const std::size_t cells = static_cast<std::size_t>(p.grid.n_theta()) * p.grid.n_phi();
        for (std::size_t b = 0; b < cells; ++b)
          e += p.probability[((k * p.lobes + l) * cells + b) * p.channels + c];
        s += fmt::format(" {:.6f}", e);
      }
    }
    s += "\n";
  }
  return s;
}

}  // namespace fiberlab::compare
