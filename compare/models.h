#pragma once
// The comparison tools' view of the analytic models: build a Model by name
// from ModelParams, and apply `--set KEY=VALUE` overrides. This is an adapter
// over analytic/ (model_factory.h and model_params.h, which own the names and
// the keys); compare/ only forwards, so every tool accepts the same names and
// keys as `fiberlab predict`.
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "sim/result_file.h"

namespace fiberlab::compare {

// "exact" | "deon2011" | "marschner2003". Throws fiberlab::Error otherwise.
std::unique_ptr<analytic::Model> make_model(const std::string& name,
                                            const analytic::ModelParams& params);

// Applies one "KEY=VALUE" (angles in degrees, lists comma-separated), as
// `fiberlab predict --set` does. Throws fiberlab::Error naming the key.
void apply_setting(analytic::ModelParams& params, const std::string& key_value);

// A model specification as given on the command line: "NAME" or
// "NAME:KEY=VALUE:KEY=VALUE" (the overrides apply to this model only, e.g.
// "marschner2003:longitudinal=two_theta_h").
struct ModelSpec {
  std::string name;                  // the model name
  std::vector<std::string> settings; // KEY=VALUE
  std::string label;                 // the spec as written (for tables)
};
ModelSpec parse_model_spec(const std::string& spec);

// Model parameters for a simulation's settings (compare/model_defaults.h),
// then `settings` (global --set), then the spec's own overrides.
analytic::ModelParams params_for(const sim::Settings& s, const ModelSpec& spec,
                                 const std::vector<std::string>& settings);

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

// predict_bins() for every incident configuration of a result (parallel
// over configurations with OpenMP when `parallel`).
std::vector<std::vector<double>> predict_result(const analytic::Model& model,
                                                const sim::ResultFile& result,
                                                bool parallel = true);

}  // namespace fiberlab::compare
