// fiberlab.predict from Python: an analytic model's bin probabilities for the
// histogram of a configuration, exactly as `fiberlab predict` makes them
// (parameters from compare::params_for: the config's defaults, then
// KEY=VALUE overrides in the --set syntax; bins from compare::predict_bins).
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "bindings.h"
#include "common/units.h"
#include "compare/models.h"
#include "sim/run/settings.h"

namespace fiberlab::python {

// A model's parameters by their --set names, in --set's units: angles in
// degrees (the table's unit "deg"), integers as int, choices as text, a
// scalar parameter as a number and a per-lobe or per-channel list as a list;
// so that predict(result, model, **params) gives the same parameters.
py::dict params_dict(const std::string& model_name, const analytic::ModelParams& params) {
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  const std::vector<analytic::ParamAttribute> values = analytic::param_attributes(model_name, params);
  py::dict out;
  for (std::size_t i = 0; i < table.size() && i < values.size(); ++i) {
    const analytic::ParamSpec& spec = table[i];
    const analytic::ParamAttribute& a = values[i];
    const py::str key(a.name);
    if (a.is_text) {
      out[key] = a.text;
    } else if (spec.unit == "integer" && a.numbers.size() == 1) {
      out[key] = static_cast<long long>(a.numbers[0]);
    } else {
      std::vector<double> x = a.numbers;
      if (spec.unit == "deg")
        for (double& v : x) v = rad_to_deg(v);
      if (spec.get_number && x.size() == 1) out[key] = x[0];  // a scalar parameter
      else out[key] = x;
    }
  }
  return out;
}

namespace {

py::dict predict(const sim::Settings& s, const std::string& model_name, const std::vector<std::string>& sets) {
  const compare::ModelSpec spec{model_name, {}, model_name};
  const analytic::ModelParams params = compare::params_for(s, spec, sets);
  const BinGrid grid = BinGrid::make(s.tally.n_theta, s.tally.n_phi, s.tally.theta_bins);
  const std::vector<sim::Settings::Incidence> inc = s.incidences();
  const int L = params.lobes, C = static_cast<int>(params.sigma_a.size());
  std::vector<double> probability, theta_i, phi_i;
  {
    py::gil_scoped_release release;
    const auto model = compare::make_model(spec.name, params);
    for (const sim::Settings::Incidence& x : inc) {
      const std::vector<double> p = compare::predict_bins(*model, grid, x.theta_i, x.phi_i, L, C,
                                                          s.fiber.eccentricity != 1.0);
      probability.insert(probability.end(), p.begin(), p.end());
      theta_i.push_back(x.theta_i);
      phi_i.push_back(x.phi_i);
    }
  }
  const py::ssize_t K = static_cast<py::ssize_t>(inc.size());
  py::dict d;
  d["probability"] = to_array(probability, {K, L, grid.n_theta(), grid.n_phi(), C});
  d["params"] = params_dict(spec.name, params);
  d["alpha"] = params.alpha;  // radians, for compare::compare
  d["theta_i"] = to_array(theta_i, {K});
  d["phi_i"] = to_array(phi_i, {K});
  d["theta_edges"] = to_array(grid.theta_edges, {grid.n_theta() + 1});
  d["phi_edges"] = to_array(grid.phi_edges, {grid.n_phi() + 1});
  return d;
}

}  // namespace

void bind_prediction(py::module_& m) {
  m.def("param_units", [](const std::string& model) {
    py::dict units;  // --set key -> "deg", "integer", "choice", "1/R", "" (analytic/model_params.h)
    for (const analytic::ParamSpec& spec : analytic::model_info(model).params) units[py::str(spec.key)] = spec.unit;
    return units;
  }, py::arg("model"), "The unit of each of the model's parameters");
  m.def("predict", &predict, py::arg("settings"), py::arg("model"), py::arg("settings_overrides"),
        "Bin probabilities (K, L, n_theta, n_phi, C) of `model` for `settings`, with KEY=VALUE overrides");
}

}  // namespace fiberlab::python
