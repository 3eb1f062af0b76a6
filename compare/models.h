#pragma once
// The comparison tools' view of the analytic models: a model's parameters
// for a simulation (the model's own physical defaults, analytic/
// model_registry.h, then --set overrides) and its bin probabilities in a
// result's layout. analytic/ owns the names, the keys and the rules;
// compare/ only forwards, so every tool accepts the same names and keys as
// `fiberlab predict`.
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "analytic/physical_defaults.h"
#include "sim/store/result_file.h"

namespace fiberlab::compare {

// A registered model by name (analytic::make_model). Throws fiberlab::Error otherwise.
std::unique_ptr<analytic::Model> make_model(const std::string& name,
                                            const analytic::ModelParameters& params);

// The model's theta_r shift per lobe, radians (analytic::theta_r_shifts):
// the `alpha` of compare().
std::vector<double> theta_r_shifts(const std::string& name, const analytic::ModelParameters& params);

// The simulator's settings as the models see a fiber (a copy, no physics).
analytic::PhysicalFiber physical_fiber(const sim::Settings& s);

// A model specification as given on the command line: "NAME" or
// "NAME:KEY=VALUE:KEY=VALUE" (the overrides apply to this model only, e.g.
// "marschner2003:longitudinal=two_theta_h").
struct ModelSpec {
  std::string name;                  // the model name
  std::vector<std::string> settings; // KEY=VALUE
  std::string label;                 // the spec as written (for tables)
};
ModelSpec parse_model_spec(const std::string& spec);

// The lines `predict` and `compare` print about a model before their
// results: its parameters and the published approximations in effect.
// `fiber_notes`: the approximate mappings from the simulated fiber (params_for).
std::string model_header(const ModelSpec& spec, const analytic::ModelParameters& params,
                         const std::vector<std::string>& fiber_notes = {});
// The model's parameters as a JSON object {"key": {"value": "...", "unit": "..."}}
// (command-line units: degrees for angles).
std::string params_json(const std::string& model_name, const analytic::ModelParameters& params);

// Model parameters for a simulation's settings: the model's table defaults,
// its physical defaults for the fiber (ModelInfo::from_fiber), then
// `settings` (global --set), then the spec's own overrides. The overrides are
// also applied before the physical defaults, so that a choice such as
// longitudinal=two_theta_h decides how the roughness maps to beta. A fiber
// the model cannot represent is refused (fiberlab::Error) unless the
// settings set the key concerned; `fiber_notes` (optional) receives one
// line per approximate mapping applied (analytic::FiberMapping).
analytic::ModelParameters params_for(const sim::Settings& s, const ModelSpec& spec,
                                 const std::vector<std::string>& settings,
                                 std::vector<std::string>* fiber_notes = nullptr);

// Bin probabilities of one incident configuration, [lobe][theta][phi][channel]
// in the result's layout. The model's channels must equal `channels`, lobes
// must equal `lobes` (both checked; fiberlab::Error otherwise).
// phi_i NaN is a randomly rotated fiber (SPEC section 5, phi_i: uniform):
// for an elliptical one (`elliptical`) the prediction is averaged over 32
// midpoint rotations of phi_i in [0, pi) (the ellipse has period pi); a
// circle does not depend on phi_i.
std::vector<double> predict_bins(const analytic::Model& model, const BinGrid& grid,
                                 double theta_i, double phi_i, int lobes, int channels,
                                 bool elliptical = false);

}  // namespace fiberlab::compare

namespace fiberlab::compare {

// predict_bins() for incident configuration k of a result. For a fiber with
// a medulla (docs/FUR.md) the models, which have none, predict nothing in
// its last lobe, `scattered`: their bins are followed by a zero lobe.
std::vector<double> predict_config(const analytic::Model& model, const sim::ResultFile& result, std::size_t k);

// predict_config() for every incident configuration of a result (parallel
// over configurations with OpenMP when `parallel`).
std::vector<std::vector<double>> predict_result(const analytic::Model& model,
                                                const sim::ResultFile& result,
                                                bool parallel = true);

}  // namespace fiberlab::compare
