// `fiberlab predict CONFIG_OR_RESULT --model NAME [--set KEY=VALUE ...] -o PRED.h5`:
// an analytic model's bin probabilities for the histogram a simulation with
// this configuration produces (SPEC section 7), in the same layout.
#include <fmt/core.h>
#include <fmt/ranges.h>
#include <hdf5.h>

#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "analytic/model_registry.h"
#include "cli/commands.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/models.h"
#include "sim/result_file.h"
#include "sim/settings.h"

namespace fiberlab::cli {

namespace {

struct PredictOptions {
  std::string input, model, output;
  std::vector<std::string> settings;
};

void predict(const PredictOptions& o) {
  const sim::Settings s = sim::load_settings_or_result(o.input);
  const compare::ModelSpec spec = compare::parse_model_spec(o.model);
  const analytic::ModelParams params = compare::params_for(s, spec, o.settings);
  const std::unique_ptr<analytic::Model> model = analytic::make_model(spec.name, params);
  fmt::print("{}", compare::model_header(spec, params));

  const BinGrid grid = BinGrid::make(s.tally.n_theta, s.tally.n_phi, s.tally.theta_bins);
  const std::vector<sim::Settings::Incidence> inc = s.incidences();
  const int L = params.lobes, nt = grid.n_theta(), np = grid.n_phi();
  const int C = static_cast<int>(params.sigma_a.size());
  const std::size_t per_k = static_cast<std::size_t>(L) * nt * np * C;
  AtomicOutput out(o.output, {o.input});  // checks the target before the work

  std::vector<double> prob(per_k * inc.size(), 0.0);
  std::vector<double> theta_i, phi_i;
  for (std::size_t k = 0; k < inc.size(); ++k) {
    theta_i.push_back(inc[k].theta_i);
    phi_i.push_back(inc[k].phi_i);
    const std::vector<double> p = compare::predict_bins(*model, grid, inc[k].theta_i, inc[k].phi_i, L, C,
                                                        s.fiber.eccentricity != 1.0);
    std::copy(p.begin(), p.end(), prob.begin() + static_cast<std::ptrdiff_t>(k * per_k));
  }

  h5::File f = h5::File::create(out.temp_path(), out.target());
  write_file_identity(f, "fiber-prediction", utc_timestamp());
  f.set_attr("/", "config_yaml", sim::to_yaml(s));
  write_bins(f, grid);
  write_incidences(f, theta_i, phi_i);
  f.create_group("/prediction");
  f.write_finite("/prediction/probability",
          {static_cast<hsize_t>(inc.size()), static_cast<hsize_t>(L), static_cast<hsize_t>(nt),
           static_cast<hsize_t>(np), static_cast<hsize_t>(C)},
          prob);
  f.set_attr("/prediction", "model", spec.name);
  std::string approx;
  for (const std::string& a : analytic::approximations(spec.name, params)) approx += a + "\n";
  f.set_attr("/prediction", "approximations", approx);
  // Descriptive attributes (docs/FILE_FORMAT.md).
  write_axis_names(f, L, C, s.fiber.eumelanin.has_value());
  describe_bins_and_source(f);
  describe(f, "/prediction/probability", kHistogramDims, "probability",
           "the model's probability of each bin (its density integrated over the bin)");
  // Only this model's parameters (its table), angles in radians.
  for (const analytic::ParamAttribute& a : analytic::param_attributes(spec.name, params)) {
    if (a.is_text) f.set_attr("/prediction", a.name, a.text);
    else if (a.numbers.size() == 1) f.set_attr("/prediction", a.name, a.numbers[0]);
    else f.set_attr("/prediction", a.name, a.numbers);
  }
  f.close();
  out.commit();
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
