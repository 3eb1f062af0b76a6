#pragma once
// `fiberlab energy`: does each model conserve energy? Over the theta_i sweep
// of a result (or a config), the per-lobe and total energy of the
// simulation's ledger and of each model integrated over the sphere
// (compare/energy.h), and each one's departure from the white furnace
// (total - 1, for a white fiber).
#include <string>
#include <vector>

#include "compare/energy.h"
#include "sim/run/settings.h"

namespace fiberlab::app {

// The flags of `fiberlab energy`, as given (lists and numbers still as text,
// checked here in the order the command states them).
struct EnergyRequest {
  std::string input, models;  // models empty: every registered model (energy_models_help)
  std::vector<std::string> settings;
  std::string beta_sweep, theta_i, report;
  bool run = false;
  std::string photons, threads;  // checked by sim::parse_integer_flag
  bool photons_given = false;
  int channel = 0, n_theta = 180, n_phi = 90;
};

struct EnergyResult {
  bool from_result = false;  // the input was a result file
  bool simulated = false;    // the curves start with the simulation's ledger
  bool white = false;        // sigma_a = 0 in every channel: the furnace test applies
  sim::Settings settings;
  std::vector<double> theta_i;               // radians
  std::vector<compare::EnergyCurve> curves;  // the simulation's (if any), then each model's
  std::vector<std::string> skipped;          // "NAME: not applicable: why", every-model runs only
  std::vector<std::string> lobe_names;       // the curves' lobes (`scattered` last for a fiber with a medulla)
};

// --help of --models: the default is every registered model.
std::string energy_models_help();

// Checks the request, makes the report folder's place (compare/report.h),
// runs the simulation (--run) and integrates every model.
EnergyResult energy(const EnergyRequest& request);

// Writes the report folder of a finished energy(); returns the line to print.
std::string write_energy_report(const EnergyRequest& request, const EnergyResult& result);

}  // namespace fiberlab::app
