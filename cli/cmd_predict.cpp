// `fiberlab predict CONFIG_OR_RESULT --model NAME [--set KEY=VALUE ...] -o PRED.h5`:
// an analytic model's bin probabilities for the histogram a simulation with
// this configuration produces (SPEC section 7), in the same layout.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <memory>
#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "cli/commands.h"
#include "common/atomic_output.h"
#include "compare/models.h"
#include "compare/prediction_file.h"
#include "sim/store/result_file.h"
#include "sim/run/settings.h"

namespace fiberlab::cli {

namespace {

struct PredictOptions {
  std::string input, model, output;
  std::vector<std::string> settings;
};

void predict(const PredictOptions& o) {
  const sim::Settings s = sim::load_settings_or_result(o.input);
  const compare::ModelSpec spec = compare::parse_model_spec(o.model);
  std::vector<std::string> fiber_notes;
  const analytic::ModelParams params = compare::params_for(s, spec, o.settings, &fiber_notes);
  const std::unique_ptr<analytic::Model> model = analytic::make_model(spec.name, params);
  fmt::print("{}", compare::model_header(spec, params, fiber_notes));

  compare::PredictionFile pred;
  pred.model = spec.name;
  pred.grid = BinGrid::make(s.tally.n_theta, s.tally.n_phi, s.tally.theta_bins);
  pred.lobes = params.lobes;
  pred.channels = static_cast<int>(params.sigma_a.size());
  check_output_target(o.output, {o.input});  // before the work
  for (const sim::Settings::Incidence& inc : s.incidences()) {
    pred.theta_i.push_back(inc.theta_i);
    pred.phi_i.push_back(inc.phi_i);
    const std::vector<double> p = compare::predict_bins(*model, pred.grid, inc.theta_i, inc.phi_i, pred.lobes,
                                                        pred.channels, s.fiber.eccentricity != 1.0);
    pred.probability.insert(pred.probability.end(), p.begin(), p.end());
  }
  compare::write_prediction(o.output, pred, s, params, {o.input});
}

}  // namespace

void add_predict_command(CLI::App& app) {
  auto o = std::make_shared<PredictOptions>();
  CLI::App* cmd = app.add_subcommand(
      "predict", "Bin probabilities of an analytic model for a config or a result's config");
  cmd->add_option("input", o->input, "Config (.yaml) or result (.h5)")->required();
  cmd->add_option("--model", o->model,
                  fmt::format("{} (optionally NAME:KEY=VALUE:...); keys: `fiberlab models`",
                              fmt::join(analytic::model_names(), " | ")))
      ->required();
  cmd->add_option("--set", o->settings,
                  "KEY=VALUE parameter of the model (repeatable; angles in degrees; `fiberlab models` lists "
                  "each model's keys)");
  cmd->add_option("-o,--output", o->output, "Prediction file (.h5)")->required();
  // Built when --help asks for it, not at every start (about 0.3 ms each).
  cmd->footer([] { return "\nModel parameters (--set KEY=VALUE):\n\n" + analytic::models_listing(); });
  cmd->callback([o] { predict(*o); });
}

}  // namespace fiberlab::cli
