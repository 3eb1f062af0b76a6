#pragma once
// The compiled part of the Python module `fiberlab` (`fiberlab._fiberlab`):
// thin bindings of the C++ libraries, one file per concept. Physics and
// statistics stay in the C++ (sim/, analytic/, compare/); these files only
// convert between C++ containers and NumPy arrays (SPEC s9 index order,
// (K, L, n_theta, n_phi, C), C-contiguous copies) and release the GIL for
// long work.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
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

void bind_result(py::module_& m);      // result_binding.cpp: ResultFile, Settings, estimators, I/O
void bind_run(py::module_& m);         // run_binding.cpp: the simulation
void bind_prediction(py::module_& m);  // prediction_binding.cpp: analytic models' bin probabilities
void bind_comparison(py::module_& m);  // comparison_binding.cpp: compare/'s statistics

}  // namespace fiberlab::python
