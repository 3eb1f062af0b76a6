// fiberlab.fit from Python: the fit of `fiberlab compare --fit`
// (compare::fit_model, compare/fit.h) on a result, started from the model's
// parameters for the result's fiber (compare::params_for with --set style
// overrides), with the verdict before and after it (compare::judge), as the
// CLI prints them. The GIL is released during the fit; between iterations
// the progress callable (if any) gets the CLI's progress line and pending
// Python signals are handled (Ctrl-C stops a fit at the next iteration with
// KeyboardInterrupt).
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <set>

#include "analytic/model_registry.h"
#include "bindings.h"
#include "common/error.h"
#include "compare/fit.h"
#include "compare/models.h"
#include "sim/store/result_file.h"

namespace fiberlab::python {

namespace {

// Thrown through compare::fit_model from its progress callback when Python
// has an exception to raise (the error itself is kept with the GIL held).
struct StopFit {};

class FitProgress {
 public:
  explicit FitProgress(py::object progress) : progress_(std::move(progress)) {}

  std::function<void(const std::string&)> callback() {
    return [this](const std::string& line) {
      py::gil_scoped_acquire acquire;
      try {
        if (!progress_.is_none()) progress_(line);
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      } catch (py::error_already_set& e) {
        error_ = std::make_unique<py::error_already_set>(std::move(e));
        throw StopFit{};
      }
    };
  }
  [[noreturn]] void rethrow() { throw std::move(*error_); }

 private:
  py::object progress_;
  std::unique_ptr<py::error_already_set> error_;
};

py::dict fit(const sim::ResultFile& result, const std::string& model_name, const std::vector<std::string>& keys,
             const std::vector<std::string>& sets, std::optional<double> max_chi2, double min_effective,
             double model_error, double min_energy, int max_iterations, const std::vector<std::string>& lobes,
             py::object progress) {
  compare::Options o = comparison_options(max_chi2, min_effective, model_error, min_energy);
  if (!lobes.empty()) o.lobes = compare::parse_fit_lobes(lobes, result.lobes, "lobes");
  if (max_iterations < 1) throw Error("max_iterations must be an integer >= 1");
  if (keys.empty()) throw Error("fit: give at least one key to fit (e.g. [\"beta_long\"])");
  std::set<std::string> seen;
  for (const std::string& key : keys)
    if (!seen.insert(key).second) throw Error("fit key '" + key + "' is given twice");
  const compare::ModelSpec spec{model_name, {}, model_name};
  const analytic::ModelParams start = compare::params_for(result.settings, spec, sets);
  analytic::make_model(spec.name, start);  // the model's own checks, before the fit
  for (const std::string& key : keys) compare::check_fit_key(spec.name, key);
  const double limit = max_chi2 ? *max_chi2 : 0.0;

  FitProgress relay(std::move(progress));
  compare::FitResult fr;
  compare::Verdict before, after;
  bool stopped = false;
  {
    py::gil_scoped_release release;
    auto verdict = [&](const analytic::ModelParams& p) {
      const auto model = compare::make_model(spec.name, p);
      return compare::judge(compare::compare(result, compare::predict_result(*model, result), p.alpha, o), limit);
    };
    before = verdict(start);
    try {
      fr = compare::fit_model(result, spec.name, start, keys, o, max_iterations, relay.callback());
    } catch (const StopFit&) {
      stopped = true;
    }
    if (!stopped) after = verdict(fr.params);
  }
  if (stopped) relay.rethrow();

  py::dict d;
  d["keys"] = fr.keys;
  d["start"] = fr.start;
  d["value"] = fr.value;
  d["error"] = fr.error;
  d["error_unscaled"] = fr.error_unscaled;
  d["at_bound"] = std::vector<bool>(fr.at_bound.begin(), fr.at_bound.end());
  d["chi2_start"] = fr.chi2_start;
  d["chi2"] = fr.chi2;
  d["residuals"] = fr.residuals;
  d["dof"] = fr.dof;
  d["iterations"] = fr.iterations;
  d["evaluations"] = fr.evaluations;
  d["converged"] = fr.converged;
  d["outcome"] = std::string(compare::outcome_name(fr.outcome));
  d["stop_reason"] = fr.stop_reason;
  d["params_start"] = params_dict(spec.name, start);
  d["params"] = params_dict(spec.name, fr.params);
  d["before"] = verdict_dict(before, result.lobes);
  d["after"] = verdict_dict(after, result.lobes);
  return d;
}

}  // namespace

void bind_fit(py::module_& m) {
  m.def("fit", &fit, py::arg("result"), py::arg("model"), py::arg("keys"), py::arg("settings_overrides"),
        py::arg("max_chi2") = py::none(), py::arg("min_effective") = 30.0, py::arg("model_error") = 1e-4,
        py::arg("min_energy") = 1e-4, py::arg("max_iterations") = 40, py::arg("lobes") = std::vector<std::string>{},
        py::arg("progress") = py::none(),
        "compare::fit_model (the fit of `fiberlab compare --fit`) with the verdicts before and after it");
}

}  // namespace fiberlab::python
