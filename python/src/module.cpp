// fiberlab._fiberlab: the compiled extension behind `import fiberlab`.
#include "bindings.h"

#include "common/error.h"
#include "common/interrupt.h"

PYBIND11_MODULE(_fiberlab, m) {
  m.doc() = "fiberlab's C++ library (simulation, models, comparison); use the `fiberlab` package";
  // One-line errors of the C++ library (bad config, file, parameter): a ValueError.
  pybind11::register_exception<fiberlab::Error>(m, "Error", PyExc_ValueError);
  m.attr("software_version") = FIBERLAB_VERSION;
  // Python owns the signal handlers (its SIGINT handler raises
  // KeyboardInterrupt): the library installs none for good (common/interrupt.h).
  fiberlab::leave_signals_to_host();
  fiberlab::python::bind_result(m);
  fiberlab::python::bind_run(m);
  fiberlab::python::bind_prediction(m);
  fiberlab::python::bind_comparison(m);
  fiberlab::python::bind_fit(m);
}
