// fiberlab.run from Python: sim::Simulation on resolved Settings, with the
// GIL released while photons are traced and an optional Python progress
// callable (called from the calling thread, which Simulation::run uses as
// OpenMP's thread 0, every 250 ms).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

#include "bindings.h"
#include "sim/result_file.h"
#include "sim/simulation.h"

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

std::shared_ptr<sim::ResultFile> run(sim::Settings settings, std::optional<std::uint64_t> photons,
                                     std::optional<std::uint64_t> seed, int threads, py::object progress) {
  if (photons) settings.photons = *photons;
  if (seed) settings.seed = *seed;
  ProgressRelay relay(std::move(progress));
  std::shared_ptr<sim::ResultFile> result;
  {
    py::gil_scoped_release release;
    const sim::Simulation simulation(settings);
    const std::vector<sim::Tally> tallies = simulation.run(threads, relay.callback());
    result = std::make_shared<sim::ResultFile>(
        sim::make_result(simulation.settings(), simulation.grid(), tallies));
  }
  relay.rethrow();
  return result;
}

}  // namespace

void bind_run(py::module_& m) {
  m.def("run", &run, py::arg("settings"), py::arg("photons") = py::none(), py::arg("seed") = py::none(),
        py::arg("threads") = 0, py::arg("progress") = py::none(),
        "Simulates `settings` (threads <= 0: every core); progress(done, total) is called now and then");
}

}  // namespace fiberlab::python
