// fiberlab.run from Python: app::simulate on resolved Settings, with the
// GIL released while photons are traced and an optional Python progress
// callable (called about twice a second, sim/run/simulation.h).
//
// Signals (common/interrupt.h): while photons are traced, SIGINT, SIGTERM
// and SIGHUP only set the flag the simulation polls (a ScopedInterruptPolling
// replaces Python's handlers for the call and puts them back exactly), so
// the run stops within a few hundredths of a second; the signal is then
// re-delivered to Python's own handler (raise() after the restore), which
// makes a SIGINT a KeyboardInterrupt as anywhere else in Python.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <csignal>
#include <memory>
#include <optional>

#include "app/run.h"
#include "app/threads.h"
#include "bindings.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "sim/run/memory_budget.h"
#include "sim/store/result_file.h"

namespace fiberlab::python {

namespace {

// Calls `progress(done, total)` with the GIL held. A Python exception in it
// (e.g. from a closed notebook output) stops further calls and is raised
// when the run ends; the run itself cannot be cut short from here.
class ProgressRelay {
 public:
  explicit ProgressRelay(py::object progress) : progress_(std::move(progress)) {}

  sim::ProgressCallback callback() {
    if (progress_.is_none()) return {};
    return [this](std::uint64_t done, std::uint64_t total) {
      py::gil_scoped_acquire acquire;
      if (error_) return;
      try {
        progress_(done, total);
      } catch (py::error_already_set& e) {
        error_ = std::make_unique<py::error_already_set>(std::move(e));
      }
    };
  }
  void rethrow() {
    if (error_) throw std::move(*error_);
  }

 private:
  py::object progress_;
  std::unique_ptr<py::error_already_set> error_;
};

// After an interrupted run: Python's handler gets the signal it missed (a
// KeyboardInterrupt for SIGINT; the default action for an unhandled SIGTERM
// ends the process as it would have). When no Python exception results (a
// handler that only records the signal, or a call from another thread than
// the main one), SIGINT still raises KeyboardInterrupt and other signals a
// fiberlab.Error: the run was cut short and has no result.
[[noreturn]] void raise_interrupted(int sig) {
  if (sig == 0) throw Error("run interrupted; nothing was kept");
  std::raise(sig);
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  if (sig == SIGINT) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  throw Error(std::string("run interrupted by ") + signal_name(sig) + "; nothing was kept");
}

std::shared_ptr<sim::ResultFile> run(sim::Settings settings, std::optional<std::uint64_t> photons,
                                     std::optional<std::uint64_t> seed, int threads, py::object progress) {
  if (photons) settings.photons = *photons;
  if (seed) settings.seed = *seed;
  app::check_total_photons(settings, "photons");
  threads = app::run_threads(threads);
  ProgressRelay relay(std::move(progress));
  std::shared_ptr<sim::ResultFile> result;
  bool interrupted = false;
  int received = 0;  // a signal that came during the call, even after the last photon
  {
    // Everything without the GIL is inside the scope: a signal while the
    // tracers are set up or the result is assembled is not left to a Python
    // handler that cannot run before the call returns.
    py::gil_scoped_release release;
    ScopedInterruptPolling polling;
    std::optional<sim::ResultFile> done = app::simulate(settings, threads, relay.callback());
    interrupted = !done;
    if (done) result = std::make_shared<sim::ResultFile>(std::move(*done));
    received = polling.received_signal();
  }
  if (interrupted) raise_interrupted(received);
  if (received != 0) {  // the run was complete: Python's handler decides, as after any call
    std::raise(received);
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  relay.rethrow();
  return result;
}

}  // namespace

void bind_run(py::module_& m) {
  m.attr("max_threads") = sim::kMaxThreads;  // fiberlab.run's threads: 1 to this, as `fiberlab run --threads`
  m.def("run", &run, py::arg("settings"), py::arg("photons") = py::none(), py::arg("seed") = py::none(),
        py::arg("threads") = 0, py::arg("progress") = py::none(),
        "Simulates `settings` (threads <= 0: every core); progress(done, total) is called now and then");
}

}  // namespace fiberlab::python
