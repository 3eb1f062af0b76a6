// A simulation's result (sim/store/result_file.h) as seen from Python: the raw
// sums, the estimators of SPEC section 6 (computed by app/estimates.h and
// compare::simulation_energy, not here), the energy ledger, and file I/O.
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include <memory>
#include <string>

#include "app/estimates.h"
#include "bindings.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "compare/energy.h"
#include "sim/store/result_file.h"
#include "sim/run/settings.h"

namespace fiberlab::python {

namespace {

using Result = sim::ResultFile;
using Shape = std::vector<py::ssize_t>;

Shape bins_shape(const Result& r) {
  return {static_cast<py::ssize_t>(r.configs()), r.lobes, r.grid.n_theta(), r.grid.n_phi(), r.channels};
}

// A YAML node as Python objects: maps -> dict, sequences -> list, scalars ->
// bool, int, float or str (in that order of preference).
py::object yaml_to_python(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      py::dict d;
      for (const auto& kv : node) d[py::str(kv.first.as<std::string>())] = yaml_to_python(kv.second);
      return d;
    }
    case YAML::NodeType::Sequence: {
      py::list l;
      for (const auto& item : node) l.append(yaml_to_python(item));
      return l;
    }
    case YAML::NodeType::Scalar: {
      const std::string text = node.Scalar();
      if (node.Tag() != "!") {  // unquoted: a number or a boolean when it parses as one
        if (text == "true" || text == "false") return py::bool_(text == "true");
        long long i;
        if (YAML::convert<long long>::decode(node, i)) return py::int_(i);
        double x;
        if (YAML::convert<double>::decode(node, x)) return py::float_(x);
      }
      return py::str(text);
    }
    default:
      return py::none();
  }
}

// A path from Python: text with a NUL byte would be read by the C library
// only up to the NUL (another file), so it is refused.
std::string checked_path(const std::string& path) {
  if (path.find('\0') != std::string::npos) throw Error("path contains a NUL byte");
  return path;
}

// P = S1/N, its standard error, and P / Omega with its standard error, for
// every bin (app::bin_estimates).
py::tuple estimators(const Result& r) {
  const app::BinEstimates e = app::bin_estimates(r);
  const Shape s = bins_shape(r);
  return py::make_tuple(to_array(e.mean, s), to_array(e.std_err, s), to_array(e.density, s),
                        to_array(e.density_std_err, s));
}

// Marginal probabilities over theta_r or over phi, with their standard
// errors (app::marginal).
py::tuple marginal(const Result& r, const std::string& axis) {
  const app::Marginal m = app::marginal(r, axis);
  const Shape s{static_cast<py::ssize_t>(r.configs()), r.lobes, m.n, r.channels};
  return py::make_tuple(to_array(m.mean, s), to_array(m.std_err, s));
}

// The energy ledger (compare::simulation_energy): lobe energies with their
// standard errors (K, L, C), absorbed, truncated and lost fractions and
// Russian roulette's signed term (K, C).
py::dict energy(const Result& r) {
  const compare::EnergyCurve e = compare::simulation_energy(r);
  const py::ssize_t K = static_cast<py::ssize_t>(r.configs());
  py::dict d;
  d["mean"] = to_array(e.lobe, {K, r.lobes, r.channels});
  d["std_err"] = to_array(e.lobe_error, {K, r.lobes, r.channels});
  d["absorbed"] = to_array(e.absorbed, {K, r.channels});
  d["truncated"] = to_array(e.truncated, {K, r.channels});
  d["lost"] = to_array(e.lost, {K, r.channels});
  d["roulette"] = to_array(e.roulette, {K, r.channels});
  return d;
}

}  // namespace

void bind_result(py::module_& m) {
  py::class_<sim::Settings>(m, "Settings", "A resolved simulation configuration (sim/run/settings.h)")
      .def_property_readonly("yaml", [](const sim::Settings& s) { return sim::to_yaml(s); })
      .def_property_readonly("config", [](const sim::Settings& s) { return yaml_to_python(YAML::Load(sim::to_yaml(s))); })
      .def_property_readonly("lobes", [](const sim::Settings& s) { return s.tally_lobes(); })
      .def_property_readonly("medulla", [](const sim::Settings& s) { return s.fiber.medulla.has_value(); })
      .def_property_readonly("channels", [](const sim::Settings& s) { return s.fiber.sigma_a.size(); })
      .def_property_readonly("melanin", [](const sim::Settings& s) { return s.fiber.eumelanin.has_value(); });
  m.def("parse_settings", &sim::parse_settings_yaml, py::arg("yaml_text"), py::arg("origin"),
        "Parses a YAML config (errors name `origin` and the field)");
  m.def("load_settings", [](const std::string& path) { return sim::load_settings_or_result(checked_path(path)); },
        py::arg("path"),
        "The settings of a YAML config or of a result file's config_yaml");

  py::class_<Result, std::shared_ptr<Result>>(m, "ResultFile", "A result file's contents (sim/store/result_file.h)")
      .def_property_readonly("settings", [](const Result& r) { return r.settings; })
      .def_property_readonly("config_yaml", [](const Result& r) { return r.config_yaml; })
      .def_property_readonly("seeds", [](const Result& r) { return r.seeds; })
      .def_property_readonly("software_version", [](const Result& r) { return r.software_version; })
      .def_property_readonly("created_utc", [](const Result& r) { return r.created_utc; })
      .def_property_readonly("lobes", [](const Result& r) { return r.lobes; })
      .def_property_readonly("lobe_names", [](const Result& r) { return r.lobe_names(); },
                             "the file's lobe_names (sim::ResultFile::lobe_names())")
      .def_property_readonly("channels", [](const Result& r) { return r.channels; })
      .def_property_readonly("theta_binning", [](const Result& r) { return to_string(r.grid.theta_binning); })
      .def_property_readonly("theta_edges", [](const Result& r) {
        return to_array(r.grid.theta_edges, {r.grid.n_theta() + 1});
      })
      .def_property_readonly("phi_edges", [](const Result& r) {
        return to_array(r.grid.phi_edges, {r.grid.n_phi() + 1});
      })
      .def_property_readonly("solid_angle", [](const Result& r) {
        std::vector<double> omega;
        for (int i = 0; i < r.grid.n_theta(); ++i)
          for (int j = 0; j < r.grid.n_phi(); ++j) omega.push_back(r.grid.solid_angle(i, j));
        return to_array(omega, {r.grid.n_theta(), r.grid.n_phi()});
      })
      .def_property_readonly("theta_i", [](const Result& r) {
        return to_array(r.theta_i, {static_cast<py::ssize_t>(r.configs())});
      })
      .def_property_readonly("phi_i", [](const Result& r) {
        return to_array(r.phi_i, {static_cast<py::ssize_t>(r.configs())});
      })
      .def_property_readonly("photons", [](const Result& r) {
        return to_array(r.photons, {static_cast<py::ssize_t>(r.configs())});
      })
      .def_property_readonly("weight_sum", [](const Result& r) { return to_array(r.weight_sum, bins_shape(r)); })
      .def_property_readonly("weight_sq_sum", [](const Result& r) { return to_array(r.weight_sq_sum, bins_shape(r)); })
      .def_property_readonly("count", [](const Result& r) {
        Shape s = bins_shape(r);
        s.pop_back();
        return to_array(r.count, s);
      })
      .def("estimators", &estimators, "(mean, std_err, density, density_std_err), each (K, L, n_theta, n_phi, C)")
      .def("marginal", &marginal, py::arg("axis"), "(mean, std_err) of the theta or phi marginal, (K, L, n, C)")
      .def("energy", &energy, "lobe energies with errors, absorbed and truncated fractions")
      .def("save", [](const Result& r, const std::string& path) {
        const std::string target = checked_path(path);
        py::gil_scoped_release release;
        sim::write_result(r, target);
      }, py::arg("path"), "Writes the result file (atomically)");

  m.def("read_result", [](const std::string& path) {
    const std::string source = checked_path(path);
    py::gil_scoped_release release;
    return std::make_shared<Result>(sim::read_result(source));
  }, py::arg("path"));
  m.def("lobe_names", [](int lobes, bool scattered) { return lobe_names(lobes, scattered); }, py::arg("lobes"),
        py::arg("scattered") = false,
        "R, TT, TRT, ..., p>=L-1, and `scattered` last for a fiber with a medulla (common/file_schema.h)");
  m.def("channel_names", [](const sim::Settings& s) {
    return channel_names(static_cast<int>(s.fiber.sigma_a.size()), s.fiber.eumelanin.has_value());
  }, py::arg("settings"), "R, G, B for a melanin fiber, else c0, c1, ... (common/file_schema.h)");
}

}  // namespace fiberlab::python
