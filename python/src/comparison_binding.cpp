// fiberlab.compare from Python: compare::compare() on a result and any bin
// probabilities of the same shape (a model's or a researcher's own), judged
// by compare::judge, the verdict of `fiberlab compare`.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "analytic/model_registry.h"
#include "app/fit.h"
#include "bindings.h"
#include "common/error.h"
#include "common/units.h"
#include "compare/comparison.h"
#include "compare/prediction_file.h"
#include "compare/verdict.h"
#include "sim/store/result_file.h"

namespace fiberlab::python {

namespace {

// Row i of a verdict, keyed as in `fiberlab compare --report`'s metrics.json
// (angles in degrees), with the verdict the CLI prints: "accepted",
// "rejected" or "not judged" (accepted is true for judged, accepted lobes only).
py::dict row(const compare::Verdict& v, std::size_t i, const std::vector<std::string>& lobe_names) {
  const compare::LobeComparison& r = v.rows[i];
  py::dict d;
  d["k"] = r.k;
  d["theta_i_deg"] = rad_to_deg(r.theta_i);
  d["phi_i_deg"] = rad_to_deg(r.phi_i);
  d["lobe"] = r.lobe;
  d["lobe_name"] = lobe_names.at(static_cast<std::size_t>(r.lobe));
  d["channel"] = r.channel;
  d["sim_energy"] = r.sim_energy;
  d["sim_error"] = r.sim_error;
  d["model_energy"] = r.model_energy;
  d["energy_z"] = r.energy_z;
  d["chi2"] = r.bins.chi2;
  d["dof"] = r.bins.dof;
  d["chi2_per_dof"] = r.bins.per_dof();
  d["compared_bins"] = r.compared_bins;
  d["rest_sim"] = r.rest_sim;
  d["rest_model"] = r.rest_model;
  d["theta_chi2_per_dof"] = r.theta_marginal.per_dof();
  d["theta_dof"] = r.theta_marginal.dof;
  d["phi_chi2_per_dof"] = r.phi_marginal.per_dof();
  d["phi_dof"] = r.phi_marginal.dof;
  d["l1"] = r.l1;
  d["peak_sim_deg"] = rad_to_deg(r.peak_sim);
  d["peak_model_deg"] = rad_to_deg(r.peak_model);
  d["centroid_sim_deg"] = rad_to_deg(r.centroid_sim);
  d["centroid_sim_error_deg"] = rad_to_deg(r.centroid_sim_error);
  d["centroid_model_deg"] = rad_to_deg(r.centroid_model);
  d["alpha_model_deg"] = rad_to_deg(r.alpha_model);
  d["measured_shift_deg"] = rad_to_deg(r.measured_shift);
  d["judged"] = r.judged;
  d["threshold"] = v.threshold[i];
  d["accepted"] = r.judged && v.accepted[i];
  d["verdict"] = !r.judged ? "not judged" : (v.accepted[i] ? "accepted" : "rejected");
  return d;
}

std::vector<std::vector<double>> bins_of(const sim::ResultFile& r,
                                         py::array_t<double, py::array::c_style | py::array::forcecast> p) {
  const std::vector<py::ssize_t> want{static_cast<py::ssize_t>(r.configs()), r.lobes, r.grid.n_theta(),
                                      r.grid.n_phi(), r.channels};
  const std::vector<py::ssize_t> got(p.shape(), p.shape() + p.ndim());
  if (got != want) {
    auto text = [](const std::vector<py::ssize_t>& s) {
      std::string t;
      for (auto x : s) t += (t.empty() ? "" : ", ") + std::to_string(x);
      return "(" + t + ")";
    };
    throw Error("prediction probability has shape " + text(got) + ", the result's histogram " + text(want) +
                " (K, lobes, n_theta, n_phi, channels)");
  }
  const double* data = p.data();
  for (py::ssize_t i = 0; i < p.size(); ++i)
    if (!std::isfinite(data[i])) throw Error("prediction probability holds a NaN or infinite value");
  std::vector<std::vector<double>> bins(r.configs());
  for (std::size_t k = 0; k < r.configs(); ++k)
    bins[k].assign(data + k * r.bin_cells(), data + (k + 1) * r.bin_cells());
  return bins;
}

py::dict compare_bins(const sim::ResultFile& r, py::array_t<double, py::array::c_style | py::array::forcecast> p,
                      const std::vector<double>& alpha, std::optional<double> max_chi2, double min_effective,
                      double model_error, double min_energy) {
  const std::vector<std::vector<double>> bins = bins_of(r, p);
  const compare::Options o = comparison_options(max_chi2, min_effective, model_error, min_energy);
  compare::Verdict v;
  {
    py::gil_scoped_release release;
    v = compare::judge(compare::compare(r, bins, alpha.empty() ? std::vector<double>{0.0} : alpha, o),
                       max_chi2 ? *max_chi2 : 0.0);
  }
  return verdict_dict(v, r.lobe_names());
}

}  // namespace

// The checks of `fiberlab compare`'s flags (compare::check_options), with
// Python's keyword names.
compare::Options comparison_options(std::optional<double> max_chi2, double min_effective, double model_error,
                                    double min_energy) {
  compare::Options o;
  o.min_effective = min_effective;
  o.model_rel_error = model_error;
  o.min_lobe_energy = min_energy;
  compare::check_options(o, max_chi2, compare::OptionSpelling::Python);
  return o;
}

py::dict verdict_dict(const compare::Verdict& v, const std::vector<std::string>& lobe_names) {
  py::list rows;
  for (std::size_t i = 0; i < v.rows.size(); ++i) rows.append(row(v, i, lobe_names));
  py::dict d;
  d["rows"] = rows;
  d["judged"] = v.judged;
  d["rejected"] = v.rejected;
  d["all_accepted"] = v.all_accepted;
  d["criterion"] = v.criterion;
  return d;
}

void bind_comparison(py::module_& m) {
  m.def("compare", &compare_bins, py::arg("result"), py::arg("probability"), py::arg("alpha"),
        py::arg("max_chi2") = py::none(), py::arg("min_effective") = compare::Options{}.min_effective,
        py::arg("model_error") = compare::Options{}.model_rel_error, py::arg("min_energy") = compare::Options{}.min_lobe_energy,
        "compare::compare's statistics per (k, lobe, channel) and compare::judge's verdict");
  m.def("model_names", &analytic::model_names);
  // The defaults of `fiberlab compare`'s judging flags and of its fit, which
  // fiberlab.compare and fiberlab.fit take as their own.
  const compare::Options defaults;
  py::dict d;
  d["min_effective"] = defaults.min_effective;
  d["model_error"] = defaults.model_rel_error;
  d["min_energy"] = defaults.min_lobe_energy;
  d["max_iterations"] = app::kFitIterations;
  m.attr("comparison_defaults") = d;
  m.attr("probability_rounding") = compare::kProbabilityRounding;  // compare/prediction_file.h
}

}  // namespace fiberlab::python
