// fiberlab.predict from Python: an analytic model's bin probabilities for the
// histogram of a configuration, exactly as `fiberlab predict` makes them
// (app::choose_model and app::predict: the config's defaults, then KEY=VALUE
// overrides in the --set syntax; a medullated fiber's zero `scattered` lobe).
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "app/predict.h"
#include "bindings.h"
#include "common/units.h"
#include "compare/models.h"
#include "sim/run/settings.h"

namespace fiberlab::python {

// A model's parameters by their --set names, in --set's units: angles in
// degrees (the table's unit "deg"), integers as int, choices as text, a
// scalar parameter as a number and a per-lobe or per-channel list as a list;
// so that predict(result, model, **params) gives the same parameters.
py::dict params_dict(const std::string& model_name, const analytic::ModelParameters& params) {
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
  app::ChosenModel chosen;
  compare::PredictionFile pred;
  {
    py::gil_scoped_release release;
    chosen = app::choose_model(s, compare::ModelSpec{model_name, {}, model_name}, sets);
    pred = app::predict(s, chosen);
  }
  const BinGrid& grid = pred.grid;
  const py::ssize_t K = static_cast<py::ssize_t>(pred.configs());
  py::dict d;
  d["probability"] = to_array(pred.probability, {K, pred.lobes, grid.n_theta(), grid.n_phi(), pred.channels});
  d["lobe_names"] = pred.lobe_names();  // `scattered` last for a fiber with a medulla (app::predict pads it)
  d["params"] = params_dict(model_name, chosen.params);
  d["alpha"] = analytic::theta_r_shifts(chosen.spec.name, chosen.params);  // radians, for compare::compare
  d["theta_i"] = to_array(pred.theta_i, {K});
  d["phi_i"] = to_array(pred.phi_i, {K});
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
