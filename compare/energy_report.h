#pragma once
// The report folder of `fiberlab energy --report DIR`: metrics.csv (every
// channel), metrics.json, the plots and report.md (report.h writes the
// files; this assembles what goes in them).
#include <string>
#include <vector>

#include "compare/energy.h"

namespace fiberlab::compare {

struct EnergyReport {
  std::string dir, input;
  bool simulated = false;
  bool white = false;           // sigma_a = 0 in every channel: the furnace test applies
  int channel = 0;              // the channel of metrics.json, the table and the plots
  int n_theta = 0, n_phi = 0;   // the models' integration grid
  std::vector<double> theta_i;  // radians
  std::vector<std::string> lobe_names;  // the curves' lobes (with `scattered` for a fiber with a medulla)
};

// metrics.csv: one row per (curve, theta_i, channel).
std::string energy_csv(const EnergyReport& report, const std::vector<EnergyCurve>& curves);

// Writes every file; returns the line to print ("\nreport: DIR/report.md ...").
std::string write_energy_report(const EnergyReport& report, const std::vector<EnergyCurve>& curves);

}  // namespace fiberlab::compare
