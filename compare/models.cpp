#include "compare/models.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "analytic/deon2011.h"
#include "analytic/marschner2003.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/units.h"
#include "compare/model_defaults.h"

namespace fiberlab::compare {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, sep)) out.push_back(trim(part));
  return out;
}

double parse_number(const std::string& key, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw Error(fmt::format("--set {}={}: '{}' is not a number", key, text, text));
  return v;
}

std::vector<double> parse_list(const std::string& key, const std::string& text, double scale) {
  std::vector<double> out;
  for (const std::string& item : split(text, ',')) out.push_back(parse_number(key, item) * scale);
  if (out.empty()) throw Error(fmt::format("--set {}: empty list", key));
  return out;
}

}  // namespace

// Fallback implementations (used until analytic/ provides the factory and
// the --set parser; see the reply of issue 4). Names and keys follow
// analytic/model.h's ModelParams comments.
std::unique_ptr<analytic::Model> make_model(const std::string& name,
                                            const analytic::ModelParams& params) {
  if (name == "exact") return analytic::make_smooth_cylinder(params);
  if (name == "deon2011") return analytic::make_deon2011(params);
  if (name == "marschner2003") return analytic::make_marschner2003(params);
  throw Error(fmt::format("unknown model '{}' (allowed: exact, deon2011, marschner2003)", name));
}

void apply_setting(analytic::ModelParams& p, const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos)
    throw Error(fmt::format("--set '{}': expected KEY=VALUE", key_value));
  const std::string key = trim(key_value.substr(0, eq)), value = trim(key_value.substr(eq + 1));
  const double deg = kPi / 180.0;
  if (key == "eta") {
    p.eta = parse_number(key, value);
    if (!(p.eta > 1.0)) throw Error(fmt::format("--set eta={}: must be > 1", value));
  } else if (key == "sigma_a") {
    p.sigma_a = parse_list(key, value, 1.0);
  } else if (key == "beta_long") {
    p.beta_long = parse_list(key, value, deg);
  } else if (key == "beta_azim") {
    p.beta_azim = parse_list(key, value, deg);
  } else if (key == "alpha") {
    p.alpha = parse_list(key, value, deg);
  } else if (key == "eccentricity") {
    p.eccentricity = parse_number(key, value);
  } else if (key == "lobes") {
    p.lobes = static_cast<int>(parse_number(key, value));
  } else if (key == "absorption") {
    if (value == "published") p.absorption = analytic::Absorption::Published;
    else if (value == "chord") p.absorption = analytic::Absorption::Chord;
    else throw Error(fmt::format("--set absorption={}: allowed published|chord", value));
  } else if (key == "longitudinal") {
    if (value == "theta_h") p.two_theta_h = false;
    else if (value == "two_theta_h") p.two_theta_h = true;
    else throw Error(fmt::format("--set longitudinal={}: allowed theta_h|two_theta_h", value));
  } else if (key == "roots") {
    if (value == "cubic") p.exact_roots = false;
    else if (value == "exact") p.exact_roots = true;
    else throw Error(fmt::format("--set roots={}: allowed cubic|exact", value));
  } else if (key == "r_fresnel") {
    if (value == "half_angle") p.r_half_angle_fresnel = true;
    else if (value == "per_h") p.r_half_angle_fresnel = false;
    else throw Error(fmt::format("--set r_fresnel={}: allowed half_angle|per_h", value));
  } else if (key == "k_g") {
    p.k_g = parse_number(key, value);
  } else if (key == "w_c") {
    p.w_c = parse_number(key, value) * deg;
  } else if (key == "delta_eta") {
    p.delta_eta = parse_number(key, value);
  } else if (key == "delta_h_m") {
    p.delta_h_m = parse_number(key, value);
  } else if (key == "quadrature_order") {
    p.quadrature_order = static_cast<int>(parse_number(key, value));
  } else {
    throw Error(fmt::format("--set {}: unknown key", key));
  }
}

ModelSpec parse_model_spec(const std::string& spec) {
  ModelSpec m;
  m.label = spec;
  const std::vector<std::string> parts = split(spec, ':');
  if (parts.empty() || parts[0].empty()) throw Error(fmt::format("model '{}': no name", spec));
  m.name = parts[0];
  for (std::size_t i = 1; i < parts.size(); ++i) m.settings.push_back(parts[i]);
  return m;
}

analytic::ModelParams params_for(const sim::Settings& s, const ModelSpec& spec,
                                 const std::vector<std::string>& settings) {
  analytic::ModelParams p = model_params_from_settings(s, spec.name);
  for (const std::string& kv : settings) apply_setting(p, kv);
  for (const std::string& kv : spec.settings) apply_setting(p, kv);
  return p;
}

std::vector<double> predict_bins(const analytic::Model& model, const BinGrid& grid, double theta_i,
                                 double phi_i, int lobes, int channels) {
  if (model.lobes() != lobes)
    throw Error(fmt::format("model {} predicts {} lobes, the histogram has {}", model.name(),
                            model.lobes(), lobes));
  std::vector<double> out = model.bin_probabilities(grid, theta_i, std::isnan(phi_i) ? 0.0 : phi_i);
  const std::size_t expect = static_cast<std::size_t>(lobes) * grid.n_theta() * grid.n_phi() * channels;
  if (out.size() != expect)
    throw Error(fmt::format("model {} gives {} channels, the histogram has {} (set sigma_a with one "
                            "value per channel)",
                            model.name(), out.size() / (static_cast<std::size_t>(lobes) * grid.n_theta() * grid.n_phi()),
                            channels));
  return out;
}

}  // namespace fiberlab::compare

namespace fiberlab::compare {

std::vector<std::vector<double>> predict_result(const analytic::Model& model,
                                                const sim::ResultFile& r, bool parallel) {
  const long K = static_cast<long>(r.configs());
  std::vector<std::vector<double>> out(K);
  std::string error;
#pragma omp parallel for schedule(dynamic) if (parallel && K > 1)
  for (long k = 0; k < K; ++k) {
    try {
      out[k] = predict_bins(model, r.grid, r.theta_i[k], r.phi_i[k], r.lobes, r.channels);
    } catch (const std::exception& e) {
#pragma omp critical
      error = e.what();
    }
  }
  if (!error.empty()) throw Error(error);
  return out;
}

}  // namespace fiberlab::compare
