// fiberlab.fit from Python: app::fit, the fit of `fiberlab compare --fit` on
// a result with the verdicts before and after it, as the CLI prints them,
// and with per_lobe each lobe's own fit (app::fit_each_lobe, as --per-lobe). The GIL is released during the fit; between iterations
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

// One fit's numbers and its verdicts before and after, as fiberlab.Fit takes them.
py::dict fit_dict(const compare::FitResult& fr, const std::string& model_name,
                  const analytic::ModelParameters& start, const compare::Verdict& before,
                  const compare::Verdict& after, const std::vector<std::string>& lobe_names) {
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
  d["params_start"] = params_dict(model_name, start);
  d["params"] = params_dict(model_name, fr.params);
  d["before"] = verdict_dict(before, lobe_names);
  d["after"] = verdict_dict(after, lobe_names);
  return d;
}

py::dict fit(const sim::ResultFile& result, const std::string& model_name, const std::vector<std::string>& keys,
             const std::vector<std::string>& sets, std::optional<double> max_chi2, double min_effective,
             double model_error, double min_energy, int max_iterations, const std::vector<std::string>& lobes,
             bool per_lobe, py::object progress, const std::vector<std::string>& fit_settings) {
  app::FitRequest request;
  request.model = model_name;
  request.keys = keys;
  request.sets = sets;
  request.lobes = lobes;
  request.options = comparison_options(max_chi2, min_effective, model_error, min_energy);
  request.max_chi2 = max_chi2;
  request.max_iterations = max_iterations;
  request.per_lobe = per_lobe;
  request.fit_settings = fit_settings;
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
  py::dict d = fit_dict(report.fit, model_name, report.start, report.before, report.after, result.lobe_names());
  py::list lobe_fits;
  for (const app::LobeFitVerdict& lf : report.lobe_fits) {
    py::dict one = fit_dict(lf.fit, model_name, report.start, lf.before, lf.after, result.lobe_names());
    one["lobe"] = lf.lobe;
    one["lobe_name"] = result.lobe_names().at(static_cast<std::size_t>(lf.lobe));
    lobe_fits.append(one);
  }
  d["lobe_fits"] = lobe_fits;
  return d;
}

}  // namespace

void bind_fit(py::module_& m) {
  m.def("fit", &fit, py::arg("result"), py::arg("model"), py::arg("keys"), py::arg("settings_overrides"),
        py::arg("max_chi2") = py::none(), py::arg("min_effective") = compare::Options{}.min_effective,
        py::arg("model_error") = compare::Options{}.model_rel_error, py::arg("min_energy") = compare::Options{}.min_lobe_energy, py::arg("max_iterations") = app::kFitIterations, py::arg("lobes") = std::vector<std::string>{},
        py::arg("per_lobe") = false, py::arg("progress") = py::none(),
        py::arg("fit_settings") = std::vector<std::string>{},
        "app::fit (the fit of `fiberlab compare --fit`, and with per_lobe each lobe's own as --per-lobe) with "
        "the verdicts before and after it");
}

}  // namespace fiberlab::python
