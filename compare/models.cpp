#include "compare/models.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "analytic/model_registry.h"
#include "common/error.h"
#include "common/units.h"
#include "compare/report.h"

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

}  // namespace

std::unique_ptr<analytic::Model> make_model(const std::string& name,
                                            const analytic::ModelParameters& params) {
  return analytic::make_model(name, params);
}

std::vector<double> theta_r_shifts(const std::string& name, const analytic::ModelParameters& params) {
  return analytic::theta_r_shifts(name, params);
}

analytic::PhysicalFiber physical_fiber(const sim::Settings& s) {
  analytic::PhysicalFiber f;
  static_cast<Fiber&>(f) = s.fiber;
  f.lobes = s.tally.lobes;
  f.photons = s.photons;
  return f;
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

std::string model_header(const ModelSpec& spec, const analytic::ModelParameters& params,
                         const std::vector<std::string>& fiber_notes) {
  std::string s = fmt::format("model {}: {}\n", spec.label, analytic::describe_params(spec.name, params));
  if (!fiber_notes.empty()) s += "  from the simulated fiber:\n";
  for (const std::string& n : fiber_notes) s += "  - " + n + "\n";
  s += "  approximations in effect:\n";
  for (const std::string& a : analytic::approximations(spec.name, params)) s += "  - " + a + "\n";
  return s;
}

std::string params_json(const std::string& model_name, const analytic::ModelParameters& params) {
  std::string s;
  for (const analytic::ParamSpec& spec : analytic::model_info(model_name).params) {
    // "choice" and "integer" say what kind of value it is, not a unit: a reader
    // prints "absorption = published", not "published choice".
    const bool has_unit = spec.unit != "choice" && spec.unit != "integer";
    s += fmt::format("{}{}: {{\"value\": {}, \"unit\": {}}}", s.empty() ? "" : ", ", json_string(spec.key),
                     json_string(spec.show(params)), json_string(has_unit ? spec.unit : ""));
  }
  return "{" + s + "}";
}

namespace {
// The keys of KEY=VALUE settings.
void add_keys(const std::vector<std::string>& key_values, std::vector<std::string>& keys) {
  for (const std::string& kv : key_values) keys.push_back(trim(kv.substr(0, kv.find('='))));
}
}  // namespace

analytic::ModelParameters params_for(const sim::Settings& s, const ModelSpec& spec,
                                 const std::vector<std::string>& settings,
                                 std::vector<std::string>* fiber_notes) {
  const analytic::ModelInfo& info = analytic::model_info(spec.name);
  auto overrides = [&](analytic::ModelParameters& p) {
    analytic::apply_settings(spec.name, p, settings);
    analytic::apply_settings(spec.name, p, spec.settings);
  };
  analytic::ModelParameters p = analytic::default_params(spec.name);
  overrides(p);
  analytic::FiberMapping mapping;
  add_keys(settings, mapping.user_keys);
  add_keys(spec.settings, mapping.user_keys);
  info.from_fiber(physical_fiber(s), p, mapping);
  overrides(p);
  if (fiber_notes) *fiber_notes = mapping.notes;
  return p;
}

std::vector<double> predict_bins(const analytic::Model& model, const BinGrid& grid, double theta_i,
                                 double phi_i, int lobes, int channels, bool elliptical) {
  if (model.lobes() != lobes)
    throw Error(fmt::format("model {} predicts {} lobes, the histogram has {}", model.name(),
                            model.lobes(), lobes));
  std::vector<double> out;
  if (std::isnan(phi_i) && elliptical) {
    constexpr int kRotations = 32;
    for (int r = 0; r < kRotations; ++r) {
      const std::vector<double> q = model.bin_probabilities(grid, theta_i, (r + 0.5) * kPi / kRotations);
      if (out.empty()) out.assign(q.size(), 0.0);
      for (std::size_t x = 0; x < q.size() && x < out.size(); ++x) out[x] += q[x] / kRotations;
    }
  } else {
    out = model.bin_probabilities(grid, theta_i, std::isnan(phi_i) ? 0.0 : phi_i);
  }
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

std::vector<double> predict_config(const analytic::Model& model, const sim::ResultFile& r, std::size_t k) {
  const bool medulla = r.settings.fiber.medulla.has_value();
  std::vector<double> bins = predict_bins(model, r.grid, r.theta_i.at(k), r.phi_i.at(k),
                                          medulla ? r.lobes - 1 : r.lobes, r.channels,
                                          r.settings.fiber.eccentricity != 1.0);
  if (medulla) bins.resize(r.bin_cells(), 0.0);
  return bins;
}

std::vector<std::vector<double>> predict_result(const analytic::Model& model,
                                                const sim::ResultFile& r, bool parallel) {
  const long K = static_cast<long>(r.configs());
  std::vector<std::vector<double>> out(K);
  std::string error;
#pragma omp parallel for schedule(dynamic) if (parallel && K > 1)
  for (long k = 0; k < K; ++k) {
    try {
      out[k] = predict_config(model, r, static_cast<std::size_t>(k));
    } catch (const std::exception& e) {
#pragma omp critical
      error = e.what();
    }
  }
  if (!error.empty()) throw Error(error);
  return out;
}

}  // namespace fiberlab::compare
