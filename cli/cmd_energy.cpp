// `fiberlab energy CONFIG_OR_RESULT [--models M,...] [--set KEY=VALUE ...]
//                 [--beta-sweep B,...] [--theta-i SPEC] [--run] [--report DIR]`
// Does model M conserve energy? Over the theta_i sweep of a result (or a
// config), the per-lobe and total energy of the simulation's ledger and of
// each model integrated over the sphere, and each one's departure from the
// white furnace (total - 1, for a white fiber). Given a config, only the
// models are evaluated unless --run is given (then the simulation runs here,
// in memory, with the config's photons or --photons).
// The work: app/energy.h; the report folder: compare/energy_report.h.
#include <fmt/core.h>

#include <algorithm>
#include <memory>
#include <string>

#include "app/energy.h"
#include "cli/commands.h"
#include "common/units.h"
#include "compare/comparison.h"

namespace fiberlab::cli {

namespace {

// The table on stdout: per theta_i, each curve's lobes, total, R+TT+TRT, the
// furnace departure (white fibers) and the simulation's ledger.
void print_energy(const app::EnergyRequest& o, const app::EnergyResult& r) {
  const bool from_result = r.from_result, simulated = r.simulated, white = r.white;
  const sim::Settings& settings = r.settings;
  const std::vector<double>& theta_i = r.theta_i;
  const std::vector<compare::EnergyCurve>& curves = r.curves;
  const int c = o.channel;
  fmt::print("{}: {}{}\n", o.input, from_result ? "result file" : "config",
             simulated ? (from_result ? "" : " (simulated here, --run)")
                       : " (simulation not run: models only; pass --run or a result file)");
  for (const std::string& line : r.skipped) fmt::print("{}\n", line);
  fmt::print("fiber: eta {:g}, sigma_a[{}] = {:g}{}; channel {} shown\n", settings.fiber.eta, c,
             settings.fiber.sigma_a.at(std::min<std::size_t>(c, settings.fiber.sigma_a.size() - 1)),
             white ? " (white: the furnace test applies, total should be 1)" : " (absorbing: no furnace test)",
             c);
  const int L = curves.front().lobes;
  for (std::size_t k = 0; k < theta_i.size(); ++k) {
    fmt::print("\ntheta_i = {:.2f} deg\n  {:<44}", rad_to_deg(theta_i[k]), "source");
    for (int l = 0; l < L; ++l) fmt::print(" {:>9}", r.lobe_names.at(l));
    fmt::print(" {:>9} {:>9} {:>10}{}\n", "total", "R+TT+TRT", white ? "total-1" : "",
               simulated ? "  absorbed truncated      lost ledger" : "");
    for (const auto& e : curves) {
      fmt::print("  {:<44}", e.label.substr(0, 44));
      for (int l = 0; l < e.lobes; ++l) fmt::print(" {:9.6f}", e.at(k, l, c));
      const double total = e.total(k, c);
      fmt::print(" {:9.6f} {:9.6f} {:>10}", total, e.three_lobe(k, c),
                 white ? fmt::format("{:+.2e}", total - 1.0) : std::string());
      if (e.simulated)
        fmt::print("  {:8.6f} {:9.2e} {:9.6f} {:.12f}  (total +- {:.1e})", e.absorbed[k * e.channels + c],
                   e.truncated[k * e.channels + c], e.lost[k * e.channels + c],
                   e.ledger[k * e.channels + c], e.total_error(k, c));
      fmt::print("\n");
    }
  }
}

void energy_command(const app::EnergyRequest& o) {
  const app::EnergyResult r = app::energy(o);
  print_energy(o, r);
  if (!o.report.empty()) fmt::print("{}", app::write_energy_report(o, r));
}

}  // namespace

void add_energy_command(CLI::App& app) {
  auto o = std::make_shared<fiberlab::app::EnergyRequest>();
  CLI::App* cmd = app.add_subcommand(
      "energy", "Energy per lobe and in total over theta_i: simulation ledger vs models (white furnace)");
  cmd->add_option("input", o->input, "Result file (.h5) or YAML config (models only unless --run)")->required();
  cmd->add_option("--models", o->models, fiberlab::app::energy_models_help());
  cmd->add_option("--set", o->settings,
                  "Model parameter KEY=VALUE for every model that has KEY (degrees); repeatable");
  cmd->add_option("--beta-sweep", o->beta_sweep,
                  "Evaluate each model that has beta_long at these beta_long (degrees, every lobe), as in "
                  "d'Eon 2011 Fig. 3");
  cmd->add_option("--theta-i", o->theta_i, "Config only: model theta_i, degrees A,B,C or FROM:TO:STEP");
  cmd->add_flag("--run", o->run, "Config only: run the simulation too (in memory)");
  CLI::Option* photons = cmd->add_option("--photons", o->photons, "With --run: photons per incident direction");
  cmd->add_option("--threads", o->threads, "With --run: OpenMP threads");
  cmd->add_option("--channel", o->channel, "Channel shown in the table and plots (0)");
  cmd->add_option("--grid-theta", o->n_theta, "theta bins of the models' integration grid (180)");
  cmd->add_option("--grid-phi", o->n_phi, "phi bins of the models' integration grid (90)");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  cmd->callback([o, photons] {
    o->photons_given = photons->count() > 0;
    energy_command(*o);
  });
}

}  // namespace fiberlab::cli
