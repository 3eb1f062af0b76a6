// fiberlab.predict from Python: an analytic model's bin probabilities for the
// histogram of a configuration, exactly as `fiberlab predict` makes them
// (parameters from compare::params_for: the config's defaults, then
// KEY=VALUE overrides in the --set syntax; bins from compare::predict_bins).
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "bindings.h"
#include "compare/models.h"
#include "sim/settings.h"

namespace fiberlab::python {

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
  py::dict params_out;  // the model's parameters by their --set names; angles in radians
  for (const analytic::ParamAttribute& a : analytic::param_attributes(spec.name, params)) {
    if (a.is_text) params_out[py::str(a.name)] = a.text;
    else if (a.numbers.size() == 1) params_out[py::str(a.name)] = a.numbers[0];
    else params_out[py::str(a.name)] = a.numbers;
  }
  const py::ssize_t K = static_cast<py::ssize_t>(inc.size());
  py::dict d;
  d["probability"] = to_array(probability, {K, L, grid.n_theta(), grid.n_phi(), C});
  d["params"] = params_out;
  d["alpha"] = params.alpha;
  d["theta_i"] = to_array(theta_i, {K});
  d["phi_i"] = to_array(phi_i, {K});
  d["theta_edges"] = to_array(grid.theta_edges, {grid.n_theta() + 1});
  d["phi_edges"] = to_array(grid.phi_edges, {grid.n_phi() + 1});
  return d;
}

}  // namespace

void bind_prediction(py::module_& m) {
  m.def("predict", &predict, py::arg("settings"), py::arg("model"), py::arg("settings_overrides"),
        "Bin probabilities (K, L, n_theta, n_phi, C) of `model` for `settings`, with KEY=VALUE overrides");
}

}  // namespace fiberlab::python
