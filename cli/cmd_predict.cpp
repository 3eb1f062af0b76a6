// `fiberlab predict CONFIG_OR_RESULT --model NAME [--set KEY=VALUE ...] -o PRED.h5`:
// an analytic model's bin probabilities for the histogram a simulation with
// this configuration produces (SPEC section 7), in the same layout.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <memory>
#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "app/predict.h"
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
  const app::ChosenModel chosen = app::choose_model(s, compare::parse_model_spec(o.model), o.settings);
  fmt::print("{}", compare::model_header(chosen.spec, chosen.params, chosen.fiber_notes));
  check_output_target(o.output, {o.input});  // before the work
  compare::write_prediction(o.output, app::predict(s, chosen), s, chosen.params, {o.input});
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
