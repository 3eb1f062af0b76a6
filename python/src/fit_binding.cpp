// fiberlab.fit from Python: app::fit, the fit of `fiberlab compare --fit` on
// a result with the verdicts before and after it, as the CLI prints them. The GIL is released during the fit; between iterations
// the progress callable (if any) gets the CLI's progress line and pending
// Python signals are handled (Ctrl-C stops a fit at the next iteration with
// KeyboardInterrupt).
#include <pybind11/stl.h>

#include <memory>
#include <optional>

#include "app/fit.h"
#include "bindings.h"
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
  app::FitRequest request;
  request.model = model_name;
  request.keys = keys;
  request.sets = sets;
  request.lobes = lobes;
  request.options = comparison_options(max_chi2, min_effective, model_error, min_energy);
  request.max_chi2 = max_chi2;
  request.max_iterations = max_iterations;
  FitProgress relay(std::move(progress));
  app::FitReport report;
  bool stopped = false;
  {
    py::gil_scoped_release release;
    try {
      report = app::fit(result, request, relay.callback());
    } catch (const StopFit&) {
      stopped = true;
    }
  }
  if (stopped) relay.rethrow();
  const compare::FitResult& fr = report.fit;

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
  d["params_start"] = params_dict(model_name, report.start);
  d["params"] = params_dict(model_name, fr.params);
  d["before"] = verdict_dict(report.before, result.lobes);
  d["after"] = verdict_dict(report.after, result.lobes);
  return d;
}

}  // namespace

void bind_fit(py::module_& m) {
  m.def("fit", &fit, py::arg("result"), py::arg("model"), py::arg("keys"), py::arg("settings_overrides"),
        py::arg("max_chi2") = py::none(), py::arg("min_effective") = compare::Options{}.min_effective,
        py::arg("model_error") = compare::Options{}.model_rel_error, py::arg("min_energy") = compare::Options{}.min_lobe_energy, py::arg("max_iterations") = app::kFitIterations, py::arg("lobes") = std::vector<std::string>{},
        py::arg("progress") = py::none(),
        "compare::fit_model (the fit of `fiberlab compare --fit`) with the verdicts before and after it");
}

}  // namespace fiberlab::python
