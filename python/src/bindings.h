#pragma once
// The compiled part of the Python module `fiberlab` (`fiberlab._fiberlab`):
// thin bindings of the C++ libraries, one file per concept. Physics and
// statistics stay in the C++ (sim/, analytic/, compare/, and the workflows
// the command line shares in app/); these files only
// convert between C++ containers and NumPy arrays (SPEC s9 index order,
// (K, L, n_theta, n_phi, C), C-contiguous copies) and release the GIL for
// long work.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "compare/comparison.h"
#include "compare/verdict.h"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace fiberlab::python {

namespace py = pybind11;

// A NumPy array holding a copy of `data` with the given shape (row-major).
template <typename T>
py::array_t<T> to_array(const std::vector<T>& data, const std::vector<py::ssize_t>& shape) {
  py::array_t<T> a(shape);
  std::copy(data.begin(), data.end(), a.mutable_data());
  return a;
}

// A model's parameters as predict(**params) takes them (prediction_binding.cpp).
py::dict params_dict(const std::string& model_name, const analytic::ModelParameters& params);

// The checks of `fiberlab compare`'s flags and the options they make; a
// verdict as {"rows": [...], "judged", "rejected", "all_accepted",
// "criterion"} (comparison_binding.cpp).
compare::Options comparison_options(std::optional<double> max_chi2, double min_effective, double model_error,
                                    double min_energy);
py::dict verdict_dict(const compare::Verdict& v, const std::vector<std::string>& lobe_names);

void bind_result(py::module_& m);      // result_binding.cpp: ResultFile, Settings, estimators, I/O
void bind_run(py::module_& m);         // run_binding.cpp: the simulation
void bind_prediction(py::module_& m);  // prediction_binding.cpp: analytic models' bin probabilities
void bind_comparison(py::module_& m);  // comparison_binding.cpp: compare/'s statistics and verdict
void bind_fit(py::module_& m);         // fit_binding.cpp: app/fit.h, the fit of `fiberlab compare --fit`

}  // namespace fiberlab::python
